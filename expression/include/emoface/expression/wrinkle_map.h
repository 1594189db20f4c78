#pragma once
// The wrinkle library: per FACS Action Unit, the wrinkles its muscle makes
// (per side for a bilateral AU), written as curves placed relative to
// feature points (data/expression/wrinkles.json), rendered as a height field
// at a feature layout and turned into a tangent-space normal map. A key map
// shows some AUs' wrinkles (one AU on one side for the frame's AU keys; an
// emotion's prototype AUs at their intensities for the thesis's emotion keys)
// or, with none, the neutral skin's fine detail.
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

#include "emoface/expression/action_units.h"
#include "emoface/expression/feature_layout.h"

namespace emoface::expression {

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
    float depth_factor = 1.0f;  // the wrinkle's depth (and, with it, width) here, as a fraction of its
                                // depth; between points it changes smoothly (deepest near the nose wing)
};

struct WrinkleSpec {
    std::string name;
    WrinkleProfile profile = WrinkleProfile::Groove;
    std::vector<AnchoredPoint> points;  // a curve through them; one point = a round mark
    float depth = 0.02f;   // face units (height of the valley or ridge)
    float width = 0.03f;   // face units (Gaussian sigma across the curve)
    float taper = 0.25f;   // fraction of the arc at the start over which depth fades in ...
    float taper_end = -1.0f;  // ... and at the end (< 0: as taper); a long end taper fades a line outwards
    float crease = -1.0f;  // share of the depth in the valley's narrow crease (< 0: FoldShape::core);
                           // low for broad folds of bunched skin, higher for fine lines
    int count = 1;         // parallel copies ...
    glm::vec2 step{0.0f};  // ... each moved by this many face units from the last
    float depth_falloff = 1.0f;  // depth multiplier from one copy to the next
    float side = 1.0f;     // Fold: which side of the curve bulges (+1 left of travel)
    float shoulder = -1.0f;  // crest height of the bunched skin beside it (< 0: FoldShape::shoulder);
                             // high where neighbouring folds share broad rolls (the forehead)
    float asymmetry = -1.0f;  // how much steeper the `side` flank is (< 0: FoldShape::asymmetry); low
                              // for a fold the cheek rounds over softly, with no hard edge
};

// How every groove and fold is shaped, for all wrinkles alike (wrinkles.json
// "fold_shape"; the reasoning is there). Lengths are in units of the
// wrinkle's width (its sigma) unless noted.
struct FoldShape {
    float shoulder = 0.3f;           // crest height beside a groove, fraction of its depth
    float shoulder_offset = 2.2f;    // crest distance from the valley floor
    float shoulder_width = 1.3f;     // crest sigma
    float asymmetry = 0.3f;          // one flank (sigma * (1 - a)) steeper than the other (1 + a)
    float core = 0.55f;              // share of the depth in a sharp narrow core of the valley ...
    float core_width = 0.5f;         // ... this wide; the rest over broad shallow walls ...
    float wall_width = 1.6f;         // ... this wide (both in flank sigmas)
    float meander = 0.5f;            // sideways wander of the valley floor
    float meander_wavelength = 0.25f;  // face units
    float swell = 0.35f;             // depth variation along the fold, +- fraction
    float width_taper = 0.5f;        // width at the very ends, fraction of the middle's
    float copy_length = 0.25f;       // parallel copies: each end trimmed by up to this fraction
    float copy_depth = 0.25f;        // parallel copies: depth varied by +- this fraction
    float copy_spacing = 0.2f;       // parallel copies: step varied by +- this fraction
    float fine_depth = 0.22f;        // fine lines beside each groove, fraction of its depth
    float fine_width = 0.45f;        // their sigma
    float fine_offset = 3.6f;        // their distance from the valley floor
    float fine_length = 0.55f;       // their length, fraction of the groove's
};

// Cavity (ambient occlusion of a valley) stored in a map's alpha: 1 on open
// skin and on raised skin, falling in valleys by how far the valley floor
// lies below the skin around it (the height field's Gaussian mean of sigma
// `radius`): narrow creases darken, broad shallow folds barely.
struct CavitySpec {
    float full_depth = 0.025f;  // face units: a floor this far below its surroundings gets `darkest` ...
    float darkest = 0.35f;      // ... (linear in the depth below them, down to 0, so split halves add up)
    float radius = 0.04f;       // face units: the surroundings' sigma
};

struct SkinDetail {
    float amplitude = 0.0f;  // face units
    float scale = 0.02f;     // face units: size of the finest cell
    int octaves = 3;
};

// The wrinkles one AU makes at its full intensity (FACS "E").
struct AuWrinkles {
    int au = 0;
    std::vector<WrinkleSpec> left, right;  // on that side of the face
    std::vector<WrinkleSpec> across;       // over the midline: split softly between the sides
    bool empty() const { return left.empty() && right.empty() && across.empty(); }
};

// The AU number that stands for the face's resting lines (wrinkles.json
// "resting"): the neutral key shows them, and an emotion key, which the
// thesis's blend mixes with neutral, names them among its sources.
constexpr int kRestingLines = 0;

struct WrinkleLibrarySpec {
    std::vector<AuWrinkles> action_units;  // in file order, each AU once
    AuWrinkles resting;                    // au kRestingLines; may be empty
    SkinDetail neutral_detail;
    FoldShape fold;
    CavitySpec cavity;
    const AuWrinkles* find(int au) const;  // nullptr: the AU makes no wrinkles (kRestingLines: the resting lines)
};

// One AU's wrinkles in a key map: the side's list plus its half of the
// `across` wrinkles (AuSide::Both: all of them, whole), depths times
// `intensity`.
struct WrinkleSource {
    int au = 0;
    AuSide side = AuSide::Both;
    float intensity = 1.0f;
};
// The resting lines, whole, as a key's source.
constexpr WrinkleSource kRestingLinesSource{kRestingLines, AuSide::Both, 1.0f};
// What a key map shows: the sources' wrinkles; none: the neutral key, the
// resting lines and the skin's fine detail (wrinkles.json "resting" and
// "neutral_skin_detail").
using WrinkleSources = std::vector<WrinkleSource>;

// Loads data/expression/wrinkles.json; errors name the file, AU, side and
// wrinkle that is wrong ("action_units.AU6.left[1].depth: expected ...").
WrinkleLibrarySpec load_wrinkle_spec(const std::string& path);

// The part of a map that a key's wrinkles touch, in normalised texture
// coordinates (x right, y down), the fold's full reach included: outside it
// the key's map is exactly flat. The whole map for the neutral key.
struct WrinkleRegion {
    glm::vec2 min{0.0f}, max{1.0f};
    bool empty() const { return !(max.x > min.x && max.y > min.y); }
};
WrinkleRegion wrinkle_region(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                             const FeatureLayout& layout);

struct NormalMap {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;  // width * height * 4, row 0 = top
};

// Height field (face units, 0 = flat skin) of one key's wrinkles at `layout`,
// size x size samples at pixel centres, computed only inside the key's
// region (0 elsewhere). Deterministic. Every wrinkle fades out below the
// hairline (feature points 11.2, 11.1, 11.3) and before the map's edge, so
// no fold sits on the hair or is cut off. A side's wrinkles, and the half
// of an `across` wrinkle given to one side, are weighted by a smooth step
// across the midline (the polyline through 11.1, 8.1, 8.2, 2.10, 2.1 where
// present), so a one-sided AU leaves the other half flat and the two sides
// of an AU sum to the whole AU.
std::vector<float> render_height_field(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                                       const FeatureLayout& layout, int size);

// Tangent-space normal map of a height field (see the convention above),
// with the cavity in alpha: exactly 255 where the height is >= 0, lower in
// valleys (heights in normalised texture units; face_unit scales
// cavity.full_depth and cavity.radius to them). Where the height field is locally flat the
// pixel is exactly (128, 128, 255, 255), and outside `region` (where the
// height must be 0) it is written so without looking.
NormalMap height_to_normal_map(const std::vector<float>& height, int size, float face_unit,
                               const CavitySpec& cavity = {}, const WrinkleRegion& region = {});

// render_height_field + height_to_normal_map. size in [256, 4096].
NormalMap generate_wrinkle_map(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                               const FeatureLayout& layout, int size);

}  // namespace emoface::expression
