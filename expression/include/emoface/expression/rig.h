#pragma once
// The FAP rig: low-level FAPs move a face's feature points, and the mesh
// follows (DESIGN.md, "One frame").
//
// Each FAP moves its feature point by value x FAPU along the FAP table's
// direction (x = face's left, y = up, z = to the viewer). Vertices follow
// through the influence weights computed once in the constructor:
//  - point FAPs (lips, chin boss, eyelids, brows, cheeks, nose, ears, tongue)
//    move the skin as a sheet: a smooth partition of unity of C2 bells over
//    geodesic (along-the-mesh) distance, corrected so that each feature
//    point moves exactly by its own FAPs. Distances along the skin keep an
//    upper-lip FAP off the lower lip across the closed mouth and a lid off
//    the other lid. Feature points no FAP moves that should stay put (eye
//    corners, nose base, jaw corners, ear roots) are anchors. A frame's
//    FAPs are first clamped to human ranges (RigOptions::ranges) and the
//    inner and outer lip contours move together;
//  - on a face with eyeballs and eyelid margins, FAPs 19-22 close a lid along
//    its whole length (the margin moves by the lid opening at each point),
//    lid skin slides over the eyeball instead of sinking into it, and the
//    upper lid's inner part follows the inner brow;
//  - FAP 3 (open_jaw) rotates the jaw, lower lip and chin about the jaw pivot
//    so that 2.1 drops by value x MNS; 14 and 15 translate the jaw;
//  - FAPs 23-28 rotate and thrust the eyeballs about their centres, 29/30
//    grow the pupils by sliding the iris vertices over the eyeball;
//  - FAPs 48-50 rotate the head about 7.1 (head pivot), fading down the neck.
// Per frame the host turns the FAPs into a RigFrame (a few hundred doubles:
// frame()), and each vertex's position is the one kernel body of
// rig_kernel.h over the precomputed flat arrays (view()): on all cores here,
// on the GPU in render's CUDA geometry driver. No allocation once `out` has
// its size.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "emoface/expression/face.h"
#include "emoface/expression/fap_values.h"
#include "emoface/expression/rig_kernel.h"
#include "emoface/fap/fap_table.h"

namespace emoface::expression {

namespace detail {
class GeodesicGraph;
}

// The human range of each low-level FAP (data/expression/fap_ranges.json):
// the rig clamps a frame's FAPs into it, so values no face can reach move the
// face as far as it goes instead of tearing the mesh. Default: unbounded.
struct FapRanges {
    std::array<double, fap::kFapCount> lower, upper;  // index FAP - 1
    FapRanges();
    double min(int fap) const { return lower.at(fap - 1); }
    double max(int fap) const { return upper.at(fap - 1); }
    // `faps` with each value clamped into its range; `clamped` (optional)
    // counts the values that were outside.
    FapValues clamp(const FapValues& faps, int* clamped = nullptr) const;
};

// The inner and outer lip contours (FAPs 4-13 and 51-60) are the two edges
// of one vermilion: in the returned values a contour the frame leaves at 0
// takes its partner's value. The rig applies this to every frame.
FapValues lip_contours_together(FapValues faps);

// Reads {"faps": {FAP name: {"range": [min, max], "why": text}}} with every
// low-level FAP named once; throws emoface::InputError naming the file and
// key for a missing or unknown FAP, or a range with min > 0 or max < 0.
FapRanges load_fap_ranges(const std::string& path);

struct RigOptions {
    // Multiplies every influence radius (1 = the built-in radii, which scale
    // with the face's eye separation ES0).
    double radius_scale = 1.0;
    // Each frame's FAPs are clamped into these first.
    FapRanges ranges;
};

// A face after one frame of FAPs.
struct DeformedFace {
    std::vector<TriMesh::Point> positions;  // one per mesh vertex
    // Current positions of the 84 feature points, indexed like
    // fap::feature_points(); absent ones stay (0, 0, 0).
    fap::FeaturePointPositions feature_points{};
};

class FaceRig {
public:
    // Precomputes the influences; throws emoface::InputError when the face
    // lacks what FAPU need or is inconsistent (validate_face()).
    explicit FaceRig(const Face& face, const RigOptions& options = {});

    void deform(const FapValues& faps, DeformedFace& out) const;
    DeformedFace deform(const FapValues& faps) const;
    // The rig as it ran before the kernel body, one stage after the other
    // over the whole mesh, on one thread: the oracle the kernel's tests
    // compare with (rig_reference.cpp).
    DeformedFace deform_reference(const FapValues& faps) const;

    // Only the feature points: the kernel body at their vertices alone.
    fap::FeaturePointPositions feature_points(const FapValues& faps) const;

    // The frame's parameters for the kernel body (FAPs clamped, lip
    // contours together, point displacements, rigid transforms).
    RigFrame frame(const FapValues& faps) const;
    // The face's flat arrays, in host memory (valid while the rig lives).
    RigView view() const;
    // The feature points for a frame, from its parameters.
    fap::FeaturePointPositions feature_points(const RigFrame& frame) const;

    // Writes `deformed` into `mesh` (a copy of the face's mesh) and
    // recomputes its normals.
    static void write_to(const DeformedFace& deformed, TriMesh& mesh);

    // Whether FAP `fap` (1..68) moves anything on this face; when not,
    // why_no_effect() says why ("" when it has an effect).
    bool has_effect(int fap) const;
    const std::string& why_no_effect(int fap) const;

    int vertex_count() const { return static_cast<int>(neutral_.size()); }
    // The radius (in the face's units) of a feature point's influence, 0 when
    // it has none (for docs and tests).
    double influence_radius(int feature_point) const;
    // Number of (vertex, feature point) weights of the point FAPs.
    std::size_t influence_count() const { return weights_.size(); }
    // The jaw's share (0..1) of a vertex's motion under FAPs 3, 14, 15.
    float jaw_weight(int vertex) const { return jaw_weight_.at(vertex); }

private:
    struct EyeState {
        int first = 0, count = 0;
        glm::dvec3 centre{0.0};
        double radius = 0, iris_angle = 0, pupil_angle = 0;
        std::vector<float> polar, azimuth;  // per eyeball vertex, neutral
    };
    struct LidWeight {
        int vertex;
        int lid;  // index into lid_fps_
        float weight;
    };
    struct LidVertex {
        int vertex;
        int eye;
        float min_radius;
        float shell_radius;  // neutral distance from the eyeball's centre
        float follow;        // how much a lid FAP carries it (its largest lid weight)
    };

    void build_point_field(const Face& face, double radius_scale);
    // The cheeks' masses (CheekMass entries), on the skin graph of the
    // point field; es = ES0 x radius scale.
    void build_cheek_masses(detail::GeodesicGraph& graph, double es);
    void build_jaw(const Face& face);
    void build_eyes(const Face& face);
    void build_head(const Face& face);
    void point_displacements(const FapValues& faps, std::array<std::array<double, 3>, fap::kFeaturePointCount>& d) const;

    std::vector<TriMesh::Point> neutral_;
    std::vector<VertexPart> parts_;
    std::array<FeaturePointLocation, fap::kFeaturePointCount> fps_{};
    fap::Fapu fapu_{};

    // Point FAPs: feature points in the linear system and the weights of
    // each vertex on them (CSR by vertex).
    std::vector<int> system_fps_;           // feature point index per system entry
    std::vector<double> system_radius_;     // kernel radius per system entry
    std::vector<bool> system_held_;         // entries (and eyelid margins) the point field holds still
    std::vector<int> influence_start_;      // size vertex_count + 1
    std::vector<RigInfluence> weights_;  // system: index into system_fps_
    std::array<int, fap::kFeaturePointCount> system_of_fp_{};    // -1 when not in the system

    // The mouth corners glide over the skin around them (left, right): the
    // mean outward normal of the skin within the corner's reach, towards
    // whose plane point_displacements() tilts a corner's outward motion.
    void build_corner_glide(const Face& face);
    std::array<glm::dvec3, 2> corner_normal_{};

    // Jaw.
    std::vector<float> jaw_weight_;
    std::vector<int> jaw_vertices_;
    glm::dvec3 jaw_pivot_{0.0};
    bool has_jaw_ = false;

    // Eyes and eyelids.
    std::vector<EyeState> eyes_;
    // The fields with their own weights beside the point field: the lids
    // (3.1-3.4 where the face has eyelid margins), the inner brows' share of
    // the upper lids, the lower lids' bulges and the cheeks' masses. Each
    // entry is driven by the feature point lid_fps_[i] as its kind says.
    enum class Driven : char {
        Follow,     // moves as the feature point moves
        LidBulge,   // the skin below a lower margin, forward as the margin rises
        CheekMass,  // the apple of the cheek, up and forward as the cheek and the mouth corner rise
    };
    std::vector<int> lid_fps_;
    std::vector<Driven> lid_kind_;
    // Per CheekMass entry: the mouth corner and the upper lip's outer point
    // (-1 when absent) whose rise bunches it, and which way is out (+1 on
    // the face's left).
    struct CheekMass {
        int corner;
        int lip;
        double out;
    };
    std::vector<CheekMass> cheek_mass_;  // indexed like lid_fps_ (unused but for CheekMass entries)
    // Entry i's displacement, from the feature points' displacements.
    std::array<double, 3> lid_displacement(std::size_t i,
                                           const std::array<std::array<double, 3>, fap::kFeaturePointCount>& fp_d) const;
    std::vector<LidWeight> lid_weights_;
    std::vector<LidVertex> lid_vertices_;
    // Eyelashes: a strand whose first vertex is welded to a lid margin
    // vertex rides on that vertex, turning with it about the eyeball.
    struct LashVertex {
        int vertex;
        int anchor;  // the margin vertex
        int eye;
    };
    std::vector<LashVertex> lash_vertices_;

    // Head.
    glm::dvec3 head_pivot_{0.0};
    std::vector<float> head_weight_;

    std::array<std::string, fap::kFapCount> no_effect_{};
    FapRanges ranges_;

    // The kernel body's flat arrays (rig_kernel.h), from the above.
    void build_kernel_arrays();
    struct KernelArrays {
        std::vector<int> lid_start;
        std::vector<RigLidWeight> lid_weights;
        std::vector<int> slide_start;
        std::vector<RigSlide> slides;
        std::vector<int> lash_anchor, lash_eye, eye_of;
        std::vector<float> jaw_weight, eye_polar, eye_azimuth;
    } kernel_;
};

}  // namespace emoface::expression
