#include "emoface/expression/profiles.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "fap_values_reader.h"
#include "json_reader.h"

namespace emoface::expression {

AuIntensities EmotionProfiles::action_units_of(const EmotionMix& mix) const {
    action_units.check(mix.aus, fmt::format("emotion mix \"{}\"", mix.to_string()));
    AuIntensities out = mix.aus;
    for (Emotion e : kEmotions) {
        const double w = mix[e];
        if (w == 0.0) continue;
        const AuIntensities& p = prototypes[emotion_index(e)];
        for (int a = 0; a < kAuNumberLimit; ++a) {
            out.left[a] += w * p.left[a];
            out.right[a] += w * p.right[a];
        }
    }
    for (int a = 0; a < kAuNumberLimit; ++a) {
        out.left[a] = std::min(out.left[a], 1.0);
        out.right[a] = std::min(out.right[a], 1.0);
    }
    return out;
}

FapValues EmotionProfiles::faps(const EmotionMix& mix) const { return action_units.faps(action_units_of(mix)); }

EmotionMix EmotionProfiles::mix_from_action_units(const AuIntensities& aus) const {
    // One row per AU side that some prototype has.
    std::vector<std::vector<double>> columns(kEmotionCount);
    std::vector<double> target;
    for (int a = 1; a < kAuNumberLimit; ++a)
        for (const auto side : {&AuIntensities::left, &AuIntensities::right}) {
            bool used = false;
            for (const AuIntensities& p : inferred_prototypes) used |= (p.*side)[a] != 0.0;
            if (!used) continue;
            for (int e = 0; e < kEmotionCount; ++e) columns[e].push_back((inferred_prototypes[e].*side)[a]);
            target.push_back((aus.*side)[a]);
        }
    const std::vector<double> w = bounded_least_squares(columns, target, 0.0, 1.0);
    EmotionMix mix;
    for (int e = 0; e < kEmotionCount; ++e) {
        if (w[e] <= 0.0) continue;
        // How much of the prototype is there at the fitted weight: each AU
        // counts by its share of the prototype, in full when the face shows
        // it at w × its prototype intensity or more. The least-squares fit
        // alone gives sadness to a speaking mouth's AU15; weighing it by
        // the prototype's presence needs the raised inner brows too.
        double present = 0.0, total = 0.0;
        for (std::size_t r = 0; r < target.size(); ++r) {
            const double p = columns[e][r];
            if (p <= 0.0) continue;
            total += p;
            present += p * std::min(1.0, target[r] / (w[e] * p));
        }
        mix.weights[e] = total > 0.0 ? w[e] * present / total : 0.0;
    }
    const double sum = mix.sum();
    if (sum > 1.0)
        for (double& x : mix.weights) x /= sum;
    return mix;
}

EmotionProfiles load_emotion_profiles(const std::string& path) {
    EmotionProfiles p;
    const std::string dir = std::filesystem::path(path).parent_path().string();
    detail::read_json_file(path, [&](detail::JsonReader& top) {
        top.comment("_about");
        const std::string table_file = top.string("action_units");
        p.action_units = load_action_units(dir.empty() ? table_file : dir + "/" + table_file);
        detail::JsonReader emotions = top.object("emotions");
        for (Emotion e : kEmotions) {
            const int i = emotion_index(e);
            detail::JsonReader r = emotions.object(emotion_name(e));
            p.reasoning[i] = r.string("reasoning");
            for (auto& [key, value] : r.object("action_units").entries()) {
                std::string error;
                const auto term = parse_au_term(key, &error);
                if (!term || term->side != AuSide::Both)
                    value.fail("a whole action unit \"AU<number>\" as the key", "\"" + key + "\"");
                if (!p.action_units.find(term->number))
                    value.fail(fmt::format("an AU of {} ({})", table_file, p.action_units.numbers_text()),
                               "\"" + key + "\"");
                const double w = value.as_number();
                if (!(w > 0.0 && w <= 1.0)) value.fail("an intensity in (0, 1]");
                if (p.prototypes[i].left[term->number] != 0.0)
                    value.fail("each AU once", fmt::format("AU{} a second time", term->number));
                p.prototypes[i].left[term->number] = p.prototypes[i].right[term->number] = w;
            }
            p.profiles[i] = p.action_units.faps(p.prototypes[i]);
            std::bitset<fap::kFapCount> all;
            all.set();
            p.inferred_prototypes[i] = p.action_units.infer(p.profiles[i], all);
            r.finish();
        }
        emotions.finish();
    });
    return p;
}

bool is_mouth_fap(int f) { return (f >= 3 && f <= 18) || (f >= 43 && f <= 47) || (f >= 51 && f <= 60); }

FapValues VisemeProfiles::faps(const fap::Viseme& v) const {
    auto profile = [&](int code) -> const FapValues* {
        return code >= 1 && code < kVisemeCount ? &profiles[code] : nullptr;
    };
    const double a = std::clamp(v.blend, 0, fap::kMaxIntensity) / static_cast<double>(fap::kMaxIntensity);
    FapValues out{};
    if (const FapValues* p1 = profile(v.select1))
        for (int f = 0; f < fap::kFapCount; ++f) out[f] += a * (*p1)[f];
    if (const FapValues* p2 = profile(v.select2))
        for (int f = 0; f < fap::kFapCount; ++f) out[f] += (1.0 - a) * (*p2)[f];
    return out;
}

VisemeProfiles load_viseme_profiles(const std::string& path) {
    VisemeProfiles p;
    detail::read_json_file(path, [&](detail::JsonReader& top) {
        detail::JsonReader visemes = top.object("visemes");
        for (int code = 1; code < kVisemeCount; ++code) {
            detail::JsonReader r = visemes.object(std::to_string(code));
            (void)r.string("phonemes");
            p.profiles[code] = detail::read_fap_values(r.at("faps"), is_mouth_fap, "a mouth FAP (3-18, 43-47, 51-60)");
            r.finish();
        }
        visemes.finish();
    });
    return p;
}

}  // namespace emoface::expression
