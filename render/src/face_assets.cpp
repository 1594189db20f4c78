#include "emoface/render/face_assets.h"

#include <algorithm>
#include <bitset>
#include <chrono>
#include <filesystem>

#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
#include "emoface/common/timing.h"

namespace emoface::render {

namespace {

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
    for (const char* file : {"emotions.json", "visemes.json", "feature_lines.json", "wrinkles.json"})
        if (!std::filesystem::is_regular_file(dir + file))
            fail<InputError>("render: data folder {}: expression/{} is missing (expected the project's data/)",
                             data_dir, file);
    auto a = std::make_unique<FaceAssets>();
    a->face = std::move(face);
    a->layout = options.layout;

    auto t = Clock::now();
    a->rig = std::make_unique<expression::FaceRig>(a->face);
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
    const expression::WrinkleLibrarySpec spec = expression::load_wrinkle_spec(dir + "wrinkles.json");
    a->times.profiles_ms = ms_since(t);

    t = Clock::now();
    if (options.read_keys) {
        a->keys = options.read_keys(a->lines);
    } else {
        // Each key at its own expression's full intensity (neutral: no
        // FAPs); independent of each other, so made side by side.
        a->keys.resize(expression::kWrinkleKeyCount);
        const FaceAssets& shared = *a;
        parallel_for(expression::kWrinkleKeyCount, 1, [&](int begin, int end) {
            for (int k = begin; k < end; ++k) {
                expression::FapValues pose{};
                if (k > 0) pose = shared.emotions.profiles[std::size_t(k - 1)];
                a->keys[std::size_t(k)] = make_wrinkle_key(shared.face, *shared.rig, spec, expression::WrinkleKey(k),
                                                           pose, options.wrinkle_map_size, options.layout);
            }
        });
    }
    a->times.keys_ms = ms_since(t);
    return a;
}

std::unique_ptr<FaceAssets> load_default_face_assets(const std::string& data_dir,
                                                     const FaceAssetsOptions& options) {
    return load_face_assets(expression::make_default_face(data_dir + "/face", options.face),
                            data_dir, options);
}

std::vector<float> key_weights(const expression::EmotionMix& mix) {
    std::vector<float> w(expression::kWrinkleKeyCount, 0.0f);
    float sum = 0.0f;
    for (int e = 0; e < expression::kEmotionCount; ++e) {
        w[std::size_t(e + 1)] = float(std::clamp(mix.weights[std::size_t(e)], 0.0, 1.0));
        sum += w[std::size_t(e + 1)];
    }
    if (sum > 1.0f)  // rounding in a mix that sums to 1
        for (std::size_t k = 1; k < w.size(); ++k) w[k] /= sum;
    w[0] = std::max(0.0f, 1.0f - std::min(sum, 1.0f));
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
