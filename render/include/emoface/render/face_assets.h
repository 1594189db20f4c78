#pragma once
// What the pipeline needs for one face, loaded once: the face, its rig, the
// emotion and viseme profiles, the morph's feature lines and the seven key
// wrinkle maps (neutral + six emotions, each made at its own expression's
// layout, DESIGN.md "Texture layouts"). FaceScene draws frames from it.
#include <functional>
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
    // Wall-clock milliseconds of loading them (for the commands' reports).
    struct Times {
        double rig_ms = 0;       // the rig's influence weights
        double profiles_ms = 0;  // emotion/viseme profiles, feature lines, wrinkle spec
        double keys_ms = 0;      // the seven key wrinkle maps (generated or read)
    } times;
};

// The sides a wrinkle map may have. Throws emoface::InputError
// "WHAT SIZE: expected 256..4096" (WHAT: "render: wrinkle map size",
// "play: --wrinkle-size", ...): the one check of a map size.
constexpr int kMinWrinkleMapSize = 256;
constexpr int kMaxWrinkleMapSize = 4096;
void check_wrinkle_map_size(int size, const std::string& what);

struct FaceAssetsOptions {
    int wrinkle_map_size = 1024;          // 256..4096 (generated keys)
    expression::DefaultFaceOptions face;  // the default face's resolution
    WrinkleLayout layout = WrinkleLayout::Projective;
    // Where the keys come from instead of being generated (painted maps): a
    // reader given the face's feature lines, e.g. render_io's
    // read_wrinkle_keys on a folder (render itself reads no image files).
    std::function<std::vector<WrinkleKey>(const std::vector<expression::FeatureLine>& lines)> read_keys;
};

// Loads the profiles, lines and wrinkle library from `data_dir` (the
// project's data/ folder) for `face`, builds its rig and generates the keys
// (side by side), or reads them with options.read_keys. The one asset loader:
// the commands' Session, the goldens and the benchmarks use it. Throws
// emoface::InputError naming the file that is wrong or missing.
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
