#include "emoface/expression/profiles.h"

#include <algorithm>
#include <cmath>

#include "json_reader.h"

namespace emoface::expression {
namespace {

// {"fap name or number": value, ...} -> FapValues; `allowed` filters FAPs.
template <typename Allowed>
FapValues read_faps(const nlohmann::json& j, const std::string& file, const std::string& where, Allowed allowed,
                    const char* allowed_text) {
    if (!j.is_object()) fail<InputError>("expression: {}: \"{}\" must be an object of FAP values", file, where);
    FapValues out{};
    for (auto it = j.begin(); it != j.end(); ++it) {
        if (!it.key().empty() && it.key()[0] == '_') continue;
        int number = 0;
        if (auto f = fap::find_fap(it.key())) {
            number = *f;
        } else {
            const std::string& k = it.key();
            if (k.empty() || !std::all_of(k.begin(), k.end(), [](char c) { return c >= '0' && c <= '9'; }) || k.size() > 3)
                fail<InputError>("expression: {}: {}: \"{}\" is not a FAP name or number", file, where, k);
            number = std::stoi(k);
        }
        if (!allowed(number))
            fail<InputError>("expression: {}: {}: FAP {} ({}) is not allowed here; expected {}", file, where, number,
                             number >= 1 && number <= fap::kFapCount ? std::string(fap::fap_info(number).name) : "?",
                             allowed_text);
        if (!it->is_number() || !std::isfinite(it->get<double>()))
            fail<InputError>("expression: {}: {}: the value of \"{}\" must be a number", file, where, it.key());
        if (out[number - 1] != 0.0)
            fail<InputError>("expression: {}: {}: FAP {} is given twice", file, where, number);
        out[number - 1] = it->get<double>();
    }
    return out;
}

}  // namespace

FapValues EmotionProfiles::faps(const EmotionMix& mix) const {
    FapValues out{};
    for (Emotion e : kEmotions) {
        const double w = mix[e];
        if (w == 0.0) continue;
        for (int f = 0; f < fap::kFapCount; ++f) out[f] += w * (*this)[e][f];
    }
    return out;
}

EmotionProfiles load_emotion_profiles(const std::string& path) {
    const nlohmann::json root = detail::read_json_file(path);
    detail::JsonReader top(root, path, "");
    detail::JsonReader emotions = top.object("emotions");
    EmotionProfiles p;
    for (Emotion e : kEmotions) {
        detail::JsonReader r = emotions.object(emotion_name(e));
        p.reasoning[emotion_index(e)] = r.string("reasoning");
        p.profiles[emotion_index(e)] =
            read_faps(r.raw("faps"), path, std::string("emotions.") + emotion_name(e) + ".faps",
                      [](int f) { return f >= 3 && f <= fap::kFapCount; }, "a low-level FAP (3..68)");
        r.finish();
    }
    emotions.finish();
    top.finish();
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
    const nlohmann::json root = detail::read_json_file(path);
    detail::JsonReader top(root, path, "");
    detail::JsonReader visemes = top.object("visemes");
    VisemeProfiles p;
    for (int code = 1; code < kVisemeCount; ++code) {
        detail::JsonReader r = visemes.object(std::to_string(code));
        (void)r.string("phonemes");
        p.profiles[code] = read_faps(r.raw("faps"), path, "visemes." + std::to_string(code) + ".faps", is_mouth_fap,
                                     "a mouth FAP (3-18, 43-47, 51-60)");
        r.finish();
    }
    visemes.finish();
    top.finish();
    return p;
}

}  // namespace emoface::expression
