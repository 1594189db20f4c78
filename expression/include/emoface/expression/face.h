#pragma once
// A face the rig can drive: the neutral mesh, where its 84 MPEG-4 feature
// points are, its FAPU, the parts that move rigidly (eyeballs, jaw-borne mouth
// interior), a frontal texture box for the projective wrinkle layout and a
// base-colour image.
//
// Coordinates (DESIGN.md, MPEG-4): x = the face's left (the viewer's right),
// y = up, z = towards the viewer. The default face is in millimetres; imported
// faces keep their own units (FAPU make the rig unit-free).
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "emoface/expression/feature_layout.h"
#include "emoface/expression/mesh.h"
#include "emoface/fap/fapu.h"

namespace emoface::expression {

using Vec3d = std::array<double, 3>;

// Where one feature point is on a face. A feature point is either a mesh
// vertex (vertex >= 0, position = that vertex's neutral position) or a free
// position the mesh has no vertex for (e.g. 7.1, the top of the spine, inside
// the neck). Absent ones (present == false) are those a face does not model;
// Candide-3 lacks the tongue, teeth and ears, for instance.
struct FeaturePointLocation {
    bool present = false;
    int vertex = -1;
    Vec3d position{0.0, 0.0, 0.0};
};

// What a vertex belongs to; the rig moves each part by its own rule.
enum class VertexPart : std::uint8_t {
    Skin = 0,        // the deformable surface (face, head, neck, ears)
    EyeballLeft = 1, // rigid, rotates about Eyeball::centre (FAPs 23, 25, 27, 29)
    EyeballRight = 2,
    MouthUpper = 3,  // mouth cavity roof and upper teeth: move with the head only
    MouthLower = 4,  // cavity floor and lower teeth: move rigidly with the jaw
    Tongue = 5,      // moves with the jaw plus tongue FAPs 43-47
};
const char* part_name(VertexPart part);

// A vertex index range [first, first + count).
struct VertexRange {
    int first = 0;
    int count = 0;
    bool contains(int v) const { return v >= first && v < first + count; }
    int end() const { return first + count; }
};

// An eyeball: a closed sphere-like group of vertices (a contiguous range of
// Face::mesh) whose front pole (+z) is the pupil centre, feature point 3.5 or
// 3.6. The iris and pupil are painted in the base colour at polar angles
// iris_angle and pupil_angle (radians from +z); pupil dilation (FAPs 29/30)
// slides the vertices inside iris_angle along the sphere.
//
// upper_margin / lower_margin are the skin vertices of the eyelid margins from
// the inner to the outer eye corner (both lists start and end at the shared
// corner vertices). With them the rig closes a lid along its whole length
// (FAPs 19-22); without them (imported faces) it falls back to radial weights.
struct Eyeball {
    VertexRange vertices;
    Vec3d centre{0.0, 0.0, 0.0};
    double radius = 0.0;
    double iris_angle = 0.0;
    double pupil_angle = 0.0;
    std::vector<int> upper_margin;
    std::vector<int> lower_margin;
};

// The frontal box the projective texture layout maps to [0,1]^2 (DESIGN.md,
// "Texture layouts") is expression::TextureBox of feature_layout.h (one type
// for both headers; project_to_texture() gives u to the right, v down).

// An RGBA8 image, rows stored top to bottom (row 0 is the image's top, as in
// PNG files). Texture coordinates follow OBJ/OpenGL: v = 0 is the bottom row,
// so texel row r covers v = 1 - (r + 0.5) / height.
struct Image {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> rgba;  // width * height * 4

    bool empty() const { return width == 0 || height == 0; }
};

struct Face {
    std::string name;
    // Neutral mesh with vertex normals and the fixed base-colour UVs
    // (texcoords2D) requested and filled.
    TriMesh mesh;
    // One VertexPart per mesh vertex (uint8 of VertexPart).
    std::vector<VertexPart> parts;
    // Indexed like fap::feature_points() (0 = "2.1" ... 83 = "11.6").
    std::array<FeaturePointLocation, kFeatureCount> feature_points{};
    fap::Fapu fapu{};
    // [0] = left eye (x > 0), [1] = right eye, when the face has eyeballs.
    std::vector<Eyeball> eyeballs;
    // Pivot of the jaw rotation (FAP 3) and of the head (FAPs 48-50; this is
    // feature point 7.1 when present).
    Vec3d jaw_pivot{0.0, 0.0, 0.0};
    Vec3d head_pivot{0.0, 0.0, 0.0};
    TextureBox texture_box{};
    // Base colour (skin, lips, brows, eyes, mouth interior) addressed by the
    // mesh's texcoords; empty for an imported face without a texture.
    Image base_colour;
    // For a face loaded from files: the base-colour image its FDP names
    // (absolute path, "" if none); the renderer loads it.
    std::string base_colour_file;
    // The file the face was read from (the FDP of an OBJ face, the .wfm),
    // for messages about its geometry; "" for the generated default face.
    std::string source;
    // Pairs of vertices that are one point of the surface, split only so
    // each can carry its own texture coordinate (UV seams). The rig moves
    // them alike; the default face's eye and mouth slits are NOT welded.
    std::vector<std::array<int, 2>> welded;

    int vertex_count() const { return static_cast<int>(mesh.n_vertices()); }
    bool has(int feature_point) const { return feature_points.at(feature_point).present; }
    // Neutral position of a feature point (throws when absent).
    const Vec3d& position(int feature_point) const;
    // All 84 neutral positions, absent ones (0, 0, 0), in the layout
    // fap::compute_fapu() takes.
    fap::FeaturePointPositions positions() const;
};

// Recomputes face.fapu from the feature points with fap::compute_fapu().
// Throws emoface::InputError naming the missing feature points when one of
// those FAPU need (3.1, 3.3, 3.5, 3.6, 9.15, 2.2, 8.3, 8.4) is absent, and when
// the face is mirrored (ES0 or MW0 not positive: x must be the face's left).
// Messages name `source` (the file the face came from) or else the face.
void update_fapu(Face& face, const std::string& source = {});

// Checks the invariants the rig relies on (sizes agree, feature point vertices
// in range, eyeball ranges inside the mesh); throws emoface::InputError with
// `context` in the message otherwise.
void validate_face(const Face& face, const std::string& context);

// Sets jaw_pivot and head_pivot from the feature points, for faces that do
// not give them (Candide-3, an FDP without pivots): the jaw pivot behind the
// outer eye corners at the height between the eyes and the nose base, the
// head pivot (7.1 when present) below and behind it.
void estimate_pivots(Face& face);

// The face's texture box around its skin in frontal projection, with a margin.
TextureBox frontal_box(const Face& face);

// Feature points the face lacks, as ids ("6.1", ...), in table order.
std::vector<std::string> missing_feature_points(const Face& face);

}  // namespace emoface::expression
