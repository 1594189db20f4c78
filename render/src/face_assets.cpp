#include "emoface/render/face_assets.h"

#include <algorithm>

#include "emoface/common/error.h"

namespace emoface::render {

std::unique_ptr<FaceAssets> load_face_assets(expression::Face face, const std::string& data_dir,
                                             const FaceAssetsOptions& options) {
    if (options.wrinkle_map_size < 256 || options.wrinkle_map_size > 4096)
        fail<InputError>("render: wrinkle map size must be in 256..4096, got {}",
                         options.wrinkle_map_size);
    auto a = std::make_unique<FaceAssets>();
    a->face = std::move(face);
    a->layout = options.layout;
    a->rig = std::make_unique<expression::FaceRig>(a->face);
    const std::string dir = data_dir + "/expression/";
    a->emotions = expression::load_emotion_profiles(dir + "emotions.json");
    a->visemes = expression::load_viseme_profiles(dir + "visemes.json");
    std::bitset<expression::kFeatureCount> present;
    for (int i = 0; i < expression::kFeatureCount; ++i) present[i] = a->face.feature_points[i].present;
    a->lines = expression::lines_for_face(expression::load_feature_lines(dir + "feature_lines.json"),
                                          present);
    const expression::WrinkleLibrarySpec spec = expression::load_wrinkle_spec(dir + "wrinkles.json");
    // Each key at its own expression's full intensity (neutral: no FAPs).
    for (int k = 0; k < expression::kWrinkleKeyCount; ++k) {
        expression::FapValues pose{};
        if (k > 0) pose = a->emotions.profiles[std::size_t(k - 1)];
        a->keys.push_back(make_wrinkle_key(a->face, *a->rig, spec, expression::WrinkleKey(k), pose,
                                           options.wrinkle_map_size, options.layout));
    }
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
