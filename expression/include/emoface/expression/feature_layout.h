#pragma once
// Feature layouts: where the 84 MPEG-4 feature points sit in a texture
// (DESIGN.md, "Texture layouts"), and the feature lines the morph warps with.
//
// Texture coordinates are normalised: x in [0, 1] to the image's right (the
// face's left), y in [0, 1] DOWN the image (row 0 = top of the face). The morph
// uses the same convention, so a layout is resolution-independent.
#include <array>
#include <bitset>
#include <string>
#include <string_view>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "emoface/fap/feature_points.h"
#include "emoface/fap/fapu.h"

namespace emoface::expression {

constexpr int kFeatureCount = fap::kFeaturePointCount;

// The face-space rectangle (x, y of the frontal view, any length unit) that
// the projective layout maps onto the unit texture square.
struct TextureBox {
    glm::vec2 min{0.0f};  // face's right, bottom
    glm::vec2 max{1.0f};  // face's left, top
};

// Frontal orthographic projection of a face-space point into the box:
// x -> u to the right, y (up) -> v down the image. z is ignored.
glm::vec2 project_to_texture(const glm::vec3& point, const TextureBox& box);

struct FeatureLayout {
    std::array<glm::vec2, kFeatureCount> points{};  // indexed by fap::feature_point_index
    std::bitset<kFeatureCount> present;

    // Position of feature point `id` ("4.1"); throws emoface::Error if the
    // layout lacks it.
    glm::vec2 at(const std::string& id) const;
    // The length that wrinkle specs are written in: the distance between the
    // pupils (3.5-3.6), or between the outer eye corners (3.7-3.12) x 0.7
    // when a face has no pupils. Throws if neither is present.
    float face_unit() const;
};

// `projective` layout: every present feature point projected into the box.
FeatureLayout projective_layout(const std::array<glm::vec3, kFeatureCount>& positions,
                                const std::bitset<kFeatureCount>& present,
                                const TextureBox& box);

// The same from the rig's double-precision feature points.
FeatureLayout projective_layout(const fap::FeaturePointPositions& positions,
                                const std::bitset<kFeatureCount>& present,
                                const TextureBox& box);

// `anchored` layout: the feature points' fixed UVs (v measured up, as OBJ and
// OpenGL store it; converted here to the image-down convention).
FeatureLayout anchored_layout(const std::array<glm::vec2, kFeatureCount>& uvs,
                              const std::bitset<kFeatureCount>& present);

struct Face;

// The anchored layout of a face with its own UVs (the mesh's texcoords2D, v
// up): where each present feature point sits in the face's UV space, y down.
// A feature point on a skin vertex takes that vertex's UV. One on another part
// (the pupils 3.5/3.6 on the eyeballs, teeth, tongue) or at a free position
// (7.1 inside the neck) has no UV of the skin, yet the wrinkles are placed
// from it (the pupils set the face unit): it gets the UV the skin around it
// would give it, an affine map from frontal position (x, y) to UV fitted by
// least squares to the nearest feature points on skin vertices (their
// distance-weighted mean UV where that fit strays far outside their UVs).
// This assumes the skin's UVs are one upright island around the face (the
// brows above the eyes, the face's left to the image's right), which is what
// painting wrinkles across the glabella needs anyway. Throws
// emoface::InputError naming the face when the mesh has no UVs, or the
// feature points' UVs span no area.
FeatureLayout anchored_layout(const Face& face);

// A layout as JSON, so a painted key map can come with its own layout:
//   {"convention": "...", "points": {"2.1": [x, y], ...}}
// with x, y normalised, y down the image. Points not listed are absent.
std::string layout_to_json(const FeatureLayout& layout);
FeatureLayout layout_from_json(std::string_view text, const std::string& source);
void save_layout(const FeatureLayout& layout, const std::string& path);  // temp + rename
FeatureLayout load_layout(const std::string& path);

// A feature line: two feature-point indices.
struct FeatureLine {
    int from = 0;
    int to = 0;
    std::string region;
};

// Loads data/expression/feature_lines.json (format described in the file).
// Errors name the file and the offending entry.
std::vector<FeatureLine> load_feature_lines(const std::string& path);

// The lines whose two end points `present` holds, so that every layout of
// one face has the same line count.
std::vector<FeatureLine> lines_for_face(const std::vector<FeatureLine>& lines,
                                        const std::bitset<kFeatureCount>& present);

struct Segment {
    glm::vec2 p{0.0f};
    glm::vec2 q{0.0f};
};

// A layout's line segments, one per line, in the same order. A segment
// shorter than `min_length` (normalised units) in this pose is returned with
// p == q; the morph skips zero-length target lines for that pose.
std::vector<Segment> layout_segments(const std::vector<FeatureLine>& lines,
                                     const FeatureLayout& layout,
                                     float min_length = 1e-4f);

// The face's neutral layout must give every line a length (the morph's key 0
// defines the lines): throws InputError naming `source` (the face's file) and
// the two feature points of the first line shorter than `min_length`.
void check_lines_have_length(const std::vector<FeatureLine>& lines, const FeatureLayout& neutral,
                             const std::string& source, float min_length = 1e-4f);

}  // namespace emoface::expression
