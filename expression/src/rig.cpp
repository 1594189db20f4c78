#include "emoface/expression/rig.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string_view>

#include <glm/glm.hpp>

#include "emoface/common/constants.h"
#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
#include "emoface/fap/feature_points.h"
#include "emoface/fap/fapu.h"
#include "geodesic.h"
#include "json_reader.h"

namespace emoface::expression {
namespace {

using V = glm::dvec3;

V to_v(const TriMesh::Point& p) { return {p[0], p[1], p[2]}; }
V to_v(const std::array<double, 3>& p) { return {p[0], p[1], p[2]}; }
std::array<double, 3> to_array(const V& v) { return {v.x, v.y, v.z}; }

double raised_cosine(double t) { return t >= 1.0 ? 0.0 : 0.5 * (1.0 + std::cos(kPi * t)); }

// Rotations about the axes (glm::dmat3 is column-major: each group of three
// is a column).
glm::dmat3 rot_x(double a) {
    const double c = std::cos(a), s = std::sin(a);
    return {1, 0, 0, 0, c, s, 0, -s, c};
}
glm::dmat3 rot_y(double a) {
    const double c = std::cos(a), s = std::sin(a);
    return {c, 0, -s, 0, 1, 0, s, 0, c};
}
glm::dmat3 rot_z(double a) {
    const double c = std::cos(a), s = std::sin(a);
    return {c, s, 0, -s, c, 0, 0, 0, 1};
}

bool is_point_fap(int f) {
    return (f >= 4 && f <= 13) || (f >= 16 && f <= 22) || (f >= 31 && f <= 46) || (f >= 51 && f <= 68);
}

// Kernel radius of a feature point as a fraction of ES0 (eye separation).
// The kernels are bells with no plateau, so they are wide: about twice the
// distance to the neighbours on the same feature, and wider where skin moves
// in broad sheets: a brow's reaches the hairline (the forehead rises as one
// sheet), a cheek's the cheekbone and the jaw. The anchors' hold fades as
// gently as the moving points' pull, or the skin creases against them. The
// mouth corners' (2.4, 2.5, 8.3, 8.4) reach the cheek and the jaw's side: at
// 0.32 a corner drawn down or out pushed the skin ahead of it together into
// a crescent (to 0.43 of its length below the corner in AU15, now 0.61),
// the bulges beside the mouth corners in sadness and fear and the lump and
// fold on fear's jaw, and creased AU12 by 54 degrees and AU20 by 50 (now 14
// and 24, rig_smoothness_test).
double radius_factor(std::string_view id) {
    static const std::map<std::string_view, double> table = {
        {"2.2", 0.26},  {"2.3", 0.26},  {"2.4", 0.45},  {"2.5", 0.45},  {"2.6", 0.26},  {"2.7", 0.26},
        {"2.8", 0.26},  {"2.9", 0.26},  {"2.10", 0.5},  {"2.11", 0.3},  {"2.12", 0.3},  {"2.13", 0.35},
        {"2.14", 0.35}, {"3.1", 0.22},  {"3.2", 0.22},  {"3.3", 0.18},  {"3.4", 0.18},  {"3.7", 0.15},
        {"3.8", 0.15},  {"3.11", 0.15}, {"3.12", 0.15}, {"4.1", 1.0},   {"4.2", 1.0},   {"4.3", 1.05},
        {"4.4", 1.05},  {"4.5", 1.0},   {"4.6", 1.0},  {"5.1", 0.7},   {"5.2", 0.7},   {"5.3", 0.65},
        {"5.4", 0.65},  {"6.1", 0.3},   {"6.2", 0.3},   {"6.3", 0.25},  {"6.4", 0.25},  {"8.1", 0.28},
        {"8.2", 0.28},  {"8.3", 0.45},  {"8.4", 0.45},  {"8.5", 0.26},  {"8.6", 0.26},  {"8.7", 0.26},
        {"8.8", 0.26},  {"8.9", 0.22},  {"8.10", 0.22}, {"9.1", 0.3},   {"9.2", 0.3},   {"9.3", 0.4},
        {"10.1", 0.5},  {"10.2", 0.5},  {"10.3", 0.5},  {"10.4", 0.5},
    };
    auto it = table.find(id);
    return it == table.end() ? 0.25 : it->second;
}

// The apple of the cheek: the malar fat pad over the zygomaticus, which a
// smile (AU6 pushing from above, AU12 pulling the mouth corner up towards
// the cheekbone) bunches up and forward, lateral to the nasolabial fold,
// which it deepens. Its rise is the cheek point's rise plus kCornerShare of
// the mouth corner's and kUpperLipShare of the upper lip's outer point's (AU10:
// the levator labii lifts the infraorbital triangle with the lip and deepens
// the fold's upper part); it moves by kMassUp of that up, kMassForward forward
// and kMassOut out (kMassUp < 0: see below), most at its centre, nothing medial to the fold.
// Observers saw a smile that "moves only the mouth" when the cheek only slid
// up with the skin (issue 11); a Duchenne cheek comes 3-6 mm forward. At
// kMassForward 0.35 (joy 4.7 mm) a blind observer still saw cheeks that "do
// not lift enough" at 512 px; 0.45 brings joy's 6 mm.
constexpr double kCornerShare = 1.2, kUpperLipShare = 1.0;
// The sheet already carries the mass up with the cheek point; held back by a
// fifth of its rise, it does not crowd the skin under the lower lid further
// (which creased it past the smoothness bound: a tenth, with the mass centred
// under the eye, creased the lid's junction with the cheek by 9.2 degrees in
// AU6+AU12, a fifth 8.4; joy's cheek still rises 6 mm).
constexpr double kMassUp = -0.2, kMassForward = 0.45, kMassOut = 0.06;
// Its reach from its centre, and the fold's width (inside, outside), in ES0.
// Its bell is (1 - t^2)^3, round on top: a C2 Wendland bell over 0.45 ES0
// bends most at its peak, and joy's apple came forward as a pointed crest
// (14 degrees of crease at its top on the half-resolution test face, now 5)
// with a steep outer flank that the key light drew as a dark streak from
// below the outer eye corner to the nose wing at 512 px (blind review,
// session 9). Centred 0.6 of the way to the cheekbone, over 0.6 ES0 it
// reached the nose wing, past the fold's top, and creased the skin there
// (AU6 30 degrees); centred further out (kCentreOnCheekbone) only its thin
// edge reaches the fold's top.
constexpr double kMassRadius = 0.65, kFoldInside = 0.02, kFoldOutside = 0.10;
// Its centre's share of the cheekbone (5.3) against the nose wing (9.1).
// At 0.6 over 0.55 ES0 the apple rose 6 mm forward low beside the nose while
// the skin above it, below the outer half of the lower lid, rose with the
// lid: between them ran a valley in the skin's forward motion, 1.8 mm deep
// in joy and 2.2 in AU6+AU12 (rig_cheek_test), from beside the nose wing
// towards the outer eye corner: the "diagonal groove ... like a crushed
// mesh" a blind observer saw on joy's shadow-side cheek (round 14). Centred
// further out under the eye and broader (0.65 ES0, so its top stays round),
// the mass fills most of it (0.6 and 0.8 mm) and still comes 6 mm forward.
// Further out or broader it filled it all but creased the skin below the
// outer lower lid (9.8 degrees at 0.95 over 0.75 ES0) or swelled the lid's
// bulge (AU6 3.7 mm over 0.8 ES0, eyelid_test). The fold still cuts it off
// medially; the cheek point now lies near its top, so a cheek FAP brings it
// forward with the apple (rig_test).
constexpr double kCentreOnCheekbone = 0.75;
// The lower lid's share of the cheek's rise at its widest (AU6 pushing it
// from below), how sharply that share peaks there (a power of the opening's
// fraction: the ends stay), and how far below the margin the lid's skin
// follows (in lid fades).
constexpr double kCheekPush = 0.28, kCheekPushPeak = 3.0, kCheekPushFade = 1.5;

// C2 bell, 1 at t = 0 and flat there, 0 from t = 1 on.
double wendland(double t) { return t >= 1.0 ? 0.0 : std::pow(1.0 - t, 4) * (4.0 * t + 1.0); }

// Feature points no FAP moves that hold the skin around them in place.
bool is_anchor(std::string_view id) {
    static const char* anchors[] = {"3.7",  "3.8",  "3.11", "3.12", "9.4",  "9.5",  "9.6",  "9.7",  "9.12",
                                    "9.13", "9.14", "9.15", "2.11", "2.12", "2.13",
                                    "2.14", "10.5", "10.6", "10.7", "10.8", "10.9", "10.10"};
    for (const char* a : anchors)
        if (id == a) return true;
    return false;
}

// y of a margin polyline at x (linear between its vertices), and whether x
// is within it.
bool margin_y(const std::vector<std::array<double, 2>>& m, double x, double* y) {
    for (std::size_t i = 0; i + 1 < m.size(); ++i) {
        const double x0 = m[i][0], x1 = m[i + 1][0];
        if ((x >= x0 && x <= x1) || (x >= x1 && x <= x0)) {
            const double t = x1 == x0 ? 0.0 : (x - x0) / (x1 - x0);
            *y = m[i][1] + t * (m[i + 1][1] - m[i][1]);
            return true;
        }
    }
    return false;
}


// The jaw under FAPs 3 (open), 14 (thrust) and 15 (shift): a turn about the
// pivot that drops the chin (`chin`, from the pivot) by open x MNS, and a
// translation. The condyles glide forward as the jaw opens (the mandible
// turns and slides, so the chin goes down more than back). Turned about the
// pivot alone (which sits high over the chin here) the chin swung back 1.4
// times as far as it dropped and the jaw's angle as far, against skin the
// jaw carries only part of the way (build_jaw's fades): it was pushed
// together to under half its length over the jaw's side, the lump along the
// jaw line and the "balloon" of surprise's lower face at 512 px. The glide
// cancels kJawGlide of the chin's backward swing (RigSmoothness measures
// the stretch).
constexpr double kJawGlide = 0.6;

struct JawMotion {
    glm::dmat3 r{1.0};
    V t{0.0};
};

JawMotion jaw_motion(const V& chin, double open, double thrust, double shift, const fap::Fapu& fapu) {
    JawMotion m;
    const double drop = open * fapu.mns;
    const double a = std::hypot(chin[1], chin[2]);
    const double phi0 = std::atan2(chin[2], chin[1]);
    const double angle = a > 0 ? std::acos(std::clamp((chin[1] - drop) / a, -1.0, 1.0)) - phi0 : 0.0;
    m.r = rot_x(angle);
    const auto& i14 = fap::fap_info(14);
    const auto& i15 = fap::fap_info(15);
    const double back = (m.r * chin)[2] - chin[2];
    for (int c = 0; c < 3; ++c)
        m.t[c] = thrust * fapu.of(i14.unit) * i14.direction[c] + shift * fapu.of(i15.unit) * i15.direction[c];
    m.t[2] -= kJawGlide * back;
    return m;
}

}  // namespace

// Both contours move: the corners, where they lie 2 mm apart, would tear
// into a stitch if one moved alone (vreng's files send only FAPs 51-60).
FapValues lip_contours_together(FapValues faps) {
    for (int inner = 4; inner <= 13; ++inner) {
        double& a = faps[inner - 1];
        double& b = faps[inner + 47 - 1];  // 4 -> 51 ... 13 -> 60
        if (a == 0.0) a = b;
        else if (b == 0.0) b = a;
    }
    return faps;
}

FapRanges::FapRanges() {
    lower.fill(-std::numeric_limits<double>::infinity());
    upper.fill(std::numeric_limits<double>::infinity());
}

FapValues FapRanges::clamp(const FapValues& faps, int* clamped) const {
    FapValues out;
    for (int i = 0; i < fap::kFapCount; ++i) {
        out[i] = std::clamp(faps[i], lower[i], upper[i]);
        if (clamped && out[i] != faps[i]) ++*clamped;
    }
    return out;
}

FapRanges load_fap_ranges(const std::string& path) {
    FapRanges r;
    std::array<bool, fap::kFapCount> seen{};
    detail::read_json_file(path, [&](detail::JsonReader& top) {
        top.comment("_about");
        for (auto& [name, entry] : top.object("faps").entries()) {
            const auto f = fap::find_fap(name);
            if (!f || *f < 3) entry.fail("a low-level FAP name (open_jaw ... pull_r_ear)", "\"" + name + "\"");
            if (seen[*f - 1]) entry.fail("each FAP once", "\"" + name + "\" again");
            seen[*f - 1] = true;
            const auto range = entry.numbers<2>("range");
            if (!(range[0] <= 0 && range[1] >= 0))
                entry.at("range").fail("[min <= 0, max >= 0] (rest is in every range)");
            entry.comment("why");
            entry.finish();
            r.lower[*f - 1] = range[0];
            r.upper[*f - 1] = range[1];
        }
        for (int f = 3; f <= fap::kFapCount; ++f)
            if (!seen[f - 1])
                top.at("faps").fail("every low-level FAP", fmt::format("no \"{}\"", std::string(fap::fap_info(f).name)));
    });
    return r;
}

FaceRig::FaceRig(const Face& face, const RigOptions& options) {
    validate_face(face, "face \"" + face.name + "\"");
    if (!(options.radius_scale > 0.05 && options.radius_scale < 20))
        fail<InputError>("expression: rig: radius_scale must be in (0.05, 20), found {}", options.radius_scale);
    const int n = face.vertex_count();
    neutral_.resize(n);
    for (int v = 0; v < n; ++v) neutral_[v] = face.mesh.point(TriMesh::VertexHandle(v));
    parts_ = face.parts;
    fps_ = face.feature_points;
    fapu_ = face.fapu;
    ranges_ = options.ranges;
    if (!(fapu_.es > 0 && fapu_.mns > 0 && fapu_.mw > 0 && fapu_.ens > 0 && fapu_.irisd > 0))
        fail<InputError>("expression: rig: face \"{}\" has no FAPU (call update_fapu)", face.name);

    build_point_field(face, options.radius_scale);
    build_corner_glide(face);
    build_jaw(face);
    build_eyes(face);
    build_head(face);
    build_kernel_arrays();

    for (int f = 1; f <= fap::kFapCount; ++f) {
        std::string& why = no_effect_[f - 1];
        if (f <= 2) {
            why = "high-level FAP: face_state() turns it into low-level FAPs";
            continue;
        }
        const auto& info = fap::fap_info(f);
        const auto fp = fap::find_feature_point(info.feature_point);
        if (is_point_fap(f) || f == 47) {
            const bool ok = fp && system_of_fp_[*fp] >= 0 &&
                            (f != 47 || system_of_fp_[fap::feature_point_index("6.4")] >= 0) &&
                            (!system_held_[system_of_fp_[*fp]] ||
                             std::find(lid_fps_.begin(), lid_fps_.end(), *fp) != lid_fps_.end());
            if (!ok)
                why = fmt::format("the face has no vertex for feature point {}", std::string(info.feature_point));
        } else if (f == 3 || f == 14 || f == 15) {
            if (!has_jaw_) why = "the face lacks the chin or lip feature points the jaw needs";
        } else if (f >= 23 && f <= 30) {
            const bool left = (f % 2) == 1;
            bool found = false;
            for (const EyeState& e : eyes_) found |= (e.centre[0] > 0) == left;
            if (!found) why = "the face has no eyeball meshes";
        }
    }
}

void FaceRig::build_point_field(const Face& face, double radius_scale) {
    const int n = face.vertex_count();
    const double es0 = fapu_.es * 1024.0;
    system_of_fp_.fill(-1);

    // Eyelid margins (faces with eyeballs): the lid FAPs close a lid along
    // its whole margin, in proportion to the opening at each point, through
    // their own field; the point field holds the margins still.
    struct Lid {
        std::vector<std::array<double, 2>> upper, lower;
        std::vector<int> vertices;
    };
    std::array<Lid, 2> lids;
    std::array<bool, 2> has_lid{false, false};
    for (const Eyeball& eb : face.eyeballs) {
        if (eb.upper_margin.size() < 3) continue;
        const int side = eb.centre[0] > 0 ? 0 : 1;
        has_lid[side] = true;
        for (int v : eb.upper_margin) lids[side].upper.push_back({neutral_[v][0], neutral_[v][1]});
        for (int v : eb.lower_margin) lids[side].lower.push_back({neutral_[v][0], neutral_[v][1]});
        lids[side].vertices = eb.upper_margin;
        lids[side].vertices.insert(lids[side].vertices.end(), eb.lower_margin.begin(), eb.lower_margin.end());
    }
    auto lid_side = [](std::string_view id) { return (id == "3.1" || id == "3.3") ? 0 : 1; };
    auto is_lid = [&](std::string_view id) {
        return (id == "3.1" || id == "3.2" || id == "3.3" || id == "3.4") && has_lid[lid_side(id)];
    };

    // Which feature points take part: those a point FAP moves, and anchors.
    std::array<bool, fap::kFeaturePointCount> driven{};
    for (int f = 3; f <= fap::kFapCount; ++f) {
        if (!is_point_fap(f) && f != 47) continue;
        const auto fp = fap::find_feature_point(fap::fap_info(f).feature_point);
        if (fp) driven[*fp] = true;
        if (f == 47) driven[fap::feature_point_index("6.4")] = true;
    }
    struct Entry {
        std::vector<int> sources;
        double radius;
        bool held;  // displacement always 0 in the point field
    };
    std::vector<Entry> entries;
    std::map<int, int> entry_of_vertex;
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const FeaturePointLocation& fp = fps_[k];
        if (!fp.present || fp.vertex < 0) continue;
        const auto id = fap::feature_points()[k].id;
        if (!driven[k] && !is_anchor(id)) continue;
        // Points that share a vertex share one entry (Candide-3 has a few).
        auto [it, inserted] = entry_of_vertex.emplace(fp.vertex, static_cast<int>(entries.size()));
        if (inserted) {
            entries.push_back({{fp.vertex}, radius_factor(id) * es0 * radius_scale, is_lid(id)});
            system_fps_.push_back(k);
        }
        system_of_fp_[k] = it->second;
    }
    // Neighbouring points of one feature (a brow, a lip contour) must
    // overlap, or the skin between two points moved alike sags: each radius
    // reaches 1.3 times as far as the nearest driven point of its group, up
    // to twice its table value.
    for (std::size_t j = 0; j < entries.size(); ++j) {
        const int k = system_fps_[j];
        if (!driven[k]) continue;
        const int group = fap::feature_points()[k].group;
        double nearest = 1e30;
        for (std::size_t i = 0; i < entries.size(); ++i) {
            const int q = system_fps_[i];
            if (i == j || !driven[q] || fap::feature_points()[q].group != group) continue;
            nearest = std::min(nearest, glm::length(to_v(fps_[k].position) - to_v(fps_[q].position)));
        }
        if (nearest < 1e29) entries[j].radius = std::clamp(1.3 * nearest, entries[j].radius, 2.0 * entries[j].radius);
    }
    for (const Entry& e : entries) system_radius_.push_back(e.radius);
    for (int side = 0; side < 2; ++side)
        if (has_lid[side]) entries.push_back({lids[side].vertices, 0.1 * es0 * radius_scale, true});
    system_held_.clear();
    for (const Entry& e : entries) system_held_.push_back(e.held);

    // A smooth partition of unity over geodesic distance, corrected to
    // interpolate. Each entry j has a bell phi_j = wendland(g / R_j) (C2,
    // flat at its centre, no plateau and no edge); a vertex's share of entry
    // j is phi_j / (B + sum_k phi_k), where the background B stands for "no
    // motion" and held entries (lid margins) and anchors count in the sum
    // with no displacement of their own. So skin fades from moved to unmoved
    // over the kernels' whole width, as a stretched sheet does, without the
    // ridge a plateau-and-edge kernel leaves, and nothing overshoots a
    // convex combination by much. The shares at the moving points form a
    // small matrix S (S_ij = share of j at point i); the controls
    // c = S^-1 d make every point move exactly by its own FAPs, and a
    // vertex's weights on the displacements are its shares times S^-1,
    // computed once here.
    constexpr double kBackground = 0.5;
    detail::GeodesicGraph graph(face.mesh, face.welded);
    std::vector<std::vector<std::pair<int, double>>> reach(n);  // (entry, share)
    for (std::size_t j = 0; j < entries.size(); ++j)
        for (auto [v, g] : graph.within(entries[j].sources, entries[j].radius))
            reach[v].emplace_back(static_cast<int>(j), wendland(g / entries[j].radius));
    for (auto& r : reach) {
        double total = kBackground;
        for (const auto& [j, phi] : r) total += phi;
        for (auto& [j, phi] : r) phi /= total;
    }
    // The moving entries (driven by a FAP, not held), numbered 0..m-1.
    std::vector<int> moving_of_entry(entries.size(), -1);
    std::vector<int> moving;
    for (std::size_t j = 0; j < entries.size(); ++j)
        if (!entries[j].held && driven[system_fps_[j]]) {
            moving_of_entry[j] = static_cast<int>(moving.size());
            moving.push_back(static_cast<int>(j));
        }
    const int m = static_cast<int>(moving.size());
    std::vector<double> inverse(static_cast<std::size_t>(m) * m, 0.0);  // S^-1, row-major
    {
        std::vector<double> s(static_cast<std::size_t>(m) * m, 0.0);
        for (int i = 0; i < m; ++i) {
            inverse[i * m + i] = 1.0;
            for (const auto& [j, share] : reach[entries[moving[i]].sources[0]])
                if (moving_of_entry[j] >= 0) s[i * m + moving_of_entry[j]] = share;
        }
        // Gauss-Jordan with partial pivoting (m is a few dozen).
        for (int c = 0; c < m; ++c) {
            int pivot = c;
            for (int r = c + 1; r < m; ++r)
                if (std::abs(s[r * m + c]) > std::abs(s[pivot * m + c])) pivot = r;
            if (std::abs(s[pivot * m + c]) < 1e-9)
                fail("expression: rig: the influence of feature point {} is not independent of its neighbours'",
                     std::string(fap::feature_points()[system_fps_[moving[c]]].id));
            for (int k = 0; k < m; ++k) {
                std::swap(s[c * m + k], s[pivot * m + k]);
                std::swap(inverse[c * m + k], inverse[pivot * m + k]);
            }
            const double inv = 1.0 / s[c * m + c];
            for (int k = 0; k < m; ++k) s[c * m + k] *= inv, inverse[c * m + k] *= inv;
            for (int r = 0; r < m; ++r) {
                if (r == c || s[r * m + c] == 0.0) continue;
                const double f = s[r * m + c];
                for (int k = 0; k < m; ++k) s[r * m + k] -= f * s[c * m + k], inverse[r * m + k] -= f * inverse[c * m + k];
            }
        }
    }
    std::vector<int> moving_at_vertex(n, -1);
    for (int i = 0; i < m; ++i) moving_at_vertex[entries[moving[i]].sources[0]] = i;
    influence_start_.assign(n + 1, 0);
    std::vector<double> row(m);
    for (int v = 0; v < n; ++v) {
        influence_start_[v] = static_cast<int>(weights_.size());
        if (moving_at_vertex[v] >= 0) {
            // Exactly its own FAPs (the product below is, up to rounding).
            weights_.push_back({static_cast<std::uint16_t>(moving[moving_at_vertex[v]]), 1.0f});
            continue;
        }
        bool any = false;
        std::fill(row.begin(), row.end(), 0.0);
        for (const auto& [j, share] : reach[v]) {
            const int i = moving_of_entry[j];
            if (i < 0 || share < 1e-7) continue;
            any = true;
            for (int k = 0; k < m; ++k) row[k] += share * inverse[i * m + k];
        }
        if (!any) continue;
        for (int k = 0; k < m; ++k)
            if (std::abs(row[k]) > 1e-4) weights_.push_back({static_cast<std::uint16_t>(moving[k]), static_cast<float>(row[k])});
    }
    influence_start_[n] = static_cast<int>(weights_.size());

    // The lid field: the margin moves by (opening here / opening at the
    // feature point) times the lid FAP, the lid skin beyond it less and less.
    // The held margins still take a share of the brows' wide kernels, so a
    // brow raise (AU1+2) dragged the upper margin up by over half its own
    // rise and bared a band of white above the iris: a stare. The levator,
    // not the frontalis, lifts the margin; the brow lifts the skin above the
    // lid fold. So the brows' weights on the upper lid are shielded, fully
    // at the margin and fading out over the lid's height (the lid fold, 8-12
    // mm up); the inner lid's own share of the brow is the rule below.
    auto add_entry = [&](int fp, Driven kind) {
        lid_fps_.push_back(fp);
        lid_kind_.push_back(kind);
        cheek_mass_.push_back({-1, -1, 0.0});
        return static_cast<int>(lid_fps_.size()) - 1;
    };
    constexpr double kBrowShield = 0.9;
    std::vector<double> brow_shield(n, 0.0);
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const auto id = fap::feature_points()[k].id;
        if (!is_lid(id) || !fps_[k].present || fps_[k].vertex < 0) continue;
        const int side = lid_side(id);
        const bool upper = id == "3.1" || id == "3.2";
        auto opening = [&](double x) {
            double yu, yl;
            if (!margin_y(lids[side].upper, x, &yu) || !margin_y(lids[side].lower, x, &yl)) return 0.0;
            return std::max(yu - yl, 0.0);
        };
        const auto& margin = upper ? lids[side].upper : lids[side].lower;
        const int src = fps_[k].vertex;
        const double o_fp = opening(neutral_[src][0]);
        if (o_fp <= 0) fail("expression: rig: the eye opening at feature point {} is closed", std::string(id));
        // The upper lid's skin folds under the brow as it rises or falls;
        // the lower lid's skin moves as one sheet down to the cheek (AU6 and
        // AU7 lift the infraorbital skin with the margin, where it bunches).
        const double fade = (upper ? 0.14 : 0.17) * es0 * radius_scale;
        const int lid = add_entry(k, Driven::Follow);
        for (auto [v, g] : graph.within({src}, 0.35 * es0 * radius_scale)) {
            if (parts_[v] != VertexPart::Skin) continue;
            const double x = neutral_[v][0], y = neutral_[v][1];
            double ym;
            if (!margin_y(margin, x, &ym)) continue;
            const double h = upper ? y - ym : ym - y;  // beyond the margin, away from the opening
            if (h < -1e-3) continue;
            const double w = std::min(opening(x) / o_fp, 1.0) * raised_cosine(std::max(h, 0.0) / fade);
            if (w > 1e-5) lid_weights_.push_back({v, lid, static_cast<float>(v == src ? 1.0 : w)});
            if (upper)
                brow_shield[v] = std::max(brow_shield[v], kBrowShield * std::min(opening(x) / o_fp, 1.0) *
                                                              raised_cosine(std::max(h, 0.0) / (1.2 * fade)));
        }
        if (!upper) {
            // As the lower margin rises (AU6, AU7), the skin below it
            // bunches into a bulge (FACS: the lower-lid bulge, the "bags"
            // of the Duchenne smile): pushed forward by up to kBulge of the
            // margin's rise, most a third of the lid's height below the
            // margin and nothing at the margin or past the lid's skin.
            constexpr double kBulge = 0.45;
            const int bulge = add_entry(k, Driven::LidBulge);
            for (auto [v, g] : graph.within({src}, 0.35 * es0 * radius_scale)) {
                if (parts_[v] != VertexPart::Skin) continue;
                const double x = neutral_[v][0], y = neutral_[v][1];
                double ym;
                if (!margin_y(margin, x, &ym) || ym - y < 1e-3) continue;
                const double t = (ym - y) / (1.2 * fade);
                if (t >= 1.0) continue;
                const double w = kBulge * std::min(opening(x) / o_fp, 1.0) * std::pow(std::sin(kPi * std::pow(t, 0.75)), 2);
                if (w > 1e-5) lid_weights_.push_back({v, bulge, static_cast<float>(w)});
            }
            // The rising cheek (AU6) pushes the lower lid up from below,
            // most where the eye is open widest: the margin's middle rises
            // over its ends and the lid arches up (the smiling eye), and the
            // lid's skin rises with it so the cheek and lid move as one. The
            // lid FAP alone (AU7) lifts the margin in proportion to the
            // opening, keeping its hollow; a Duchenne lid with only that
            // looked sleepy, not smiling, to observers (issue 11).
            const int cheek = fap::feature_point_index(side == 0 ? "5.3" : "5.4");
            if (fps_[cheek].present && fps_[cheek].vertex >= 0) {
                const int push = add_entry(cheek, Driven::Follow);
                for (auto [v, g] : graph.within({src}, 0.5 * es0 * radius_scale)) {
                    if (parts_[v] != VertexPart::Skin) continue;
                    const double x = neutral_[v][0], y = neutral_[v][1];
                    double ym;
                    if (!margin_y(margin, x, &ym) || ym - y < -1e-3) continue;
                    const double open = std::min(opening(x) / o_fp, 1.0);
                    const double w = kCheekPush * std::pow(open, kCheekPushPeak) *
                                     raised_cosine(std::max(ym - y, 0.0) / (kCheekPushFade * fade));
                    if (w > 1e-5) lid_weights_.push_back({v, push, static_cast<float>(w)});
                }
            }
            continue;
        }
        // The upper lid's inner part follows the inner brow (FACS: AU1
        // draws the inner upper lid up with the brow, AU4 pushes it down and
        // in): the oblique lid of the sad eye. The share peaks a third of
        // the way from the inner corner and is nothing at both corners.
        const int brow = fap::feature_point_index(side == 0 ? "4.1" : "4.2");
        if (!fps_[brow].present) continue;
        constexpr double kBrowFollow = 0.2;
        const double x_inner = margin.front()[0], x_outer = margin.back()[0];
        const int follow = add_entry(brow, Driven::Follow);
        for (auto [v, g] : graph.within({src}, 0.35 * es0 * radius_scale)) {
            if (parts_[v] != VertexPart::Skin) continue;
            const double x = neutral_[v][0], y = neutral_[v][1];
            double ym;
            if (!margin_y(margin, x, &ym) || y - ym < -1e-3) continue;
            const double t = std::clamp((x - x_inner) / (x_outer - x_inner), 0.0, 1.0);
            const double w = kBrowFollow * 6.75 * t * (1 - t) * (1 - t) * raised_cosine(std::max(y - ym, 0.0) / fade);
            if (w > 1e-5) lid_weights_.push_back({v, follow, static_cast<float>(w)});
        }
    }
    build_cheek_masses(graph, es0 * radius_scale);
    for (int v = 0; v < n; ++v) {
        if (brow_shield[v] <= 0.0) continue;
        for (int k = influence_start_[v]; k < influence_start_[v + 1]; ++k)
            if (fap::feature_points()[system_fps_[weights_[k].system]].group == 4)
                weights_[k].weight *= static_cast<float>(1.0 - brow_shield[v]);
    }
}

void FaceRig::build_cheek_masses(detail::GeodesicGraph& graph, double es) {
    auto located = [&](const char* id) {
        const FeaturePointLocation& p = fps_[fap::feature_point_index(id)];
        return p.present && p.vertex >= 0;
    };
    auto at = [&](const char* id) { return to_v(fps_[fap::feature_point_index(id)].position); };
    for (const auto& [cheek_id, corner_id, wing_id, lip_id] :
         {std::array{"5.3", "8.3", "9.1", "8.5"}, std::array{"5.4", "8.4", "9.2", "8.6"}}) {
        if (!located(cheek_id) || !located(corner_id) || !located(wing_id)) continue;
        const V cheek = at(cheek_id), corner = at(corner_id), wing = at(wing_id);
        const double out = cheek[0] > wing[0] ? 1.0 : -1.0;
        // Its centre: below the eye, between the cheekbone and the nose wing;
        // its source, the skin vertex nearest to that.
        const V centre = kCentreOnCheekbone * cheek + (1 - kCentreOnCheekbone) * wing;
        int source = -1;
        double nearest = 1e30;
        for (int v = 0; v < static_cast<int>(neutral_.size()); ++v) {
            if (parts_[v] != VertexPart::Skin) continue;
            const double d = glm::length(to_v(neutral_[v]) - centre);
            if (d < nearest) nearest = d, source = v;
        }
        if (source < 0) continue;
        // The nasolabial fold, seen from the front: from just beside the
        // top of the nose wing down and out to beyond the mouth corner,
        // bowed out towards the cheek (a quadratic curve in x, y).
        const glm::dvec2 a(wing[0] + out * 0.04 * es, wing[1] + 0.04 * es);
        const glm::dvec2 b(corner[0] + out * 0.12 * es, corner[1] - 0.08 * es);
        const glm::dvec2 along = glm::normalize(b - a);
        const glm::dvec2 lateral = glm::dvec2(-along.y, along.x) * (glm::dot(glm::dvec2(-along.y, along.x), glm::dvec2(out, 0.0)) > 0 ? 1.0 : -1.0);
        const glm::dvec2 bow = 0.5 * (a + b) + 0.05 * es * lateral;
        constexpr int kSegments = 16;
        std::array<glm::dvec2, kSegments + 1> fold;
        for (int i = 0; i <= kSegments; ++i) {
            const double t = double(i) / kSegments;
            fold[i] = (1 - t) * (1 - t) * a + 2 * t * (1 - t) * bow + t * t * b;
        }
        // Signed distance from the fold (+ towards the cheek).
        auto beside_fold = [&](const glm::dvec2& p) {
            double best = 1e30, sign = 1.0;
            for (int i = 0; i < kSegments; ++i) {
                const glm::dvec2 e = fold[i + 1] - fold[i];
                const double t = std::clamp(glm::dot(p - fold[i], e) / glm::dot(e, e), 0.0, 1.0);
                const glm::dvec2 q = fold[i] + t * e;
                const double d = glm::length(p - q);
                if (d < best) {
                    best = d;
                    sign = glm::dot(p - fold[i], glm::dvec2(-e.y, e.x) * glm::dot(glm::dvec2(-e.y, e.x), lateral)) >= 0 ? 1.0 : -1.0;
                }
            }
            return sign * best;
        };
        const int entry = static_cast<int>(lid_fps_.size());
        lid_fps_.push_back(fap::feature_point_index(cheek_id));
        lid_kind_.push_back(Driven::CheekMass);
        cheek_mass_.push_back({fap::feature_point_index(corner_id), located(lip_id) ? fap::feature_point_index(lip_id) : -1, out});
        const double radius = kMassRadius * es;
        // Straight-line distance: the graph's edge-path distance zigzags at
        // the mass's scale and creased its top. The search runs kMassSearch
        // times further along the edges, so no vertex the straight-line bell
        // still weights is left out (cut off at the path radius, the bell
        // stepped: a dent from the outer eye corner down the cheek in joy).
        constexpr double kMassSearch = 2.0;
        const V middle = to_v(neutral_[source]);
        for (auto [v, path] : graph.within({source}, kMassSearch * radius)) {
            if (parts_[v] != VertexPart::Skin) continue;
            const double g = glm::length(to_v(neutral_[v]) - middle);
            const double s = beside_fold({neutral_[v][0], neutral_[v][1]});
            const double round = std::max(1.0 - (g / radius) * (g / radius), 0.0);
            const double w = round * round * round * glm::smoothstep(-kFoldInside * es, kFoldOutside * es, s);
            if (w > 1e-5) lid_weights_.push_back({v, entry, static_cast<float>(w)});
        }
    }
}

// The skin around a mouth corner curves back round the dental arch and
// down to the jaw, facing about 45 degrees out beside the corner. A corner
// FAP moves the corner along x or y only; the point field carries that
// motion to the skin around it unchanged, so a corner drawn out by AU20
// (risorius, 7 mm) lifted the skin beside it 8 mm off the face, a rubber
// lump lateral to each corner (issue 11: "rubber bulges beside the mouth
// corners" in fear). Risorius pulls the corner along the face, back over
// the teeth: the corner moves towards the plane of the skin around it (its
// mean normal over kGlideReach of the corner's kernel radius), so the sheet
// beside it slides more and rises less.
// It glides by kGlide of the way into that plane, outward only (medially
// and up the corner runs onto the lips and the cheek's front, which face
// forward): fully, the sheet's edge 15 mm out creased (AU20 61 deg against
// 39); at 0.35 the skin beside the corner rose 5.8 mm for the corner's
// 8.3 mm out instead of 8.1, and the lower cheek below the corner still
// bulged 4.7 mm out along its normal at 0.8 AU20, an uneven jaw in fear at
// 512 px (blind review, session 9); at 0.6 the skin beside the corner rises
// 4.3 mm (rig_smoothness_test), the lower cheek 3.0, and AU20's largest
// crease is 49.8 deg.
constexpr double kGlideReach = 0.8, kGlide = 0.6;

void FaceRig::build_corner_glide(const Face& face) {
    for (int side = 0; side < 2; ++side) {
        corner_normal_[side] = {0.0, 0.0, 1.0};
        const int k = fap::feature_point_index(side == 0 ? "8.3" : "8.4");
        if (!fps_[k].present || system_of_fp_[k] < 0) continue;
        const V c = to_v(fps_[k].position);
        const double reach = kGlideReach * system_radius_[system_of_fp_[k]];
        V sum(0.0);
        for (auto f : face.mesh.faces()) {
            std::array<V, 3> p;
            int i = 0;
            bool skin = true;
            for (auto v : face.mesh.fv_range(f)) {
                skin &= parts_[v.idx()] == VertexPart::Skin;
                p[i++] = to_v(neutral_[v.idx()]);
            }
            if (!skin) continue;
            const double t = glm::length((p[0] + p[1] + p[2]) / 3.0 - c) / reach;
            if (t < 1.0) sum += wendland(t) * glm::cross(p[1] - p[0], p[2] - p[0]);  // area-weighted
        }
        // A plane steeper than 60 degrees from the front would send the
        // corner back further than it moves (and faces built so are odd).
        if (glm::length(sum) > 0 && sum[2] > 0.5 * glm::length(sum)) corner_normal_[side] = glm::normalize(sum);
    }
}

void FaceRig::build_jaw(const Face& face) {
    const int n = face.vertex_count();
    jaw_weight_.assign(n, 0.0f);
    for (int v = 0; v < n; ++v)
        if (parts_[v] == VertexPart::MouthLower || parts_[v] == VertexPart::Tongue) jaw_weight_[v] = 1.0f;
    auto idx = [](const char* id) { return fap::feature_point_index(id); };
    for (const char* id : {"2.1", "2.2", "2.3", "2.4", "2.5"})
        if (!fps_[idx(id)].present) {
            for (int v = 0; v < n; ++v)
                if (jaw_weight_[v] > 0) jaw_vertices_.push_back(v);
            has_jaw_ = false;
            return;
        }
    has_jaw_ = true;
    jaw_pivot_ = to_v(face.jaw_pivot);
    const double es0 = fapu_.es * 1024.0;
    const V p22 = to_v(fps_[idx("2.2")].position), p23 = to_v(fps_[idx("2.3")].position);
    const V pl = to_v(fps_[idx("2.4")].position), pr = to_v(fps_[idx("2.5")].position);
    const double chin_y = fps_[idx("2.1")].position[1];
    const double mx = 0.5 * (pl[0] + pr[0]), half_width = 0.5 * std::abs(pl[0] - pr[0]);
    const double y_mid = 0.5 * (p22[1] + p23[1]), y_corner = 0.5 * (pl[1] + pr[1]);
    const double z_corner = 0.5 * (pl[2] + pr[2]);
    const V P = jaw_pivot_;
    // Half the height of the fade across the line from the mouth corners
    // to the jaw joint (at 0.25 the cheek's skin over the line was pushed
    // together more as the jaw dropped).
    const double delta = 0.35 * es0;

    // Which side of the mouth a vertex is on, by distance along the skin:
    // across the closed lips the two sides are far apart.
    detail::GeodesicGraph graph(face.mesh, face.welded);
    auto sources = [&](std::initializer_list<const char*> ids) {
        std::vector<int> s;
        for (const char* id : ids)
            if (fps_[idx(id)].present && fps_[idx(id)].vertex >= 0) s.push_back(fps_[idx(id)].vertex);
        return s;
    };
    const double lip_zone = 0.5 * es0;
    std::vector<double> to_upper(n, 1e30), to_lower(n, 1e30);
    for (auto [v, g] : graph.within(sources({"2.2", "2.6", "2.7"}), lip_zone)) to_upper[v] = g;
    for (auto [v, g] : graph.within(sources({"2.3", "2.8", "2.9"}), lip_zone)) to_lower[v] = g;

    for (int v = 0; v < n; ++v) {
        if (parts_[v] != VertexPart::Skin) continue;
        const double x = neutral_[v][0], y = neutral_[v][1], z = neutral_[v][2];
        double line;
        if (z >= z_corner) {
            line = y_mid + (y_corner - y_mid) * std::min(std::abs(x - mx) / half_width, 1.0);
        } else {
            const double t = std::clamp((z_corner - z) / std::max(z_corner - P[2], 1e-9), 0.0, 1.0);
            line = y_corner + (P[1] - y_corner) * t;
        }
        double w = glm::smoothstep(delta, -delta, y - line);
        if (to_upper[v] < 1e29 || to_lower[v] < 1e29) {
            // Fully on the jaw (lower lip) or off it (upper) only mid-mouth:
            // towards the corners both lips follow it partly, so an open
            // mouth is an oval narrowing into closed corners, not a slot.
            // The lip's share joins the line's by products, not max/min: a
            // max or min kinks the weight where the two cross (square
            // contours beside the mouth, a fold from each corner down to
            // the chin and a bulge beside it when the jaw drops).
            const double lip = 1.0 - glm::smoothstep(0.15 * half_width, 1.15 * half_width, std::abs(x - mx));
            w = to_lower[v] < to_upper[v] ? 1.0 - (1.0 - w) * (1.0 - lip) : w * (1.0 - lip);
        }
        // The neck below the chin and the head behind the jaw joint stay; the
        // fades are long so a wide-open jaw stretches the skin instead of
        // folding it (the one from back to front runs over the jaw's whole
        // side: 0.6 ES0 long, it pushed that skin together).
        w *= glm::smoothstep(chin_y - 0.8 * es0, chin_y - 0.08 * es0, y);
        w *= glm::smoothstep(P[2] - 0.1 * es0, P[2] + 1.0 * es0, z);
        jaw_weight_[v] = static_cast<float>(w);
    }
    for (int v = 0; v < n; ++v)
        if (jaw_weight_[v] > 1e-4f) jaw_vertices_.push_back(v);
}

void FaceRig::build_eyes(const Face& face) {
    double clearance = 1e30;
    for (const Eyeball& eb : face.eyeballs) {
        EyeState e;
        e.first = eb.vertices.first;
        e.count = eb.vertices.count;
        e.centre = to_v(eb.centre);
        e.radius = eb.radius;
        e.iris_angle = eb.iris_angle;
        e.pupil_angle = eb.pupil_angle;
        for (int v = e.first; v < e.first + e.count; ++v) {
            const V d = to_v(neutral_[v]) - e.centre;
            const double r = glm::length(d);
            e.polar.push_back(static_cast<float>(r > 0 ? std::acos(std::clamp(d[2] / r, -1.0, 1.0)) : 0.0));
            e.azimuth.push_back(static_cast<float>(std::atan2(d[1], d[0])));
        }
        for (const auto* margin : {&eb.upper_margin, &eb.lower_margin})
            for (int v : *margin) {
                clearance = std::min(clearance, glm::length(to_v(neutral_[v]) - e.centre) - e.radius);
            }
        eyes_.push_back(std::move(e));
    }
    // Lashes: the component (along mesh edges) of a skin vertex welded to a
    // margin vertex, if it is a small strand and not a stretch of skin split
    // by a UV seam.
    for (std::size_t e = 0; e < face.eyeballs.size(); ++e) {
        const Eyeball& eb = face.eyeballs[e];
        std::vector<int> margin(eb.upper_margin);
        margin.insert(margin.end(), eb.lower_margin.begin(), eb.lower_margin.end());
        auto on_margin = [&](int v) { return std::find(margin.begin(), margin.end(), v) != margin.end(); };
        for (const auto& w : face.welded)
            for (int k = 0; k < 2; ++k) {
                const int anchor = w[k], root = w[1 - k];
                if (!on_margin(anchor) || on_margin(root) || parts_[root] != VertexPart::Skin) continue;
                constexpr std::size_t kMaxStrand = 64;
                std::vector<int> strand{root};
                for (std::size_t q = 0; q < strand.size() && strand.size() <= kMaxStrand; ++q)
                    for (auto vv : face.mesh.vv_range(TriMesh::VertexHandle(strand[q])))
                        if (std::find(strand.begin(), strand.end(), vv.idx()) == strand.end()) strand.push_back(vv.idx());
                if (strand.size() > kMaxStrand) continue;
                for (int v : strand) lash_vertices_.push_back({v, anchor, static_cast<int>(e)});
            }
    }

    // Skin in front of an eyeball keeps at least its neutral clearance (the
    // margins' at most), so a closing lid slides over the eye; what a lid FAP
    // carries also keeps its neutral distance from the eyeball's centre, so
    // a lid turns about the eye (closing, the upper margin meets the lower
    // one on the eyeball; opening, it slides back over it) instead of
    // moving straight up or down off its surface.
    if (clearance > 1e29) return;
    clearance = std::max(clearance, 0.0);
    std::vector<float> follow(neutral_.size(), 0.0f);
    // (Only the lid FAPs turn skin about the eye; the inner brow's share
    // of the upper lid moves it as the brow moves the skin above.)
    for (const LidWeight& lw : lid_weights_)
        if (fap::feature_points()[lid_fps_[lw.lid]].id[0] == '3' && lid_kind_[lw.lid] == Driven::Follow)
            follow[lw.vertex] = std::max(follow[lw.vertex], lw.weight);
    for (int v = 0; v < static_cast<int>(neutral_.size()); ++v) {
        if (parts_[v] != VertexPart::Skin) continue;
        for (std::size_t e = 0; e < eyes_.size(); ++e) {
            const V d = to_v(neutral_[v]) - eyes_[e].centre;
            const double r = glm::length(d);
            if (d[2] <= 0 || r > eyes_[e].radius * 1.8) continue;
            const double min_r = eyes_[e].radius + std::min(std::max(r - eyes_[e].radius, 0.0), clearance);
            lid_vertices_.push_back(
                {v, static_cast<int>(e), static_cast<float>(min_r), static_cast<float>(r), std::min(follow[v], 1.0f)});
        }
    }
}

void FaceRig::build_head(const Face& face) {
    head_pivot_ = to_v(face.head_pivot);
    const double es0 = fapu_.es * 1024.0;
    head_weight_.assign(neutral_.size(), 1.0f);
    for (std::size_t v = 0; v < neutral_.size(); ++v)
        if (parts_[v] == VertexPart::Skin)
            head_weight_[v] = static_cast<float>(glm::smoothstep(head_pivot_[1] - 0.9 * es0, head_pivot_[1], double(neutral_[v][1])));
}

void FaceRig::point_displacements(const FapValues& faps, std::array<std::array<double, 3>, fap::kFeaturePointCount>& d) const {
    for (auto& v : d) v = {0.0, 0.0, 0.0};
    for (int f = 4; f <= fap::kFapCount; ++f) {
        const double value = faps[f - 1];
        if (value == 0.0 || !(is_point_fap(f) || f == 47)) continue;
        const auto& info = fap::fap_info(f);
        if (f == 47) {
            // Tongue roll: both borders curl up by the angle over the tongue's half width.
            const int c = fap::feature_point_index("6.2");
            for (const char* id : {"6.3", "6.4"}) {
                const int k = fap::feature_point_index(id);
                if (!fps_[k].present || !fps_[c].present) continue;
                const double half = std::abs(fps_[k].position[0] - fps_[c].position[0]);
                d[k][1] += half * std::sin(value * fapu_.au);
            }
            continue;
        }
        const auto fp = fap::find_feature_point(info.feature_point);
        if (!fp) continue;
        const double s = value * fapu_.of(info.unit);
        for (int c = 0; c < 3; ++c) d[*fp][c] += s * info.direction[c];
    }
    // The corners glide in the plane of the skin around them (build_corner_glide).
    for (const auto& [side, ids] : {std::pair{0, std::array{"2.4", "8.3"}}, std::pair{1, std::array{"2.5", "8.4"}}}) {
        const V& nrm = corner_normal_[side];
        for (const char* id : ids) {
            auto& p = d[fap::feature_point_index(id)];
            const double out = side == 0 ? std::max(p[0], 0.0) : std::min(p[0], 0.0);
            p[2] -= kGlide * nrm[0] * out / nrm[2];
        }
    }
    // A mouth corner's inner and outer points (2.4 and 8.3) are one corner
    // a lip's thickness apart: they may move apart by at most half that
    // distance, or the skin between them shears into a stitch. Both give
    // way towards their mean.
    for (const auto& [inner_id, outer_id] : {std::pair{"2.4", "8.3"}, std::pair{"2.5", "8.4"}}) {
        const int i = fap::feature_point_index(inner_id), o = fap::feature_point_index(outer_id);
        if (!fps_[i].present || !fps_[o].present) continue;
        const V diff = to_v(d[o]) - to_v(d[i]);
        const double apart = glm::length(diff);
        const double allowed = 0.5 * glm::length(to_v(fps_[o].position) - to_v(fps_[i].position));
        if (apart <= allowed) continue;
        const V give = diff * (0.5 * (apart - allowed) / apart);
        d[i] = to_array(to_v(d[i]) + give);
        d[o] = to_array(to_v(d[o]) - give);
    }
}

void FaceRig::build_kernel_arrays() {
    const int n = static_cast<int>(neutral_.size());
    if (system_held_.size() > std::size_t(rig_kernel::kMaxSystem) || lid_fps_.size() > std::size_t(rig_kernel::kMaxLidFps) ||
        eyes_.size() > std::size_t(rig_kernel::kMaxEyes))
        fail<InputError>("expression: rig: expected at most {} point-field entries, {} lid feature points and {} eyeballs, "
                         "found {}, {} and {}",
                         rig_kernel::kMaxSystem, rig_kernel::kMaxLidFps, rig_kernel::kMaxEyes, system_held_.size(),
                         lid_fps_.size(), eyes_.size());
    KernelArrays& k = kernel_;
    // Per-vertex CSR of a list of (vertex, entry), keeping the list's order.
    auto csr = [n](const auto& list, std::vector<int>& start, auto& entries, auto entry_of) {
        start.assign(std::size_t(n) + 1, 0);
        for (const auto& e : list) ++start[std::size_t(e.vertex) + 1];
        for (int v = 0; v < n; ++v) start[std::size_t(v) + 1] += start[std::size_t(v)];
        std::vector<int> fill(start.begin(), start.end() - 1);
        entries.resize(list.size());
        for (const auto& e : list) entries[std::size_t(fill[std::size_t(e.vertex)]++)] = entry_of(e);
    };
    csr(lid_weights_, k.lid_start, k.lid_weights, [](const LidWeight& w) { return RigLidWeight{w.lid, w.weight}; });
    csr(lid_vertices_, k.slide_start, k.slides,
        [](const LidVertex& l) { return RigSlide{l.eye, l.min_radius, l.shell_radius, l.follow}; });
    k.lash_anchor.assign(std::size_t(n), -1);
    k.lash_eye.assign(std::size_t(n), 0);
    for (const LashVertex& l : lash_vertices_) {  // a vertex listed twice rides on the last anchor, as before
        k.lash_anchor[std::size_t(l.vertex)] = l.anchor;
        k.lash_eye[std::size_t(l.vertex)] = l.eye;
    }
    k.jaw_weight.assign(std::size_t(n), 0.0f);
    if (has_jaw_)
        for (int v : jaw_vertices_) k.jaw_weight[std::size_t(v)] = jaw_weight_[std::size_t(v)];
    k.eye_of.assign(std::size_t(n), -1);
    k.eye_polar.assign(std::size_t(n), 0.0f);
    k.eye_azimuth.assign(std::size_t(n), 0.0f);
    for (std::size_t e = 0; e < eyes_.size(); ++e)
        for (int i = 0; i < eyes_[e].count; ++i) {
            const auto v = std::size_t(eyes_[e].first + i);
            k.eye_of[v] = int(e);
            k.eye_polar[v] = eyes_[e].polar[std::size_t(i)];
            k.eye_azimuth[v] = eyes_[e].azimuth[std::size_t(i)];
        }
}

RigView FaceRig::view() const {
    RigView r;
    r.vertex_count = static_cast<int>(neutral_.size());
    static_assert(sizeof(TriMesh::Point) == 3 * sizeof(float), "points are 3 packed floats");
    r.neutral = reinterpret_cast<const float*>(neutral_.data());
    r.influence_start = influence_start_.data();
    r.influences = weights_.data();
    r.lid_start = kernel_.lid_start.data();
    r.lid_weights = kernel_.lid_weights.data();
    r.slide_start = kernel_.slide_start.data();
    r.slides = kernel_.slides.data();
    r.lash_anchor = kernel_.lash_anchor.data();
    r.lash_eye = kernel_.lash_eye.data();
    r.jaw_weight = kernel_.jaw_weight.data();
    r.eye_of = kernel_.eye_of.data();
    r.eye_polar = kernel_.eye_polar.data();
    r.eye_azimuth = kernel_.eye_azimuth.data();
    r.head_weight = head_weight_.data();
    for (std::size_t e = 0; e < eyes_.size(); ++e)
        for (int c = 0; c < 3; ++c) r.eye_centre[e][c] = eyes_[e].centre[c];
    return r;
}

std::array<double, 3> FaceRig::lid_displacement(std::size_t i,
                                                const std::array<std::array<double, 3>, fap::kFeaturePointCount>& fp_d) const {
    const std::array<double, 3>& fp = fp_d[lid_fps_[i]];
    switch (lid_kind_[i]) {
    case Driven::Follow: return fp;
    case Driven::LidBulge: return {0.0, 0.0, std::max(fp[1], 0.0)};  // a lower margin's rise, forward
    case Driven::CheekMass: {
        const CheekMass& m = cheek_mass_[i];
        const double rise = std::max(fp[1], 0.0) + kCornerShare * std::max(fp_d[m.corner][1], 0.0) +
                            (m.lip >= 0 ? kUpperLipShare * std::max(fp_d[m.lip][1], 0.0) : 0.0);
        return {kMassOut * m.out * rise, kMassUp * rise, kMassForward * rise};
    }
    }
    return fp;
}

RigFrame FaceRig::frame(const FapValues& given) const {
    const FapValues faps = lip_contours_together(ranges_.clamp(given));
    RigFrame f;
    auto copy = [](const glm::dmat3& m, double* out) {
        for (int c = 0; c < 3; ++c)
            for (int r = 0; r < 3; ++r) out[3 * c + r] = m[c][r];
    };
    auto nonzero = [](const std::array<double, 3>& d) { return d[0] != 0 || d[1] != 0 || d[2] != 0; };

    // Point FAPs and lid FAPs: their feature points' displacements.
    std::array<std::array<double, 3>, fap::kFeaturePointCount> fp_d;
    point_displacements(faps, fp_d);
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const int j = system_of_fp_[k];
        if (j < 0 || system_held_[j]) continue;
        for (int c = 0; c < 3; ++c) f.system_d[j][c] += fp_d[k][c];
        f.points |= nonzero(fp_d[k]);
    }
    for (std::size_t i = 0; i < lid_fps_.size(); ++i) {
        const std::array<double, 3> d = lid_displacement(i, fp_d);
        for (int c = 0; c < 3; ++c) f.lid_d[i][c] = d[c];
        f.lids |= nonzero(d);
    }

    // Jaw: rotate about the pivot so that 2.1 drops by FAP 3 x MNS, then
    // thrust (14) and shift (15).
    const double open = faps[2], thrust = faps[13], shift = faps[14];
    if (has_jaw_ && (open != 0 || thrust != 0 || shift != 0)) {
        const JawMotion m = jaw_motion(to_v(fps_[fap::feature_point_index("2.1")].position) - jaw_pivot_, open, thrust, shift, fapu_);
        copy(m.r, f.jaw_r);
        for (int c = 0; c < 3; ++c) {
            f.jaw_t[c] = m.t[c];
            f.jaw_pivot[c] = jaw_pivot_[c];
        }
        f.jaw = true;
    }

    // Eyeballs.
    for (std::size_t i = 0; i < eyes_.size(); ++i) {
        const EyeState& e = eyes_[i];
        const bool left = e.centre[0] > 0;
        const double yaw = faps[left ? 22 : 23], pitch = faps[left ? 24 : 25];
        const double thrust_e = faps[left ? 26 : 27], dilate = faps[left ? 28 : 29];
        if (yaw == 0 && pitch == 0 && thrust_e == 0 && dilate == 0) continue;
        RigEyeFrame& ef = f.eyes[i];
        ef.on = true;
        ef.dilate = dilate != 0;
        copy(rot_y(yaw * fapu_.au) * rot_x(pitch * fapu_.au), ef.r);
        ef.t[2] = thrust_e * fapu_.es;
        const double sin_p = std::sin(e.pupil_angle) * e.radius;
        const double iris_r = std::sin(e.iris_angle) * e.radius;
        const double pupil_r = std::clamp(sin_p + 0.5 * dilate * fapu_.irisd, 0.12 * iris_r, 0.95 * iris_r);
        ef.new_pupil = std::asin(std::min(pupil_r / e.radius, 1.0));
        ef.iris_angle = e.iris_angle;
        ef.pupil_angle = e.pupil_angle;
    }

    // Head: pitch (48, front down), yaw (49, front to the face's left), roll
    // (50, top to the face's right), about 7.1.
    const double hp = faps[47], hy = faps[48], hr = faps[49];
    if (hp != 0 || hy != 0 || hr != 0) {
        copy(rot_y(hy * fapu_.au) * (rot_x(hp * fapu_.au) * rot_z(hr * fapu_.au)), f.head_r);
        for (int c = 0; c < 3; ++c) f.head_pivot[c] = head_pivot_[c];
        f.head = true;
    }
    return f;
}

namespace {

// The feature points of a frame whose vertex positions `at(v)` gives.
template <class At>
fap::FeaturePointPositions feature_points_of(const std::array<FeaturePointLocation, fap::kFeaturePointCount>& fps,
                                             const RigFrame& f, double es0, const At& at) {
    fap::FeaturePointPositions out{};
    glm::dmat3 head(1.0);
    for (int c = 0; c < 3; ++c)
        for (int r = 0; r < 3; ++r) head[c][r] = f.head_r[3 * c + r];
    const V pivot = to_v(std::array<double, 3>{f.head_pivot[0], f.head_pivot[1], f.head_pivot[2]});
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const FeaturePointLocation& fp = fps[k];
        if (!fp.present) {
            out[k] = {0, 0, 0};
        } else if (fp.vertex >= 0) {
            const rig_kernel::P3 p = at(fp.vertex);
            out[k] = {double(p.x), double(p.y), double(p.z)};
        } else if (f.head) {
            // Free points (7.1, 11.5) turn with the head where the skin would.
            const double w = glm::smoothstep(pivot[1] - 0.9 * es0, pivot[1], fp.position[1]);
            const V p = to_v(fp.position);
            const V moved = head * (p - pivot) + pivot;
            out[k] = to_array(p + (moved - p) * w);
        } else {
            out[k] = fp.position;
        }
    }
    return out;
}

}  // namespace

void FaceRig::deform(const FapValues& faps, DeformedFace& out) const {
    const RigFrame f = frame(faps);
    const RigView r = view();
    out.positions.resize(neutral_.size());
    TriMesh::Point* pos = out.positions.data();
    // Chunks of fixed size: the result does not depend on the threads.
    parallel_for(r.vertex_count, 4096, [&](int begin, int end) {
        for (int v = begin; v < end; ++v) {
            const rig_kernel::P3 p = rig_kernel::position(r, f, v);
            pos[v] = TriMesh::Point(p.x, p.y, p.z);
        }
    });
    out.feature_points = feature_points_of(fps_, f, fapu_.es * 1024.0, [&](int v) {
        return rig_kernel::P3{pos[v][0], pos[v][1], pos[v][2]};
    });
}

fap::FeaturePointPositions FaceRig::feature_points(const RigFrame& f) const {
    const RigView r = view();
    return feature_points_of(fps_, f, fapu_.es * 1024.0, [&](int v) { return rig_kernel::position(r, f, v); });
}

DeformedFace FaceRig::deform(const FapValues& faps) const {
    DeformedFace out;
    deform(faps, out);
    return out;
}

fap::FeaturePointPositions FaceRig::feature_points(const FapValues& faps) const {
    // The kernel body at the feature points' vertices: the same positions as
    // the full deformation's, at a few hundred vertices' cost.
    return feature_points(frame(faps));
}

// The oracle: the rig as it ran before the kernel body, stage after stage
// over the whole mesh on one thread. Kept only so that the tests can hold
// the kernel body (deform()) to it.
DeformedFace FaceRig::deform_reference(const FapValues& given) const {
    DeformedFace out;
    const FapValues faps = lip_contours_together(ranges_.clamp(given));
    const int n = static_cast<int>(neutral_.size());
    out.positions.assign(neutral_.begin(), neutral_.end());
    auto& pos = out.positions;

    // Point FAPs.
    std::array<std::array<double, 3>, fap::kFeaturePointCount> fp_d;
    point_displacements(faps, fp_d);
    std::vector<std::array<double, 3>> d(system_held_.size(), {0.0, 0.0, 0.0});
    bool any = false;
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const int j = system_of_fp_[k];
        if (j < 0 || system_held_[j]) continue;
        for (int c = 0; c < 3; ++c) d[j][c] += fp_d[k][c];
        any |= fp_d[k][0] != 0 || fp_d[k][1] != 0 || fp_d[k][2] != 0;
    }
    if (any) {
        for (int v = 0; v < n; ++v) {
            double dx = 0, dy = 0, dz = 0;
            for (int k = influence_start_[v]; k < influence_start_[v + 1]; ++k) {
                const auto& dj = d[weights_[k].system];
                const double w = weights_[k].weight;
                dx += w * dj[0];
                dy += w * dj[1];
                dz += w * dj[2];
            }
            pos[v] += TriMesh::Point(static_cast<float>(dx), static_cast<float>(dy), static_cast<float>(dz));
        }
    }
    bool lids_move = false;
    for (std::size_t i = 0; i < lid_fps_.size(); ++i) {
        const std::array<double, 3> dk = lid_displacement(i, fp_d);
        lids_move |= dk[0] != 0 || dk[1] != 0 || dk[2] != 0;
    }
    if (lids_move)
        for (const LidWeight& lw : lid_weights_) {
            const std::array<double, 3> dk = lid_displacement(lw.lid, fp_d);
            pos[lw.vertex] += TriMesh::Point(static_cast<float>(lw.weight * dk[0]), static_cast<float>(lw.weight * dk[1]),
                                             static_cast<float>(lw.weight * dk[2]));
        }
    if (any || lids_move) {
        // Lids slide over the eyeballs.
        for (const LidVertex& lv : lid_vertices_) {
            const EyeState& e = eyes_[lv.eye];
            auto& p = pos[lv.vertex];
            const double dx = p[0] - e.centre[0], dy = p[1] - e.centre[1], dz = p[2] - e.centre[2];
            const double r2 = dx * dx + dy * dy + dz * dz, m2 = double(lv.min_radius) * lv.min_radius;
            const double s2 = double(lv.shell_radius) * lv.shell_radius;
            if (r2 < m2 && dx * dx + dy * dy < m2) {
                p[2] = static_cast<float>(e.centre[2] + std::sqrt(m2 - dx * dx - dy * dy));
            } else if (lv.follow > 0 && r2 > s2 && dx * dx + dy * dy < s2) {
                const double shell_z = e.centre[2] + std::sqrt(s2 - dx * dx - dy * dy);
                p[2] = static_cast<float>(p[2] + lv.follow * (shell_z - p[2]));
            }
        }
        // Lashes ride on their margin vertex, turned by the angle it turned
        // through about the eyeball's horizontal axis.
        for (const LashVertex& l : lash_vertices_) {
            const EyeState& e = eyes_[l.eye];
            const auto a0 = neutral_[l.anchor], a = pos[l.anchor];
            const double turn = std::atan2(a[1] - e.centre[1], a[2] - e.centre[2]) -
                                std::atan2(a0[1] - e.centre[1], a0[2] - e.centre[2]);
            const auto off = neutral_[l.vertex] - a0;
            const double c = std::cos(turn), s = std::sin(turn);
            pos[l.vertex] = a + TriMesh::Point(off[0], static_cast<float>(off[1] * c + off[2] * s),
                                               static_cast<float>(off[2] * c - off[1] * s));
        }
    }

    // Jaw: rotate about the pivot so that 2.1 drops by FAP 3 x MNS, then
    // thrust (14) and shift (15).
    const double open = faps[2], thrust = faps[13], shift = faps[14];
    if (has_jaw_ && (open != 0 || thrust != 0 || shift != 0)) {
        const JawMotion m = jaw_motion(to_v(fps_[fap::feature_point_index("2.1")].position) - jaw_pivot_, open, thrust, shift, fapu_);
        const glm::dmat3& r = m.r;
        const V& t = m.t;
        for (int v : jaw_vertices_) {
            const V p = to_v(pos[v]);
            const V moved = r * (p - jaw_pivot_) + jaw_pivot_ + t;
            const double w = jaw_weight_[v];
            pos[v] = TriMesh::Point(static_cast<float>(p[0] + w * (moved[0] - p[0])),
                                    static_cast<float>(p[1] + w * (moved[1] - p[1])),
                                    static_cast<float>(p[2] + w * (moved[2] - p[2])));
        }
    }

    // Eyeballs.
    for (const EyeState& e : eyes_) {
        const bool left = e.centre[0] > 0;
        const double yaw = faps[left ? 22 : 23], pitch = faps[left ? 24 : 25];
        const double thrust_e = faps[left ? 26 : 27], dilate = faps[left ? 28 : 29];
        if (yaw == 0 && pitch == 0 && thrust_e == 0 && dilate == 0) continue;
        const glm::dmat3 r = rot_y(yaw * fapu_.au) * rot_x(pitch * fapu_.au);
        const V t(0.0, 0.0, thrust_e * fapu_.es);
        const double sin_p = std::sin(e.pupil_angle) * e.radius;
        const double iris_r = std::sin(e.iris_angle) * e.radius;
        const double pupil_r = std::clamp(sin_p + 0.5 * dilate * fapu_.irisd, 0.12 * iris_r, 0.95 * iris_r);
        const double new_pupil = std::asin(std::min(pupil_r / e.radius, 1.0));
        for (int k = 0; k < e.count; ++k) {
            const int v = e.first + k;
            V d = to_v(neutral_[v]) - e.centre;
            if (dilate != 0 && e.polar[k] < e.iris_angle) {
                const double r = glm::length(d);
                const double a = e.polar[k];
                const double na = a < e.pupil_angle
                                      ? a * new_pupil / e.pupil_angle
                                      : new_pupil + (a - e.pupil_angle) * (e.iris_angle - new_pupil) /
                                                        (e.iris_angle - e.pupil_angle);
                d = {r * std::sin(na) * std::cos(e.azimuth[k]), r * std::sin(na) * std::sin(e.azimuth[k]),
                     r * std::cos(na)};
            }
            const V p = r * d + e.centre + t;
            pos[v] = TriMesh::Point(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]));
        }
    }

    // Head: pitch (48, front down), yaw (49, front to the face's left), roll
    // (50, top to the face's right), about 7.1.
    const double hp = faps[47], hy = faps[48], hr = faps[49];
    glm::dmat3 head(1.0);
    const bool turn = hp != 0 || hy != 0 || hr != 0;
    if (turn) {
        head = rot_y(hy * fapu_.au) * (rot_x(hp * fapu_.au) * rot_z(hr * fapu_.au));
        for (int v = 0; v < n; ++v) {
            const double w = head_weight_[v];
            if (w <= 0) continue;
            const V p = to_v(pos[v]);
            const V moved = head * (p - head_pivot_) + head_pivot_;
            pos[v] = TriMesh::Point(static_cast<float>(p[0] + w * (moved[0] - p[0])),
                                    static_cast<float>(p[1] + w * (moved[1] - p[1])),
                                    static_cast<float>(p[2] + w * (moved[2] - p[2])));
        }
    }

    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const FeaturePointLocation& fp = fps_[k];
        if (!fp.present) {
            out.feature_points[k] = {0, 0, 0};
        } else if (fp.vertex >= 0) {
            out.feature_points[k] = to_array(to_v(pos[fp.vertex]));
        } else if (turn) {
            // Free points (7.1, 11.5) turn with the head where the skin would.
            const double w = glm::smoothstep(head_pivot_[1] - 0.9 * fapu_.es * 1024.0, head_pivot_[1], fp.position[1]);
            const V p = to_v(fp.position);
            const V moved = head * (p - head_pivot_) + head_pivot_;
            out.feature_points[k] = to_array(p + (moved - p) * w);
        } else {
            out.feature_points[k] = fp.position;
        }
    }
    return out;
}


void FaceRig::write_to(const DeformedFace& deformed, TriMesh& mesh) {
    if (deformed.positions.size() != mesh.n_vertices())
        fail("expression: rig: {} deformed positions for a mesh of {} vertices", deformed.positions.size(),
             mesh.n_vertices());
    for (std::size_t v = 0; v < deformed.positions.size(); ++v)
        mesh.set_point(TriMesh::VertexHandle(static_cast<int>(v)), deformed.positions[v]);
    if (!mesh.has_face_normals()) mesh.request_face_normals();
    if (!mesh.has_vertex_normals()) mesh.request_vertex_normals();
    mesh.update_normals();
}

bool FaceRig::has_effect(int fap) const {
    if (fap < 1 || fap > fap::kFapCount) fail("expression: rig: no FAP {}", fap);
    return no_effect_[fap - 1].empty();
}

const std::string& FaceRig::why_no_effect(int fap) const {
    if (fap < 1 || fap > fap::kFapCount) fail("expression: rig: no FAP {}", fap);
    return no_effect_[fap - 1];
}

double FaceRig::influence_radius(int feature_point) const {
    const int j = system_of_fp_.at(feature_point);
    return j < 0 ? 0.0 : system_radius_[j];
}

}  // namespace emoface::expression
