#include "emoface/render/face_assets.h"

#include <algorithm>
#include <bitset>
#include <chrono>
#include <filesystem>

#include <fmt/format.h>

#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
#include "emoface/common/timing.h"

namespace emoface::render {

namespace {

// The keys to generate: neutral, then each AU of the library on each side
// it has (checked against the AU table: a wrinkling AU must be one).
struct KeyPlan {
    std::string name;
    expression::WrinkleSources sources;
    expression::FapValues pose{};
};

std::vector<KeyPlan> action_unit_plans(const FaceAssets& a) {
    std::vector<KeyPlan> plans(1, KeyPlan{"neutral", {}, {}});
    for (const expression::AuWrinkles& w : a.wrinkles.action_units) {
        const expression::ActionUnit* au = a.emotions.action_units.find(w.au);
        if (!au)
            fail<InputError>("render: wrinkles.json: action_units.AU{}: expected an AU of action_units.json ({}), "
                             "found none",
                             w.au, a.emotions.action_units.numbers_text());
        const std::string name = fmt::format("AU{}", w.au);
        if (!au->sides) {
            plans.push_back({name, {{w.au, expression::AuSide::Both, 1.0f}}, au->faps});
            continue;
        }
        if (!w.left.empty() || !w.across.empty())
            plans.push_back({name + "L", {{w.au, expression::AuSide::Left, 1.0f}}, au->left});
        if (!w.right.empty() || !w.across.empty())
            plans.push_back({name + "R", {{w.au, expression::AuSide::Right, 1.0f}}, au->right});
    }
    return plans;
}

}  // namespace

void check_wrinkle_map_size(int size, const std::string& what) {
    if (size < kMinWrinkleMapSize || size > kMaxWrinkleMapSize)
        fail<InputError>("{} {}: expected {}..{}", what, size, kMinWrinkleMapSize, kMaxWrinkleMapSize);
}

std::unique_ptr<FaceAssets> load_face_assets(expression::Face face, const std::string& data_dir,
                                             const FaceAssetsOptions& options) {
    if (!options.read_keys) check_wrinkle_map_size(options.wrinkle_map_size, "render: wrinkle map size");
    const std::string dir = data_dir + "/expression/";
    // Every data file is looked for first, so a wrong folder fails before the
    // slow part with the fix, not with the first reader's "cannot open".
    for (const char* file : {"emotions.json", "visemes.json", "feature_lines.json", "wrinkles.json", "fap_ranges.json"})
        if (!std::filesystem::is_regular_file(dir + file))
            fail<InputError>("render: data folder {}: expression/{} is missing (expected the project's data/)",
                             data_dir, file);
    auto a = std::make_unique<FaceAssets>();
    a->face = std::move(face);
    a->layout = options.layout;

    auto t = Clock::now();
    expression::RigOptions rig_options;
    if (options.clamp_faps) rig_options.ranges = expression::load_fap_ranges(dir + "fap_ranges.json");
    a->rig = std::make_unique<expression::FaceRig>(a->face, rig_options);
    a->times.rig_ms = ms_since(t);

    t = Clock::now();
    a->emotions = expression::load_emotion_profiles(dir + "emotions.json");
    a->visemes = expression::load_viseme_profiles(dir + "visemes.json");
    std::bitset<expression::kFeatureCount> present;
    for (int i = 0; i < expression::kFeatureCount; ++i) present[i] = a->face.feature_points[i].present;
    a->lines = expression::lines_for_face(expression::load_feature_lines(dir + "feature_lines.json"),
                                          present);
    // A line of zero length at neutral would stop the morph; say so naming the face's file.
    expression::check_lines_have_length(a->lines, posed_layout(a->face, *a->rig, {}, a->layout), a->face.source);
    a->wrinkles = expression::load_wrinkle_spec(dir + "wrinkles.json");
    a->times.profiles_ms = ms_since(t);

    t = Clock::now();
    a->keys = options.read_keys ? options.read_keys(a->lines) : make_action_unit_keys(*a, options.wrinkle_map_size);
    for (const WrinkleKey& key : a->keys)
        if (!key_driver(key.name))
            fail<InputError>("render: wrinkle key '{}': expected neutral, an emotion or an AU term such as AU6L",
                             key.name);
    a->times.keys_ms = ms_since(t);
    return a;
}

std::unique_ptr<FaceAssets> load_default_face_assets(const std::string& data_dir,
                                                     const FaceAssetsOptions& options) {
    return load_face_assets(expression::make_default_face(data_dir + "/face", options.face),
                            data_dir, options);
}

std::vector<WrinkleKey> make_action_unit_keys(const FaceAssets& a, int size) {
    check_wrinkle_map_size(size, "render: wrinkle map size");
    const std::vector<KeyPlan> plans = action_unit_plans(a);
    // Independent of each other, so made side by side; each renders only
    // its region.
    std::vector<WrinkleKey> keys(plans.size());
    parallel_for(int(plans.size()), 1, [&](int begin, int end) {
        for (int k = begin; k < end; ++k) {
            const KeyPlan& p = plans[std::size_t(k)];
            keys[std::size_t(k)] = make_wrinkle_key(a.face, *a.rig, a.wrinkles, p.name, p.sources, p.pose, size, a.layout);
        }
    });
    return keys;
}

WrinkleKey make_emotion_key(const FaceAssets& a, std::optional<expression::Emotion> emotion, int size) {
    check_wrinkle_map_size(size, "render: wrinkle map size");
    if (!emotion) return make_wrinkle_key(a.face, *a.rig, a.wrinkles, "neutral", {}, {}, size, a.layout);
    const expression::AuIntensities& aus = a.emotions.prototypes[std::size_t(expression::emotion_index(*emotion))];
    // The emotion keys blend with neutral (key_weights), so each carries
    // the resting lines too, or they would fade as the emotion rises.
    expression::WrinkleSources sources{expression::kRestingLinesSource};
    for (const expression::AuWrinkles& w : a.wrinkles.action_units)
        if (aus.mean(w.au) > 0.0)  // prototypes are symmetric
            sources.push_back({w.au, expression::AuSide::Both, float(aus.mean(w.au))});
    return make_wrinkle_key(a.face, *a.rig, a.wrinkles, expression::emotion_name(*emotion), sources,
                            a.emotions[*emotion], size, a.layout);
}

std::optional<KeyDriver> key_driver(const std::string& name) {
    KeyDriver d;
    if (name == "neutral") return d;
    if (const auto e = expression::find_emotion(name)) {
        d.kind = KeyDriver::Kind::Emotion;
        d.emotion = *e;
        return d;
    }
    std::string error;
    if (const auto term = expression::parse_au_term(name, &error)) {
        d.kind = KeyDriver::Kind::ActionUnit;
        d.au = *term;
        return d;
    }
    return std::nullopt;
}

std::vector<float> key_weights(const std::vector<WrinkleKey>& keys, const expression::FaceState& state) {
    std::vector<float> w(keys.size(), 0.0f);
    std::vector<KeyDriver> drivers;
    drivers.reserve(keys.size());
    float emotions = 0.0f;
    for (std::size_t k = 0; k < keys.size(); ++k) {
        const auto d = key_driver(keys[k].name);
        if (!d) fail<InputError>("render: wrinkle key '{}': expected neutral, an emotion or an AU term", keys[k].name);
        drivers.push_back(*d);
        if (d->kind == KeyDriver::Kind::Emotion) {
            w[k] = float(std::clamp(state.mix.weights[std::size_t(expression::emotion_index(d->emotion))], 0.0, 1.0));
            emotions += w[k];
        } else if (d->kind == KeyDriver::Kind::ActionUnit) {
            const int au = d->au.number;
            const double v = d->au.side == expression::AuSide::Left    ? state.aus.left[std::size_t(au)]
                             : d->au.side == expression::AuSide::Right ? state.aus.right[std::size_t(au)]
                                                                       : state.aus.mean(au);
            w[k] = float(std::clamp(v, 0.0, 1.0));
        }
    }
    const float scale = emotions > 1.0f ? 1.0f / emotions : 1.0f;  // rounding in a mix that sums to 1
    for (std::size_t k = 0; k < keys.size(); ++k) {
        if (drivers[k].kind == KeyDriver::Kind::Emotion) w[k] *= scale;
        // Under half a step of an 8-bit map a key changes nothing one can
        // see (fits leave such crumbs): weight 0, so it is not morphed.
        if (w[k] < kNegligibleKeyWeight) w[k] = 0.0f;
        if (drivers[k].kind == KeyDriver::Kind::Neutral) w[k] = std::max(0.0f, 1.0f - std::min(emotions, 1.0f));
    }
    return w;
}

std::unique_ptr<FaceScene> make_face_scene(Platform& platform, const FaceAssets& assets,
                                           const FaceSceneOptions& options) {
    FaceSceneOptions o = options;
    o.layout = assets.layout;
    return std::make_unique<FaceScene>(platform, assets.face, *assets.rig, assets.keys,
                                       assets.lines, o);
}

}  // namespace emoface::render
