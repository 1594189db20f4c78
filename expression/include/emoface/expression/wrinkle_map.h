#pragma once
// The wrinkle library: per emotion, the wrinkles of thesis chapter 2.3,
// written as curves placed relative to feature points (data/expression/
// wrinkles.json), rendered as a height field at a feature layout and turned
// into a tangent-space normal map.
//
// Normal-map convention: RGB = 0.5 + 0.5 n, with n.x along the image's
// columns (right), n.y along its rows (DOWN, i.e. "DirectX" or Y- green) and
// n.z out of the skin. Both axes follow the wrinkle UV set, whose v grows
// down the image, so a TBN frame built from that UV set needs no flip.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec2.hpp>

#include "emoface/expression/feature_layout.h"

namespace emoface::expression {

// The six Ekman emotions in the order the project uses everywhere
// (FAP 2 codes 1..6), plus neutral (code 0) for the wrinkle maps.
enum class WrinkleKey { Neutral, Joy, Sadness, Anger, Fear, Disgust, Surprise };
constexpr int kWrinkleKeyCount = 7;
const char* wrinkle_key_name(WrinkleKey key);  // "neutral", "joy", ...

enum class WrinkleProfile {
    Groove,  // a Gaussian valley across the curve
    Fold,    // a valley with a bulge of skin on one side (nasolabial fold)
    Bulge,   // a raised ridge or, for a single point, a rounded bump (chin)
    Dimple,  // a rounded dip around a single point
};

// A point given relative to the feature points: the point `from`, or the
// interpolation from -> to at t, then moved by `offset` face units
// (+x towards the face's left = image right, +y up the face).
struct AnchoredPoint {
    int from = 0;
    int to = -1;  // -1: no interpolation
    float t = 0.5f;
    glm::vec2 offset{0.0f};
};

struct WrinkleSpec {
    std::string name;
    WrinkleProfile profile = WrinkleProfile::Groove;
    std::vector<AnchoredPoint> points;  // a curve through them; one point = a round mark
    float depth = 0.02f;   // face units (height of the valley or ridge)
    float width = 0.03f;   // face units (Gaussian sigma across the curve)
    float taper = 0.25f;   // fraction of the arc at each end over which depth fades in
    int count = 1;         // parallel copies ...
    glm::vec2 step{0.0f};  // ... each moved by this many face units from the last
    float depth_falloff = 1.0f;  // depth multiplier from one copy to the next
    float side = 1.0f;     // Fold: which side of the curve bulges (+1 left of travel)
};

struct SkinDetail {
    float amplitude = 0.0f;  // face units
    float scale = 0.02f;     // face units: size of the finest cell
    int octaves = 3;
};

struct WrinkleLibrarySpec {
    std::array<std::vector<WrinkleSpec>, kWrinkleKeyCount> wrinkles;  // by WrinkleKey
    SkinDetail neutral_detail;
};

// Loads data/expression/wrinkles.json; errors name the file, emotion and
// wrinkle that is wrong.
WrinkleLibrarySpec load_wrinkle_spec(const std::string& path);

struct NormalMap {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;  // width * height * 4, row 0 = top
};

// Height field (face units, 0 = flat skin) of one key's wrinkles at `layout`,
// size x size samples at pixel centres. Deterministic.
std::vector<float> render_height_field(const WrinkleLibrarySpec& spec, WrinkleKey key,
                                       const FeatureLayout& layout, int size);

// Tangent-space normal map of a height field (see the convention above).
// Where the height field is locally flat the pixel is exactly (128, 128, 255).
NormalMap height_to_normal_map(const std::vector<float>& height, int size, float face_unit);

// render_height_field + height_to_normal_map. size in [256, 4096].
NormalMap generate_wrinkle_map(const WrinkleLibrarySpec& spec, WrinkleKey key,
                               const FeatureLayout& layout, int size);

}  // namespace emoface::expression
