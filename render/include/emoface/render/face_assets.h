#pragma once
// What the pipeline needs for one face, loaded once: the face, its rig, the
// emotion and viseme profiles, the morph's feature lines, the wrinkle
// library and the key wrinkle maps (neutral + one per wrinkling AU and side,
// each made at its own AU's layout, DESIGN.md "Texture layouts"; or painted
// ones). FaceScene draws frames from it.
#include <functional>
#include <memory>
#include <optional>
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
    expression::WrinkleLibrarySpec wrinkles;     // data/expression/wrinkles.json
    std::vector<WrinkleKey> keys;                // "neutral" first, then by name (key_weights)
    WrinkleLayout layout = WrinkleLayout::Projective;  // the texture space of the keys
    // Wall-clock milliseconds of loading them (for the commands' reports).
    struct Times {
        double rig_ms = 0;       // the rig's influence weights
        double profiles_ms = 0;  // emotion/viseme profiles, feature lines, wrinkle spec
        double keys_ms = 0;      // the key wrinkle maps (generated or read)
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
    // The rig clamps FAPs to the human ranges of expression/fap_ranges.json;
    // false keeps them raw (--no-clamp).
    bool clamp_faps = true;
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

// What drives a wrinkle key, read from its name: "neutral", an emotion name
// ("joy") or an AU term ("AU6L", "AU6R"; "AU17" for a midline AU or both
// sides of one). nullopt for any other name.
struct KeyDriver {
    enum class Kind { Neutral, Emotion, ActionUnit } kind = Kind::Neutral;
    expression::Emotion emotion = expression::Emotion::Joy;
    expression::AuTerm au;
};
std::optional<KeyDriver> key_driver(const std::string& name);

// The weight of each key in a frame, from what drives it: an AU key the
// frame's AU intensity on its side (both sides: their mean); an emotion key
// the mix's weight (scaled down if the emotions sum over 1); neutral
// 1 - the sum of the emotion keys' weights (AU keys take nothing from it:
// their wrinkles add to the neutral skin, the morph's rest value is flat
// skin). The one place a key's weight is decided.
// Weights under kNegligibleKeyWeight are 0 (a key at 0 costs nothing).
inline constexpr float kNegligibleKeyWeight = 1.0f / 512.0f;
std::vector<float> key_weights(const std::vector<WrinkleKey>& keys, const expression::FaceState& state);

// The generated key set of `assets` (FaceAssetsOptions without read_keys):
// "neutral", then one key per wrinkling AU of the library, per side for a
// bilateral AU ("AU1L", "AU1R", ..., "AU17"), each at its AU's layout (the
// AU's side at full intensity through the rig).
std::vector<WrinkleKey> make_action_unit_keys(const FaceAssets& assets, int size);
// An emotion's key (the thesis's figure 6.4): the union of its prototype
// AUs' wrinkles at their intensities, at the emotion's layout; nullopt: the
// neutral key.
WrinkleKey make_emotion_key(const FaceAssets& assets, std::optional<expression::Emotion> emotion, int size);

// A scene on the assets (which must outlive it), in the assets' layout
// (options.layout is replaced by it).
std::unique_ptr<FaceScene> make_face_scene(Platform& platform, const FaceAssets& assets,
                                           const FaceSceneOptions& options = {});

}  // namespace emoface::render
