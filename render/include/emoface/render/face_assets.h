#pragma once
// What the pipeline needs for one face, loaded once: the face, its rig, the
// emotion and viseme profiles, the morph's feature lines and the seven key
// wrinkle maps (neutral + six emotions, each made at its own expression's
// layout, DESIGN.md "Texture layouts"). FaceScene draws frames from it.
#include <memory>
#include <string>
#include <vector>

#include "emoface/expression/default_face.h"
#include "emoface/expression/emotion.h"
#include "emoface/expression/face_state.h"
#include "emoface/expression/profiles.h"
#include "emoface/expression/rig.h"
#include "emoface/render/face_scene.h"

namespace emoface::render {

struct FaceAssets {
    expression::Face face;
    std::unique_ptr<expression::FaceRig> rig;
    expression::EmotionProfiles emotions;
    expression::VisemeProfiles visemes;
    std::vector<expression::FeatureLine> lines;  // those the face has both ends of
    std::vector<WrinkleKey> keys;                // by expression::WrinkleKey
    WrinkleLayout layout = WrinkleLayout::Projective;  // the texture space of the keys
};

struct FaceAssetsOptions {
    int wrinkle_map_size = 1024;          // 256..4096
    expression::DefaultFaceOptions face;  // the default face's resolution
    WrinkleLayout layout = WrinkleLayout::Projective;
};

// Loads the profiles, lines and wrinkle library from `data_dir` (the
// project's data/ folder) for `face`, builds its rig and generates the keys.
// Throws emoface::InputError naming the file that is wrong.
std::unique_ptr<FaceAssets> load_face_assets(expression::Face face, const std::string& data_dir,
                                             const FaceAssetsOptions& options = {});
// The default face (data/face) with everything above.
std::unique_ptr<FaceAssets> load_default_face_assets(const std::string& data_dir,
                                                     const FaceAssetsOptions& options = {});

// The key weights of a mix, in expression::WrinkleKey order: neutral
// (1 - sum), then joy .. surprise.
std::vector<float> key_weights(const expression::EmotionMix& mix);

// A scene on the assets (which must outlive it), in the assets' layout
// (options.layout is replaced by it).
std::unique_ptr<FaceScene> make_face_scene(Platform& platform, const FaceAssets& assets,
                                           const FaceSceneOptions& options = {});

}  // namespace emoface::render
