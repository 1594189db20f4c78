// The default face generator. The skin is one grid over the whole head: the
// columns are azimuths around the head's vertical axis (dense over the face,
// sparse behind), the rows are rays swept from eye level up over the crown
// and down over the face, under the chin and along the neck (data/face
// face.json, resolution.upper_rows / lower_rows). Each grid vertex is where
// its ray leaves the head volume, moved by the frontal relief.
//
// The eyes and the mouth are slits in that grid: along the eye row and the
// mouth row, the vertices between the two corner columns are doubled, one copy
// for the upper lid (lip) and one for the lower. The rows around each slit are
// warped so the copies land on the eyelid margins (open) or on the line where
// the lips meet (closed), and the rig can pull them apart.
#include "emoface/expression/default_face.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>

#include "emoface/common/constants.h"
#include "emoface/common/error.h"
#include "emoface/fap/feature_points.h"
#include "face_params.h"
#include "json_reader.h"
#include "face_shape.h"
#include "face_texture.h"

namespace emoface::expression {
namespace {

using detail::FaceParams;
using detail::FaceShape;

constexpr double kDeg = kPi / 180.0;

struct Row {
    double origin_y = 0;
    double z_front = 0, z_back = 0;
    double angle_front = 0, angle_back = 0;  // radians
    // A bust row (> 0): not a ray but the point this share of the column's
    // bust length along the body's profile below the lowest ray row.
    double bust_share = 0;

    static double front_weight(double theta) { return 0.5 * (1.0 + std::cos(theta)); }
    glm::dvec3 origin(double theta) const { return {0.0, origin_y, detail::mix(z_back, z_front, front_weight(theta))}; }
    double angle(double theta) const { return detail::mix(angle_back, angle_front, front_weight(theta)); }
};

glm::dvec3 ray_dir(double theta, double phi) {
    return {std::sin(theta) * std::cos(phi), std::sin(phi), std::cos(theta) * std::cos(phi)};
}

detail::RowKey lerp_key(const detail::RowKey& a, const detail::RowKey& b, double t) {
    detail::RowKey k;
    k.origin_y = detail::mix(a.origin_y, b.origin_y, t);
    k.origin_z_front = detail::mix(a.origin_z_front, b.origin_z_front, t);
    k.origin_z_back = detail::mix(a.origin_z_back, b.origin_z_back, t);
    k.angle_front_deg = detail::mix(a.angle_front_deg, b.angle_front_deg, t);
    k.angle_back_deg = detail::mix(a.angle_back_deg, b.angle_back_deg, t);
    return k;
}

Row to_row(const detail::RowKey& k) {
    return {k.origin_y, k.origin_z_front, k.origin_z_back, k.angle_front_deg * kDeg, k.angle_back_deg * kDeg};
}

int scaled(int n, double scale, int minimum) {
    return std::max(minimum, static_cast<int>(std::lround(n * scale)));
}

// Falloff of a row warp with the distance from the slit row, 1 at the slit
// and 0 at `reach`; its slope stays below 1.5 / reach so rows never cross
// while the slit offset is below reach / 1.5.
double warp_falloff(double d, double reach) {
    if (d >= reach) return 0.0;
    return 1.0 - glm::smoothstep(0.0, 1.0, d / reach);
}

class Generator {
public:
    Generator(const FaceParams& params, const DefaultFaceOptions& options)
        : p_(params), shape_(p_), scale_(options.resolution_scale) {}

    Face build(int texture_size);

private:
    glm::dvec3 base_point(double theta, const Row& row, double dphi) const {
        if (row.bust_share > 0) return bust_point(theta, row.bust_share);
        const glm::dvec3 o = row.origin(theta);
        const glm::dvec3 d = ray_dir(theta, row.angle(theta) + dphi);
        return o + d * shape_.cast(o, d);
    }
    // The elevation offset that puts the face-row vertex of column theta
    // (ray from the head centre) at height y = target(x).
    template <typename Target>
    double solve_offset(double theta, const Row& row, Target target) const {
        double dphi = 0.0;
        for (int it = 0; it < 12; ++it) {
            const glm::dvec3 p = base_point(theta, row, dphi);
            const double err = p.y - target(p.x);
            if (std::abs(err) < 1e-6) break;
            const double h = 1e-4;
            const glm::dvec3 q = base_point(theta, row, dphi + h);
            const double derr = ((q.y - target(q.x)) - err) / h;
            if (std::abs(derr) < 1e-9) break;
            dphi -= err / derr;
        }
        return dphi;
    }

    glm::dvec3 bust_point(double theta, double share) const;
    void make_columns();
    std::vector<Row> resample(const std::vector<detail::RowKey>& keys) const;
    void make_rows();
    void compute_warps();
    void build_skin(Face& face);
    void build_eyeball(Face& face, int side);
    void build_mouth_interior(Face& face);
    void build_lashes(Face& face, int side, bool upper);
    // An eyelid margin's vertices from the inner to the outer corner.
    std::vector<int> margin(int side, bool upper) const {
        std::vector<int> m;
        for (int i = eye_in_col_; i <= eye_out_col_; ++i) {
            const int c = side == 0 ? i : 2 * centre_col_ - i;
            m.push_back(!upper && eye_lower_copy_[c] >= 0 ? eye_lower_copy_[c] : grid(c, eye_row_));
        }
        return m;
    }
    void place_feature_points(Face& face);

    int grid(int i, int j) const { return j * (ncols_ + 1) + i; }
    TriMesh::VertexHandle add_vertex(Face& face, glm::dvec3 p, double u, double v, VertexPart part) {
        auto vh = face.mesh.add_vertex(TriMesh::Point(static_cast<float>(p.x), static_cast<float>(p.y),
                                                      static_cast<float>(p.z)));
        face.mesh.set_texcoord2D(vh, TriMesh::TexCoord2D(static_cast<float>(u), static_cast<float>(v)));
        face.parts.push_back(part);
        return vh;
    }
    // Adds a triangle wound so its normal points along `outward`.
    void add_oriented(Face& face, int a, int b, int c, glm::dvec3 outward) {
        const auto pa = face.mesh.point(TriMesh::VertexHandle(a));
        const auto pb = face.mesh.point(TriMesh::VertexHandle(b));
        const auto pc = face.mesh.point(TriMesh::VertexHandle(c));
        const auto n = (pb - pa) % (pc - pa);
        if (n[0] * outward.x + n[1] * outward.y + n[2] * outward.z < 0) std::swap(b, c);
        add_triangle(face, a, b, c);
    }
    void add_triangle(Face& face, int a, int b, int c) {
        if (a == b || b == c || a == c) return;
        auto fh = face.mesh.add_face(TriMesh::VertexHandle(a), TriMesh::VertexHandle(b), TriMesh::VertexHandle(c));
        if (!fh.is_valid()) ++rejected_faces_;
    }

    const FaceParams& p_;
    FaceShape shape_;
    double scale_;

    std::vector<double> theta_;  // ncols_ + 1 azimuths, first and last the same seam
    int ncols_ = 0;
    int centre_col_ = 0;
    std::vector<Row> rows_;  // bottom (bust) to top (crown)
    Row lowest_ray_row_;     // where the bust rows start
    int bust_rows_ = 0;      // the bottom rows are the bust's
    // per column azimuth: the body's profile below the lowest ray row, 1 mm
    // steps (filled as the bust rows are made)
    mutable std::map<double, std::vector<glm::dvec3>> bust_profiles_;
    int eye_row_ = 0, mouth_row_ = 0, mouth_row_down_ = 0, mouth_key_ = 0;
    double mouth_angle_ = 0;
    // Per column: elevation offsets of the rows above / below each slit.
    std::vector<double> eye_up_, eye_lo_, mouth_dphi_;
    int eye_in_col_ = 0, eye_out_col_ = 0;      // left eye (theta > 0)
    int mouth_corner_col_ = 0;                  // left corner
    std::vector<int> eye_lower_copy_, mouth_lower_copy_;  // per column, -1 if none
    int pole_ = -1;
    int rejected_faces_ = 0;
    std::vector<glm::dvec3> base_;  // base (pre-relief) points of the skin vertices
    // vertex ranges of the mouth interior pieces
    int tongue_first_ = 0, tongue_count_ = 0, tongue_rings_ = 0, tongue_segments_ = 0;
    // the teeth's feature points (9.8-9.11)
    int upper_gum_point_ = 0, lower_gum_point_ = 0, upper_edge_point_ = 0, lower_edge_point_ = 0;
};

void Generator::make_columns() {
    // At least the columns the eye opening and the mouth need (4 each, see
    // below): resolutions down to 0.1 coarsen the rows, not the features.
    int front = scaled(p_.front_columns, scale_, 56);
    if (front % 2) ++front;
    int back = scaled(p_.back_columns, scale_, 4);
    if (back % 2) ++back;
    const double a = p_.front_half_angle_deg * kDeg;
    theta_.clear();
    for (int k = 0; k < back / 2; ++k) theta_.push_back(-kPi + (kPi - a) * k / (back / 2));
    for (int k = 0; k < front; ++k) theta_.push_back(-a + 2 * a * k / front);
    for (int k = 0; k <= back / 2; ++k) theta_.push_back(a + (kPi - a) * k / (back / 2));
    ncols_ = static_cast<int>(theta_.size()) - 1;
    centre_col_ = back / 2 + front / 2;
    theta_[centre_col_] = 0.0;
}

// Rows along a key path: the path is sampled finely, and rows are put at
// even arc length of the front profile (theta = 0), or of the back profile
// where that moves faster, so no stretch of the face falls between two rows.
std::vector<Row> Generator::resample(const std::vector<detail::RowKey>& keys) const {
    constexpr int kFine = 240;
    std::vector<Row> out;
    for (std::size_t k = 0; k + 1 < keys.size(); ++k) {
        const double spacing = (keys[k].spacing > 0 ? keys[k].spacing : p_.row_spacing) / scale_;
        std::vector<double> length(kFine + 1, 0.0);
        glm::dvec3 prev_f{0.0}, prev_b{0.0};
        for (int s = 0; s <= kFine; ++s) {
            const Row row = to_row(lerp_key(keys[k], keys[k + 1], static_cast<double>(s) / kFine));
            const glm::dvec3 f = shape_.displace(base_point(0.0, row, 0.0));
            const glm::dvec3 b = base_point(kPi, row, 0.0);
            if (s > 0) length[s] = length[s - 1] + std::max(glm::length(f - prev_f), 0.5 * glm::length(b - prev_b));
            prev_f = f;
            prev_b = b;
        }
        const int n = std::max(1, static_cast<int>(std::lround(length[kFine] / spacing)));
        int s = 0;
        for (int i = 1; i <= n; ++i) {
            const double target = length[kFine] * i / n;
            while (s < kFine && length[s + 1] < target) ++s;
            const double seg = length[std::min(s + 1, kFine)] - length[s];
            const double frac = seg > 0 ? (target - length[s]) / seg : 0.0;
            const double t = std::min(1.0, (s + frac) / kFine);
            out.push_back(to_row(lerp_key(keys[k], keys[k + 1], t)));
        }
    }
    return out;
}

// The body's profile in the column's plane (through the lowest ray row's
// origin, at azimuth theta), traced from that row's point down and out: each
// step goes along the surface's tangent in the plane (the outward normal
// turned clockwise: down the neck, out along the shoulders, down the chest)
// and is pulled back onto the surface along the field's gradient.
glm::dvec3 Generator::bust_point(double theta, double share) const {
    const double c = std::cos(theta);
    const glm::dvec3& len = p_.bust_length_mm;
    const double length = len[1] + ((c >= 0 ? len[0] : len[2]) - len[1]) * std::abs(c);
    auto it = bust_profiles_.find(theta);
    if (it == bust_profiles_.end()) {
        const glm::dvec3 o = lowest_ray_row_.origin(theta);
        const glm::dvec3 h{std::sin(theta), 0.0, c};
        auto at = [&](glm::dvec2 q) { return glm::dvec3{q.x * h.x, q.y, o.z + q.x * h.z}; };
        auto gradient = [&](glm::dvec2 q) {
            constexpr double e = 0.05;
            return glm::dvec2{shape_.field(at(q + glm::dvec2{e, 0})) - shape_.field(at(q - glm::dvec2{e, 0})),
                              shape_.field(at(q + glm::dvec2{0, e})) - shape_.field(at(q - glm::dvec2{0, e}))} /
                   (2.0 * e);
        };
        const glm::dvec3 start = base_point(theta, lowest_ray_row_, 0.0);
        glm::dvec2 q{glm::dot(start - o, h), start.y};
        std::vector<glm::dvec3> profile{at(q)};
        constexpr double kStep = 1.0;
        for (double walked = 0.0; walked < length + kStep;) {
            const glm::dvec2 g = gradient(q);
            glm::dvec2 next = q + glm::normalize(glm::dvec2{g.y, -g.x}) * kStep;
            for (int k = 0; k < 3; ++k) {
                const glm::dvec2 gn = gradient(next);
                next -= shape_.field(at(next)) * gn / std::max(glm::dot(gn, gn), 1e-12);
            }
            walked += glm::length(next - q);
            q = next;
            profile.push_back(at(q));
        }
        it = bust_profiles_.emplace(theta, std::move(profile)).first;
    }
    const std::vector<glm::dvec3>& profile = it->second;
    double target = share * length;
    for (std::size_t k = 1; k < profile.size(); ++k) {
        const double step = glm::length(profile[k] - profile[k - 1]);
        if (target <= step || k + 1 == profile.size())
            return profile[k - 1] + (profile[k] - profile[k - 1]) * std::min(target / std::max(step, 1e-12), 1.0);
        target -= step;
    }
    return profile.back();
}

void Generator::make_rows() {
    const auto& lk = p_.lower_rows;
    const auto& uk = p_.upper_rows;
    for (const auto* keys : {&lk, &uk}) {
        const auto& k0 = keys->front();
        if (k0.origin_y != 0 || k0.origin_z_front != 0 || k0.origin_z_back != 0 || k0.angle_front_deg != 0 ||
            k0.angle_back_deg != 0)
            fail<InputError>("expression: {}: upper_rows and lower_rows must start at eye level (origin_y 0, "
                             "origin_z [0, 0], angle_deg [0, 0])",
                             p_.file);
    }
    // Split the lower path where its front ray meets the mouth line, so one
    // row runs exactly along the closed lips.
    std::vector<detail::RowKey> lower = lk;
    const double mouth_y = shape_.mouth_line(0.0);
    bool split = false;
    for (std::size_t k = 0; k + 1 < lower.size() && !split; ++k) {
        auto front_y = [&](double t) {
            return base_point(0.0, to_row(lerp_key(lower[k], lower[k + 1], t)), 0.0).y - mouth_y;
        };
        if (front_y(1.0) > 0) continue;
        double lo = 0.0, hi = 1.0;
        for (int it = 0; it < 50; ++it) {
            const double mid = 0.5 * (lo + hi);
            (front_y(mid) > 0 ? lo : hi) = mid;
        }
        detail::RowKey mk = lerp_key(lower[k], lower[k + 1], 0.5 * (lo + hi));
        mk.spacing = lower[k].spacing;
        lower.insert(lower.begin() + static_cast<long>(k) + 1, mk);
        mouth_key_ = static_cast<int>(k) + 1;
        split = true;
    }
    if (!split) fail<InputError>("expression: {}: lower_rows never reaches the mouth", p_.file);
    mouth_angle_ = to_row(lower[mouth_key_]).angle_front;

    // Rows down to the mouth key, to find the mouth row's index.
    const std::vector<detail::RowKey> to_mouth(lower.begin(), lower.begin() + mouth_key_ + 1);
    const std::vector<detail::RowKey> from_mouth(lower.begin() + mouth_key_, lower.end());
    std::vector<Row> down = resample(to_mouth);
    mouth_row_down_ = static_cast<int>(down.size()) - 1;
    const std::vector<Row> rest = resample(from_mouth);
    down.insert(down.end(), rest.begin(), rest.end());
    const std::vector<Row> up = resample(uk);

    rows_.assign(down.rbegin(), down.rend());
    // The bust below: rows along the body's profile (face.json
    // resolution.bust), the first rows close (the collar's edge lies there),
    // widening evenly out along the shoulders. Rays cast out from the neck's
    // axis graze the shoulders' slope: its rows bunched on the neck and
    // jumped to the shoulders' rim, a flat disc streaked along its rows.
    lowest_ray_row_ = rows_.front();
    {
        const int n = scaled(p_.bust_rows, scale_, p_.bust_rows > 0 ? 2 : 0);
        const double a = p_.bust_first_share;
        std::vector<Row> bust;
        for (int j = n; j >= 1; --j) {
            const double u = static_cast<double>(j) / n;
            Row r = lowest_ray_row_;
            r.bust_share = a * u + (1.0 - a) * u * u;
            bust.push_back(r);
        }
        rows_.insert(rows_.begin(), bust.begin(), bust.end());
        bust_rows_ = n;
    }
    eye_row_ = static_cast<int>(rows_.size());
    mouth_row_ = eye_row_ - 1 - mouth_row_down_;
    rows_.push_back(to_row(lk[0]));
    rows_.insert(rows_.end(), up.begin(), up.end());
}

void Generator::compute_warps() {
    const int n = ncols_ + 1;
    eye_up_.assign(n, 0.0);
    eye_lo_.assign(n, 0.0);
    mouth_dphi_.assign(n, 0.0);
    eye_lower_copy_.assign(n, -1);
    mouth_lower_copy_.assign(n, -1);
    const Row& r0 = rows_[eye_row_];
    const Row& rm = rows_[mouth_row_];
    auto mirror = [&](int i) { return 2 * centre_col_ - i; };

    // Eye corners: the columns whose corner-height vertex is nearest the
    // designed corners; the opening is then fitted between those columns.
    auto corner_x = [&](int i, double y) {
        const double d = solve_offset(theta_[i], r0, [&](double) { return y; });
        return base_point(theta_[i], r0, d).x;
    };
    auto nearest_col = [&](double x, double y, const Row& row, bool eye) {
        int best = centre_col_;
        double best_d = std::numeric_limits<double>::max();
        for (int i = centre_col_; i <= ncols_ && theta_[i] < p_.front_half_angle_deg * kDeg; ++i) {
            const double xi = eye ? corner_x(i, y)
                                  : base_point(theta_[i], row, solve_offset(theta_[i], row, [&](double) { return y; })).x;
            if (std::abs(xi - x) < best_d) {
                best_d = std::abs(xi - x);
                best = i;
            }
        }
        return best;
    };
    eye_in_col_ = nearest_col(p_.inner_corner[0], p_.inner_corner[1], r0, true);
    eye_out_col_ = nearest_col(p_.outer_corner[0], p_.outer_corner[1], r0, true);
    if (eye_out_col_ - eye_in_col_ < 4)
        fail<InputError>("expression: {}: the eye opening spans {} grid columns; raise resolution.front_columns",
                         p_.file, eye_out_col_ - eye_in_col_);
    shape_.set_eye_corners(corner_x(eye_in_col_, p_.inner_corner[1]), corner_x(eye_out_col_, p_.outer_corner[1]));

    const double corner_in = solve_offset(theta_[eye_in_col_], r0, [&](double) { return shape_.eye.y_in; });
    const double corner_out = solve_offset(theta_[eye_out_col_], r0, [&](double) { return shape_.eye.y_out; });
    const double x_in = shape_.eye.x_in, x_out = shape_.eye.x_out;
    constexpr double kEyeFade = 8.0;  // mm beyond a corner over which the corner's offset fades
    for (int i = centre_col_; i <= ncols_ && theta_[i] < kPi * 0.5; ++i) {
        double up, lo;
        if (i == eye_in_col_) {
            up = lo = corner_in;
        } else if (i == eye_out_col_) {
            up = lo = corner_out;
        } else if (i > eye_in_col_ && i < eye_out_col_) {
            up = solve_offset(theta_[i], r0, [&](double x) { return shape_.eye.upper(std::abs(x)); });
            lo = solve_offset(theta_[i], r0, [&](double x) { return shape_.eye.lower(std::abs(x)); });
        } else {
            const double x = base_point(theta_[i], r0, 0.0).x;
            const double to_in = std::abs(x - x_in), to_out = std::abs(x - x_out);
            up = lo = to_in < to_out ? corner_in * warp_falloff(to_in, kEyeFade)
                                     : corner_out * warp_falloff(to_out, kEyeFade);
        }
        eye_up_[i] = eye_up_[mirror(i)] = up;
        eye_lo_[i] = eye_lo_[mirror(i)] = lo;
    }

    // Mouth corners and the closed mouth line between them.
    mouth_corner_col_ = nearest_col(p_.mouth_half_width, shape_.mouth_line(p_.mouth_half_width), rm, false);
    if (mouth_corner_col_ - centre_col_ < 4)
        fail<InputError>("expression: {}: the mouth spans too few grid columns; raise resolution.front_columns",
                         p_.file);
    {
        const double d = solve_offset(theta_[mouth_corner_col_], rm,
                                      [&](double) { return shape_.mouth_line(p_.mouth_half_width); });
        shape_.set_mouth_half_width(base_point(theta_[mouth_corner_col_], rm, d).x);
    }
    const double hw = shape_.mouth_half_width();
    const double corner_d = solve_offset(theta_[mouth_corner_col_], rm, [&](double) { return shape_.mouth_line(hw); });
    constexpr double kMouthFade = 14.0;
    for (int i = centre_col_; i <= ncols_ && theta_[i] < kPi * 0.5; ++i) {
        double d;
        if (i <= mouth_corner_col_) {
            d = i == mouth_corner_col_ ? corner_d
                                       : solve_offset(theta_[i], rm, [&](double x) { return shape_.mouth_line(x); });
        } else {
            const double x = base_point(theta_[i], rm, 0.0).x;
            d = corner_d * warp_falloff(std::abs(x - hw), kMouthFade);
        }
        mouth_dphi_[i] = mouth_dphi_[mirror(i)] = d;
    }
}

void Generator::build_skin(Face& face) {
    const int nrows = static_cast<int>(rows_.size());
    // Warps fade over a number of rows: the slit offsets are angles of at
    // most a few rows, and the fade must be slower than them (see warp_falloff).
    const double spacing = p_.row_spacing / scale_;
    const double eye_reach = p_.lid_warp_reach / spacing;
    const double mouth_reach = p_.mouth_warp_reach / spacing;
    auto offset = [&](int i, int j, bool lower_copy) {
        double d = 0.0;
        if (j == eye_row_) d += lower_copy ? eye_lo_[i] : eye_up_[i];
        else if (j > eye_row_) d += eye_up_[i] * warp_falloff(j - eye_row_, eye_reach);
        else d += eye_lo_[i] * warp_falloff(eye_row_ - j, eye_reach);
        d += mouth_dphi_[i] * warp_falloff(std::abs(j - mouth_row_), mouth_reach);
        return d;
    };
    // Each row gap takes the same height of texture, but the bust's (a
    // few mm to a few cm apart) take bust.texture_rows in all, each in
    // inverse proportion to the square root of its spacing: more where the
    // rows are closest, round the collar, whose edge one texture row per
    // gap blurred across the rows at the mip level that the columns' denser
    // u picks; enough on the outer rows that the shader's pores (tiled in
    // the base UVs) do not stretch down the chest into streaks, as they did
    // at inverse proportion to the spacing itself.
    std::vector<double> below(static_cast<std::size_t>(nrows), 0.0);
    {
        const double a = p_.bust_first_share;
        auto share = [&](double u) { return a * u + (1.0 - a) * u * u; };
        std::vector<double> w(static_cast<std::size_t>(bust_rows_));
        double sum = 0.0;
        for (int j = 0; j < bust_rows_; ++j) {
            const int k = bust_rows_ - 1 - j;  // gaps counted from the neck
            const double spacing = share(static_cast<double>(k + 1) / bust_rows_) - share(static_cast<double>(k) / bust_rows_);
            w[j] = 1.0 / std::sqrt(spacing);
            sum += w[j];
        }
        const double total = p_.bust_rows > 0 ? p_.bust_texture_rows * bust_rows_ / p_.bust_rows : 0.0;
        for (int j = 1; j < nrows; ++j) below[j] = below[j - 1] + (j - 1 < bust_rows_ ? total * w[j - 1] / sum : 1.0);
    }
    auto v_of = [&](int j) { return detail::kSkinV0 + (0.995 - detail::kSkinV0) * below[j] / below.back(); };

    for (int j = 0; j < nrows; ++j) {
        for (int i = 0; i <= ncols_; ++i) {
            const glm::dvec3 b = base_point(theta_[i], rows_[j], offset(i, j, false));
            base_.push_back(b);
            add_vertex(face, shape_.displace(b), static_cast<double>(i) / ncols_, v_of(j), VertexPart::Skin);
        }
    }
    auto mirror = [&](int i) { return 2 * centre_col_ - i; };
    for (int i = eye_in_col_ + 1; i < eye_out_col_; ++i) {
        for (int c : {i, mirror(i)}) {
            const glm::dvec3 b = base_point(theta_[c], rows_[eye_row_], offset(c, eye_row_, true));
            base_.push_back(b);
            eye_lower_copy_[c] = add_vertex(face, shape_.displace(b), static_cast<double>(c) / ncols_, v_of(eye_row_),
                                            VertexPart::Skin)
                                     .idx();
        }
    }
    for (int i = mirror(mouth_corner_col_) + 1; i < mouth_corner_col_; ++i) {
        const glm::dvec3 b = base_[grid(i, mouth_row_)];
        base_.push_back(b);
        mouth_lower_copy_[i] =
            add_vertex(face, shape_.displace(b), static_cast<double>(i) / ncols_, v_of(mouth_row_), VertexPart::Skin).idx();
    }
    {
        const glm::dvec3 o = rows_.back().origin(0.0);
        const glm::dvec3 b = o + glm::dvec3{0, 1, 0} * shape_.cast(o, {0, 1, 0});
        base_.push_back(b);
        pole_ = add_vertex(face, shape_.displace(b), 0.5, 0.999, VertexPart::Skin).idx();
    }

    // The band just below a slit row takes the lower copies.
    auto at = [&](int i, int j, bool below_slit) {
        if (below_slit && j == eye_row_ && eye_lower_copy_[i] >= 0) return eye_lower_copy_[i];
        if (below_slit && j == mouth_row_ && mouth_lower_copy_[i] >= 0) return mouth_lower_copy_[i];
        return grid(i, j);
    };
    for (int j = 0; j + 1 < nrows; ++j) {
        for (int i = 0; i < ncols_; ++i) {
            const int a = grid(i, j), b = grid(i + 1, j);
            const int c = at(i + 1, j + 1, true), d = at(i, j + 1, true);
            // Diagonals mirror across the midline so symmetric FAPs deform
            // both halves alike.
            if (i >= centre_col_) {
                add_triangle(face, a, b, c);
                add_triangle(face, a, c, d);
            } else {
                add_triangle(face, a, b, d);
                add_triangle(face, b, c, d);
            }
        }
    }
    for (int i = 0; i < ncols_; ++i) add_triangle(face, grid(i, nrows - 1), grid(i + 1, nrows - 1), pole_);
}

void Generator::build_eyeball(Face& face, int side) {
    const double sx = side == 0 ? 1.0 : -1.0;
    const glm::dvec3 c{p_.eye_centre[0] * sx, p_.eye_centre[1], p_.eye_centre[2]};
    const double R = p_.eye_radius;
    const int rings = p_.eyeball_rings, segs = p_.eyeball_segments;
    const double iris = std::asin(p_.iris_radius / R);
    // A third of the rings cover the iris so pupil dilation has vertices to move.
    std::vector<double> alpha;
    const int front_rings = rings / 3;
    for (int k = 1; k <= front_rings; ++k) alpha.push_back(iris * 1.15 * k / front_rings);
    for (int k = 1; k < rings - front_rings; ++k)
        alpha.push_back(detail::mix(iris * 1.15, kPi * 0.985, static_cast<double>(k) / (rings - front_rings - 1)));

    Eyeball eb;
    eb.centre = {c.x, c.y, c.z};
    eb.radius = R;
    eb.iris_angle = iris;
    eb.pupil_angle = std::asin(p_.pupil_radius / R);
    eb.vertices.first = face.vertex_count();
    const VertexPart part = side == 0 ? VertexPart::EyeballLeft : VertexPart::EyeballRight;
    // Both eyes share the eye tile in each eye's own frame (azimuth 0
    // towards the outer corner): the right eye's azimuths are mirrored, so
    // what the tile paints nasally (the caruncle) is nasal on both.
    auto uv = [&](double a, double b, double& u, double& v) {
        if (side == 1) b = kPi - b;
        const double r = 0.48 * a / kPi;
        u = detail::tile_u0(detail::Tile::Eye) + detail::kTile * (0.5 + r * std::cos(b));
        v = detail::kTile * (0.5 + r * std::sin(b));
    };
    // How far the cornea stands off the eyeball at angle a off the eye's
    // axis: its sphere (radius Rc) meets the eyeball's where the two are
    // cornea_reach off the axis.
    const double Rc = p_.cornea_radius, reach = std::min(p_.cornea_reach, 0.9 * Rc);
    const double cornea_base = std::sqrt(R * R - reach * reach) - std::sqrt(Rc * Rc - reach * reach);
    auto cornea = [&](double a) {
        const double r = R * std::sin(a);
        if (a >= kPi / 2 || r >= reach) return 0.0;
        return std::max(0.0, cornea_base + std::sqrt(Rc * Rc - r * r) - R * std::cos(a));
    };
    const int front = add_vertex(face, c + glm::dvec3{0, 0, R + cornea(0.0)},
                                 detail::tile_u0(detail::Tile::Eye) + 0.5 * detail::kTile,
                                 0.5 * detail::kTile, part)
                          .idx();
    const int first_ring = face.vertex_count();
    for (double a : alpha) {
        for (int s = 0; s < segs; ++s) {
            const double b = 2 * kPi * s / segs;
            double u, v;
            uv(a, b, u, v);
            const glm::dvec3 dir{std::sin(a) * std::cos(b), std::sin(a) * std::sin(b), std::cos(a)};
            add_vertex(face, c + dir * (R + cornea(a)), u, v, part);
        }
    }
    double bu, bv;
    uv(kPi, 0, bu, bv);
    const int back = add_vertex(face, c + glm::dvec3{0, 0, -R}, bu, bv, part).idx();
    eb.vertices.count = face.vertex_count() - eb.vertices.first;
    auto ring = [&](int k, int s) { return first_ring + k * segs + (s % segs); };
    auto out = [&](int a) {
        const auto q = face.mesh.point(TriMesh::VertexHandle(a));
        return glm::dvec3{q[0] - c.x, q[1] - c.y, q[2] - c.z};
    };
    const int nr = static_cast<int>(alpha.size());
    for (int s = 0; s < segs; ++s) add_oriented(face, front, ring(0, s), ring(0, s + 1), out(ring(0, s)));
    for (int k = 0; k + 1 < nr; ++k)
        for (int s = 0; s < segs; ++s) {
            add_oriented(face, ring(k, s), ring(k + 1, s), ring(k + 1, s + 1), out(ring(k + 1, s)));
            add_oriented(face, ring(k, s), ring(k + 1, s + 1), ring(k, s + 1), out(ring(k, s + 1)));
        }
    for (int s = 0; s < segs; ++s) add_oriented(face, back, ring(nr - 1, s + 1), ring(nr - 1, s), out(ring(nr - 1, s)));

    eb.upper_margin = margin(side, true);
    eb.lower_margin = margin(side, false);
    face.eyeballs.push_back(std::move(eb));
}

// Eyelashes: thin ribbons, each grown from the lid margin in three segments
// that turn away from the eye (up for the upper lid, down for the lower)
// more and more towards the tip, with some spread in length and direction
// so they clump as lashes do. A lash's first vertex is welded to the margin
// vertex it grows from: the rig carries the lash with that vertex, turning it
// as the lid turns about the eye. Their UVs fall in the eye tile's corner,
// painted the lashes' colour.
void Generator::build_lashes(Face& face, int side, bool upper) {
    const FaceParams::LashRow& row = upper ? p_.upper_lashes : p_.lower_lashes;
    const std::vector<int> margin = this->margin(side, upper);
    if (row.count == 0 || margin.size() < 3) return;
    auto point = [&](int v) {
        const auto q = face.mesh.point(TriMesh::VertexHandle(v));
        return glm::dvec3{q[0], q[1], q[2]};
    };
    std::vector<double> arc(margin.size(), 0.0);
    for (std::size_t i = 1; i < margin.size(); ++i)
        arc[i] = arc[i - 1] + glm::length(point(margin[i]) - point(margin[i - 1]));
    const glm::dvec3 centre{p_.eye_centre[0] * (side == 0 ? 1.0 : -1.0), p_.eye_centre[1], p_.eye_centre[2]};
    const double outward = side == 0 ? 1.0 : -1.0;  // +x towards this eye's outer corner
    std::mt19937 random(static_cast<unsigned>(1 + 2 * side + (upper ? 0 : 1)));
    auto uniform = [&] { return static_cast<double>(random()) / 4294967296.0; };
    constexpr int kSections = 4;
    // Lashes grow in clumps of about four whose tips lean together (a comb
    // of evenly spaced, parallel lashes read as spiky): a clump's tips are
    // pulled towards its middle root by kClumpPull of the gap.
    constexpr int kClump = 4;
    constexpr double kClumpPull = 0.85;
    const double u0 = detail::tile_u0(detail::Tile::Eye);
    auto root_s = [&](double k) { return 0.05 + 0.9 * (k + 0.5) / row.count; };
    for (int k = 0; k < row.count; ++k) {
        // Where along the margin (0 inner corner, 1 outer), clear of the corners.
        const double s = 0.05 + 0.9 * (k + 0.5 + 0.8 * (uniform() - 0.5)) / row.count;
        const int clump_first = k - k % kClump;
        const double clump_s = root_s(clump_first + 0.5 * (std::min(kClump, row.count - clump_first) - 1));
        const double at = s * arc.back();
        std::size_t i = 1;
        while (i + 1 < arc.size() && arc[i] < at) ++i;
        const double t = (at - arc[i - 1]) / std::max(arc[i] - arc[i - 1], 1e-9);
        const glm::dvec3 a = point(margin[i - 1]), b = point(margin[i]);
        const glm::dvec3 root = a + (b - a) * t;
        const int anchor = margin[t < 0.5 ? i - 1 : i];
        // The frame at the root: radial out of the eye, along the margin
        // towards the outer corner, and away from the opening.
        const glm::dvec3 radial = detail::normalised(root - centre);
        glm::dvec3 along = detail::normalised(b - a);
        if (along.x * outward < 0) along = along * -1.0;
        glm::dvec3 away = detail::normalised(glm::cross(along, radial));
        if ((away.y > 0) != upper) away = away * -1.0;
        // Longest mid-lid, shortest at the inner end (FIDELITY.md).
        const double len = row.length * (0.45 + 0.55 * std::pow(std::sin(kPi * s), 0.6)) * (0.75 + 0.25 * s) *
                           (0.75 + 0.5 * uniform());
        // The tip's pull towards the clump's middle, at most 0.4 of the
        // lash's length: a sparse row's gaps (the lower lashes', 1.3 mm)
        // pulled a short lash's tip further sideways than it is long, and
        // its ribbon folded over itself (DefaultFace.SkinIsOrientedOutward).
        const double pull = std::clamp(kClumpPull * (clump_s - s) * arc.back(), -0.4 * len, 0.4 * len);
        // Uneven lengths and directions: a comb of like lashes reads as a brush.
        const double lift = (row.lift_deg + 18.0 * (uniform() - 0.5)) * kDeg;
        const double curl = row.curl_deg * (0.8 + 0.4 * uniform()) * kDeg;
        const double splay = 0.25 * (uniform() - 0.5) + 0.35 * (s - 0.5);  // outer lashes lean outwards
        glm::dvec3 p = root + radial * 0.3;  // from the lid's front edge
        const int first = face.vertex_count();
        for (int c = 0; c < kSections; ++c) {
            const double f = static_cast<double>(c) / (kSections - 1);
            const double angle = lift + curl * f * f;
            const glm::dvec3 dir =
                detail::normalised(radial * std::cos(angle) + away * std::sin(angle) + along * splay);
            const double half = 0.5 * row.width * (1.0 - 0.8 * f);
            const glm::dvec3 side_dir = detail::normalised(along - dir * glm::dot(along, dir));
            const double u = u0 + detail::kTile * (0.02 + 0.06 * f);
            const glm::dvec3 q = p + along * (pull * f * f);
            add_vertex(face, q - side_dir * half, u, detail::kTile * 0.02, VertexPart::Skin);
            add_vertex(face, q + side_dir * half, u, detail::kTile * 0.08, VertexPart::Skin);
            if (c + 1 < kSections) {
                const double g = (c + 0.5) / (kSections - 1);
                const double mid = lift + curl * g * g;
                p = p + detail::normalised(radial * std::cos(mid) + away * std::sin(mid) + along * splay) *
                            (len / (kSections - 1));
            }
        }
        for (int c = 0; c + 1 < kSections; ++c) {
            const int q = first + 2 * c;
            add_triangle(face, q, q + 1, q + 3);
            add_triangle(face, q, q + 3, q + 2);
        }
        face.welded.push_back({anchor, first});
    }
}

void Generator::build_mouth_interior(Face& face) {
    using detail::Tile;
    // Cavity: the back half of an ellipsoid, open towards the lips, seen from inside.
    {
        const glm::dvec3 cc{p_.cavity_centre[0], p_.cavity_centre[1], p_.cavity_centre[2]};
        const glm::dvec3 r{p_.cavity_radii[0], p_.cavity_radii[1], p_.cavity_radii[2]};
        const int rings = 10, segs = 36;
        auto part_of = [&](double y) { return y >= cc.y ? VertexPart::MouthUpper : VertexPart::MouthLower; };
        auto uv = [&](double g, double s, double& u, double& v) {
            // The cavity's mucosa is a dark red (the tile's rim), darker
            // towards the back wall (the tile's centre) on top of the
            // renderer's occlusion, baked for the interior (face_scene.cpp
            // bake_occlusion), which lightens it where the lips part: the
            // occlusion alone left the back wall lit like the lips, a
            // shallow mouth.
            const double rr = 0.48 * (0.25 + 0.75 * g / (0.5 * kPi));
            u = detail::tile_u0(Tile::Cavity) + detail::kTile * (0.5 + rr * std::cos(s));
            v = detail::kTile * (0.5 + rr * std::sin(s));
        };
        double u, v;
        uv(0, 0, u, v);
        const int back = add_vertex(face, cc + glm::dvec3{0, 0, -r.z}, u, v, part_of(cc.y)).idx();
        const int first = face.vertex_count();
        for (int k = 1; k <= rings; ++k) {
            const double g = 0.5 * kPi * k / rings;
            for (int s = 0; s < segs; ++s) {
                const double a = 2 * kPi * s / segs;
                const glm::dvec3 q = cc + glm::dvec3{r.x * std::sin(g) * std::cos(a), r.y * std::sin(g) * std::sin(a),
                                                     -r.z * std::cos(g)};
                uv(g, a, u, v);
                add_vertex(face, q, u, v, part_of(q.y));
            }
        }
        auto ring = [&](int k, int s) { return first + k * segs + (s % segs); };
        auto inward = [&](int a) {
            const auto q = face.mesh.point(TriMesh::VertexHandle(a));
            return glm::dvec3{cc.x - q[0], cc.y - q[1], cc.z - q[2]};
        };
        for (int s = 0; s < segs; ++s) add_oriented(face, back, ring(0, s), ring(0, s + 1), inward(ring(0, s)));
        for (int k = 0; k + 1 < rings; ++k)
            for (int s = 0; s < segs; ++s) {
                add_oriented(face, ring(k, s), ring(k + 1, s), ring(k + 1, s + 1), inward(ring(k + 1, s)));
                add_oriented(face, ring(k, s), ring(k + 1, s + 1), ring(k, s + 1), inward(ring(k, s + 1)));
            }
    }
    // Teeth: individual crowns along each dental arch (incisors, canines,
    // premolars, first molars; FaceParams crowns: width along the arch and
    // crown height, from the midline out), each a loft of rounded sections
    // from the gum line to the biting edge (incisors thin to a blade,
    // canines to a point), and a gum band over their necks with papillae
    // reaching down between them.
    const auto stomion = face.mesh.point(TriMesh::VertexHandle(grid(centre_col_, mouth_row_)));
    const double z_front = stomion[2] - p_.teeth_gap;  // labial face of the upper incisors
    auto arch = [&](bool upper) {
        const double sign = upper ? 1.0 : -1.0;  // from the biting edge towards the root
        // The upper incisors' edge shows 2-3 mm below the relaxed upper lip
        // (incisal display at rest); the lower incisors' edge rises about 2 mm
        // behind it (overbite), hidden by the lower lip until the jaw drops.
        const double y_edge = upper ? p_.mouth_y - 2.5 : p_.mouth_y - 0.5;
        const double W = upper ? p_.teeth_half_width : p_.teeth_half_width - 2.0;
        const double D = upper ? p_.teeth_depth : p_.teeth_depth - 1.5;
        const double z0 = upper ? z_front : z_front - 2.2;  // lower incisors sit behind the upper ones
        const VertexPart part = upper ? VertexPart::MouthUpper : VertexPart::MouthLower;
        const std::vector<glm::dvec2>& crowns = upper ? p_.upper_crowns : p_.lower_crowns;
        // The arch: x = W sin(tau), z = z0 - D (1 - cos(tau)); arc length by table.
        constexpr int kTable = 400;
        std::vector<double> arc(kTable + 1, 0.0);
        auto at = [&](double tau) { return glm::dvec3{W * std::sin(tau), 0.0, z0 - D * (1.0 - std::cos(tau))}; };
        const double tau_max = 0.5 * kPi;
        for (int k = 1; k <= kTable; ++k)
            arc[k] = arc[k - 1] + glm::length(at(tau_max * k / kTable) - at(tau_max * (k - 1) / kTable));
        auto tau_of = [&](double sarc) {  // arc length from the midline -> tau (left side)
            int k = 0;
            while (k < kTable && arc[k + 1] < sarc) ++k;
            const double f = (sarc - arc[k]) / std::max(arc[std::min(k + 1, kTable)] - arc[k], 1e-9);
            return tau_max * (k + std::min(f, 1.0)) / kTable;
        };
        auto frame = [&](double sarc, double side, glm::dvec3& pos, glm::dvec3& along, glm::dvec3& out) {
            const double tau = tau_of(sarc) * side;
            pos = at(tau);
            along = detail::normalised(glm::dvec3{W * std::cos(tau), 0.0, -D * std::sin(tau)});
            out = detail::normalised(glm::dvec3{along.z, 0.0, -along.x});  // horizontal, away from the arch's inside
            if (glm::dot(out, glm::dvec3{pos.x, 0.0, pos.z - (z0 - D)}) < 0) out = -out;
        };
        auto tile_uv = [&](std::size_t crown, double toward_contact, double c, double& u, double& v) {
            // The painter's teeth tile (face_texture.cpp): c 0 gum .. 1 edge
            // (front) .. 2 edge (back) .. 3 gum; k along the arch, where it
            // paints the shaded gaps of a one-piece arch. The crowns are apart
            // here, so each takes the columns just past its own distal gap
            // (the tile ends before the molar's, 41 mm: it shares the second
            // premolar's; 0.8 of that along the lower arch), a crown's sides
            // (toward_contact 1) nearest it: each crown is shaded towards its
            // contacts with its neighbours, and a row of them reads as teeth,
            // not a white strip; and the painter darkens the arch from the
            // incisors back and gives each column its own shade.
            constexpr double kDistalGap[] = {4.3, 10.6, 17.8, 24.6, 31.4};
            const double gap = kDistalGap[std::min<std::size_t>(crown, 4)];
            const double s = (upper ? gap : 0.8 * gap) + 0.1 + 2.9 * (1.0 - toward_contact);
            const double k = 0.5 + s / p_.teeth_half_width / (0.92 * kPi);
            u = detail::tile_u0(Tile::Teeth) + detail::kTile * (0.02 + 0.96 * k);
            v = detail::kTile * ((upper ? 0.5 : 0.0) + 0.02 + 0.46 * c / 3.0);
        };
        // The biting edges are not one straight line: the lateral incisors'
        // stop short of the centrals', the canine's tip reaches nearly as
        // far, the back teeth rise along the curve of the occlusal plane (mm
        // towards the root); a level edge read as a flat strip of teeth.
        auto tip_y = [&](std::size_t t) {
            constexpr double kEdgeRise[] = {0.0, 0.7, 0.25, 0.6, 0.9, 1.2};
            return y_edge + sign * (upper ? 1.0 : 0.5) * kEdgeRise[std::min<std::size_t>(t, 5)];
        };
        std::vector<double> bounds{0.0};  // tooth boundaries along the arch (mm from the midline)
        for (const glm::dvec2& c : crowns) bounds.push_back(bounds.back() + c[0]);
        int first = -1;
        constexpr int kLevels = 6, kRound = 14;
        for (double side : {1.0, -1.0}) {
            for (std::size_t t = 0; t < crowns.size(); ++t) {
                const double width = crowns[t][0], height = crowns[t][1];
                const bool incisor = t < 2, canine = t == 2;
                const double s_mid = 0.5 * (bounds[t] + bounds[t + 1]);
                glm::dvec3 pos, along, out;
                frame(s_mid, side, pos, along, out);
                // Cross-section half sizes along the arch (a) and across it (b) at f = 0 (gum) .. 1 (edge).
                auto half_a = [&](double f) {
                    // The crowns press into their neighbours a little, so
                    // only the embrasures by the edge and the gum show the
                    // dark mouth behind: apart, a black seam ran the full
                    // height of every gap (a grille).
                    const double w = 0.5 * width + 0.12;
                    if (canine) return w * (f < 0.6 ? detail::mix(0.8, 1.0, f / 0.6) : detail::mix(1.0, 0.25, (f - 0.6) / 0.4));
                    // An incisor's edge corners are rounded off, so small
                    // notches (incisal embrasures) part the crowns where
                    // they show below the lip: square corners meeting
                    // their neighbours made one flat strip of teeth.
                    if (incisor)
                        return w * (f < 0.7 ? detail::mix(0.78, 1.0, f / 0.7) : detail::mix(1.0, 0.86, std::pow((f - 0.7) / 0.3, 1.5)));
                    return w * detail::mix(0.85, 0.95, f);
                };
                auto half_b = [&](double f) {
                    if (incisor) return detail::mix(3.2, 0.6, std::pow(f, 1.3));
                    if (canine) return detail::mix(3.8, 1.2, f * f);
                    return detail::mix(4.2, 3.6, f);
                };
                // Incisors lean forward to the edge; all sit on the arch.
                const double lean = incisor ? 2.0 : (canine ? 1.0 : 0.0);
                const int tooth_first = face.vertex_count();
                if (first < 0) first = tooth_first;
                const double y_tip = tip_y(t);
                double u, v;
                for (int l = 0; l < kLevels; ++l) {
                    const double f = static_cast<double>(l) / (kLevels - 1);
                    const double y = y_tip + sign * height * (1.0 - f);
                    const glm::dvec3 c = pos + out * (lean * f - 0.5 * half_b(0.0)) + glm::dvec3{0, y, 0};
                    for (int k = 0; k < kRound; ++k) {
                        const double ang = 2 * kPi * k / kRound;
                        const double ca = std::cos(ang), sa = std::sin(ang);
                        // Superellipse of exponent 3: boxy but rounded.
                        const double ex = 2.0 / 3.0;
                        const double px = half_a(f) * (ca < 0 ? -1 : 1) * std::pow(std::abs(ca), ex);
                        const double pz = half_b(f) * (sa < 0 ? -1 : 1) * std::pow(std::abs(sa), ex);
                        // Labial side (pz > 0) maps to c 0..1, lingual to 3..2.
                        tile_uv(t, ca * ca, sa >= 0 ? 0.35 + 0.6 * f : 2.65 - 0.6 * f, u, v);
                        add_vertex(face, c + along * px + out * pz, u, v, part);
                    }
                }
                tile_uv(t, 0.0, 1.0, u, v);
                const glm::dvec3 tip = pos + out * (lean - 0.5 * half_b(0.0)) + glm::dvec3{0, y_tip - sign * 0.3, 0};
                const int cap = add_vertex(face, tip, u, v, part).idx();
                auto ring = [&](int l, int k) { return tooth_first + l * kRound + (k % kRound); };
                // Out of the tooth: from its section's centre (the sections
                // shift with the lean) to the vertex.
                auto outward = [&](int a) {
                    const int l = (a - tooth_first) / kRound;
                    const double f = static_cast<double>(l) / (kLevels - 1);
                    const glm::dvec3 c = pos + out * (lean * f - 0.5 * half_b(0.0));
                    const auto q = face.mesh.point(TriMesh::VertexHandle(a));
                    return glm::dvec3{q[0] - c.x, 0.0, q[2] - c.z};
                };
                for (int l = 0; l + 1 < kLevels; ++l)
                    for (int k = 0; k < kRound; ++k) {
                        add_oriented(face, ring(l, k), ring(l + 1, k), ring(l + 1, k + 1), outward(ring(l, k)));
                        add_oriented(face, ring(l, k), ring(l + 1, k + 1), ring(l, k + 1), outward(ring(l, k + 1)));
                    }
                for (int k = 0; k < kRound; ++k)
                    add_oriented(face, cap, ring(kLevels - 1, k), ring(kLevels - 1, k + 1), glm::dvec3{0, -sign, 0});
                if (side > 0 && t == 0) {
                    // 9.8 / 9.9: the front of the teeth at the gum; 9.10 / 9.11: the incisors' biting edge.
                    const int labial = kRound / 4;  // ang = 90 deg: the labial face's middle
                    (upper ? upper_gum_point_ : lower_gum_point_) = ring(0, labial);
                    (upper ? upper_edge_point_ : lower_edge_point_) = ring(kLevels - 1, labial);
                }
            }
        }
        // The gum: a band over the crowns' necks along the whole arch, its
        // edge scalloped down between the teeth (papillae).
        const int sections = 48;
        const double s_end = bounds.back();
        const int gum_first = face.vertex_count();
        for (int k = 0; k <= sections; ++k) {
            const double sarc = -s_end + 2.0 * s_end * k / sections;
            glm::dvec3 pos, along, out;
            frame(std::abs(sarc), sarc < 0 ? -1.0 : 1.0, pos, along, out);
            double d = 1e9;
            for (double b : bounds) d = std::min(d, std::abs(std::abs(sarc) - b));
            if (std::abs(sarc) < 1e-6) d = 0.0;
            std::size_t t = 0;
            while (t + 1 < crowns.size() && std::abs(sarc) > bounds[t + 1]) ++t;
            const double neck = tip_y(t) + sign * crowns[t][1];
            const double papilla = 2.2 * std::exp(-(d / 1.3) * (d / 1.3));
            const double thick = (t < 2 ? 3.2 : (t == 2 ? 3.8 : 4.2)) + 0.7;
            const glm::dvec3 mid = pos + out * (-0.5 * (t < 2 ? 3.2 : 3.8));
            const glm::dvec3 sec[4] = {mid + out * thick + glm::dvec3{0, neck - sign * (0.6 + papilla), 0},
                                       mid + out * (thick + 0.8) + glm::dvec3{0, neck + sign * 3.0, 0},
                                       mid - out * (thick + 0.8) + glm::dvec3{0, neck + sign * 3.0, 0},
                                       mid - out * thick + glm::dvec3{0, neck - sign * (0.6 + papilla), 0}};
            const double cs[4] = {0.05, 0.0, 3.0, 2.95};
            for (int c = 0; c < 4; ++c) {
                double u, v;
                tile_uv(4, 0.0, cs[c], u, v);
                add_vertex(face, sec[c], u, v, part);
            }
        }
        for (int k = 0; k < sections; ++k)
            for (int c = 0; c < 3; ++c) {
                const int a = gum_first + 4 * k + c, b = gum_first + 4 * (k + 1) + c;
                const int d = gum_first + 4 * k + c + 1, e = gum_first + 4 * (k + 1) + c + 1;
                const auto pa = face.mesh.point(TriMesh::VertexHandle(a));
                const auto pd = face.mesh.point(TriMesh::VertexHandle(d));
                glm::dvec3 out_dir;
                if (c == 0) {
                    glm::dvec3 pos, along, out;
                    frame(std::abs(-s_end + 2.0 * s_end * k / sections), k < sections / 2 ? -1.0 : 1.0, pos, along, out);
                    out_dir = out;
                } else if (c == 1) {
                    out_dir = {0, sign, 0};
                } else {
                    glm::dvec3 pos, along, out;
                    frame(std::abs(-s_end + 2.0 * s_end * k / sections), k < sections / 2 ? -1.0 : 1.0, pos, along, out);
                    out_dir = -out;
                }
                (void)pa;
                (void)pd;
                add_oriented(face, a, b, e, out_dir);
                add_oriented(face, a, e, d, out_dir);
            }
        return first;
    };
    arch(true);
    arch(false);

    // Tongue: a body filling the lower arch, tip (+z pole) forward against
    // the lower incisors' lingual faces. Its dorsum rises from the tip to
    // behind its middle (kTipDrop: the front half's height is that much
    // lower at the tip's end), above the lower incisors' edges, and its
    // cross-section is flat on top with rounded margins (kSection, a
    // superellipse's exponent). Seen from the front through an open mouth,
    // the dorsum then fills the opening's lower part behind the lower
    // teeth; a flat ellipsoid lying under the incisors' edges showed only
    // its front rim, and the open mouth was a black hole (blind review,
    // session 9).
    {
        const glm::dvec3 tc{p_.tongue_centre[0], p_.tongue_centre[1], p_.tongue_centre[2]};
        const glm::dvec3 r{p_.tongue_radii[0], p_.tongue_radii[1], p_.tongue_radii[2]};
        constexpr double kTipDrop = 0.35, kSection = 0.75;
        auto body = [&](double a, double b) {
            const double sa = std::sin(a), ca = std::cos(a);
            auto boxy = [&](double c) { return (c < 0 ? -1.0 : 1.0) * std::pow(std::abs(c), kSection); };
            const double across = boxy(std::cos(b)), up = boxy(std::sin(b));
            const double height = up > 0 ? r.y * (1.0 - kTipDrop * ca) : r.y;
            return tc + glm::dvec3{r.x * sa * across, height * sa * up, r.z * ca};
        };
        tongue_rings_ = 14;
        tongue_segments_ = 20;
        auto uv = [&](double a, double b, double& u, double& v) {
            const double rr = 0.48 * a / kPi;
            u = detail::tile_u0(Tile::Tongue) + detail::kTile * (0.5 + rr * std::cos(b));
            v = detail::kTile * (0.5 + rr * std::sin(b));
        };
        tongue_first_ = face.vertex_count();
        double u, v;
        uv(0, 0, u, v);
        const int tip = add_vertex(face, tc + glm::dvec3{0, 0, r.z}, u, v, VertexPart::Tongue).idx();
        const int first = face.vertex_count();
        for (int k = 1; k < tongue_rings_; ++k) {
            const double a = kPi * k / tongue_rings_;
            for (int s = 0; s < tongue_segments_; ++s) {
                const double b = 2 * kPi * s / tongue_segments_;
                uv(a, b, u, v);
                add_vertex(face, body(a, b), u, v, VertexPart::Tongue);
            }
        }
        uv(kPi, 0, u, v);
        const int root = add_vertex(face, tc + glm::dvec3{0, 0, -r.z}, u, v, VertexPart::Tongue).idx();
        tongue_count_ = face.vertex_count() - tongue_first_;
        const int segs = tongue_segments_, nr = tongue_rings_ - 1;
        auto ring = [&](int k, int s) { return first + k * segs + (s % segs); };
        auto out = [&](int a) {
            const auto q = face.mesh.point(TriMesh::VertexHandle(a));
            return glm::dvec3{q[0] - tc.x, q[1] - tc.y, q[2] - tc.z};
        };
        for (int s = 0; s < segs; ++s) add_oriented(face, tip, ring(0, s), ring(0, s + 1), out(ring(0, s)));
        for (int k = 0; k + 1 < nr; ++k)
            for (int s = 0; s < segs; ++s) {
                add_oriented(face, ring(k, s), ring(k + 1, s), ring(k + 1, s + 1), out(ring(k + 1, s)));
                add_oriented(face, ring(k, s), ring(k + 1, s + 1), ring(k, s + 1), out(ring(k, s + 1)));
            }
        for (int s = 0; s < segs; ++s) add_oriented(face, root, ring(nr - 1, s + 1), ring(nr - 1, s), out(ring(nr - 1, s)));
    }
}

void Generator::place_feature_points(Face& face) {
    std::array<bool, fap::kFeaturePointCount> placed{};
    auto set_vertex = [&](const char* id, int v) {
        const int k = fap::feature_point_index(id);
        const auto q = face.mesh.point(TriMesh::VertexHandle(v));
        face.feature_points[k] = FeaturePointLocation{true, v, {q[0], q[1], q[2]}};
        placed[k] = true;
    };
    auto set_free = [&](const char* id, glm::dvec3 p) {
        const int k = fap::feature_point_index(id);
        face.feature_points[k] = FeaturePointLocation{true, -1, {p.x, p.y, p.z}};
        placed[k] = true;
    };
    auto mirror = [&](int i) { return 2 * centre_col_ - i; };
    // Points are chosen where the symmetric face has its vertices (the
    // shape's asymmetry taken off), so the two sides get mirrored columns
    // and rows and no two points share a vertex; they sit where the
    // vertices are.
    auto symmetric = [&](int v) {
        const auto q = face.mesh.point(TriMesh::VertexHandle(v));
        const glm::dvec3 p{q[0], q[1], q[2]};
        return p - shape_.asymmetry(p);
    };
    auto px = [&](int v) { return symmetric(v).x; };
    auto py = [&](int v) { return symmetric(v).y; };
    // Front column whose vertex on row j is nearest x (left side, x > 0).
    auto col_near = [&](double x, int j) {
        int best = centre_col_;
        for (int i = centre_col_; i <= ncols_ && theta_[i] < kPi * 0.5; ++i)
            if (std::abs(px(grid(i, j)) - x) < std::abs(px(grid(best, j)) - x)) best = i;
        return best;
    };
    // Vertex of column i between rows j0 and j1 nearest height y.
    auto row_near = [&](int i, int j0, int j1, double y) {
        int best = grid(i, j0);
        for (int j = std::min(j0, j1); j <= std::max(j0, j1); ++j)
            if (std::abs(py(grid(i, j)) - y) < std::abs(py(best) - y)) best = grid(i, j);
        return best;
    };

    // Inner lip contour: the mouth slit.
    const int cm = mouth_corner_col_;
    set_vertex("2.2", grid(centre_col_, mouth_row_));
    set_vertex("2.3", mouth_lower_copy_[centre_col_]);
    set_vertex("2.4", grid(cm, mouth_row_));
    set_vertex("2.5", grid(mirror(cm), mouth_row_));
    const double hw = shape_.mouth_half_width();
    const int half = std::min(col_near(hw * 0.5, mouth_row_), cm - 1);
    set_vertex("2.6", grid(half, mouth_row_));
    set_vertex("2.7", grid(mirror(half), mouth_row_));
    set_vertex("2.8", mouth_lower_copy_[half]);
    set_vertex("2.9", mouth_lower_copy_[mirror(half)]);
    // Outer lip contour: the vermilion borders.
    const int up_rows = mouth_row_ + 20, lo_rows = std::max(0, mouth_row_ - 20);
    set_vertex("8.1", row_near(centre_col_, mouth_row_ + 1, up_rows, shape_.upper_border(0)));
    set_vertex("8.2", row_near(centre_col_, lo_rows, mouth_row_ - 1, shape_.lower_border(0)));
    const int oc = col_near(hw + p_.outer_corner_offset, mouth_row_);
    set_vertex("8.3", grid(oc, mouth_row_));
    set_vertex("8.4", grid(mirror(oc), mouth_row_));
    set_vertex("8.5", row_near(half, mouth_row_ + 1, up_rows, shape_.upper_border(px(grid(half, mouth_row_)))));
    set_vertex("8.6", row_near(mirror(half), mouth_row_ + 1, up_rows, shape_.upper_border(px(grid(half, mouth_row_)))));
    set_vertex("8.7", row_near(half, lo_rows, mouth_row_ - 1, shape_.lower_border(px(grid(half, mouth_row_)))));
    set_vertex("8.8", row_near(mirror(half), lo_rows, mouth_row_ - 1, shape_.lower_border(px(grid(half, mouth_row_)))));
    {
        int peak = centre_col_;
        for (int i = centre_col_; i < cm; ++i)
            if (shape_.upper_border(px(grid(i, mouth_row_))) > shape_.upper_border(px(grid(peak, mouth_row_)))) peak = i;
        const double y = shape_.upper_border(px(grid(peak, mouth_row_)));
        set_vertex("8.10", row_near(peak, mouth_row_ + 1, up_rows, y));
        set_vertex("8.9", row_near(mirror(peak), mouth_row_ + 1, up_rows, y));
    }
    // Eyes.
    const int ce = std::clamp(col_near(p_.eye_centre[0], eye_row_), eye_in_col_ + 1, eye_out_col_ - 1);
    for (int side = 0; side < 2; ++side) {
        const int c = side == 0 ? ce : mirror(ce);
        const bool left = side == 0;
        const double x = std::abs(px(grid(c, eye_row_)));
        set_vertex(left ? "3.1" : "3.2", grid(c, eye_row_));
        set_vertex(left ? "3.3" : "3.4", eye_lower_copy_[c]);
        set_vertex(left ? "3.13" : "3.14", row_near(c, eye_row_ + 1, eye_row_ + 15, shape_.eye.upper(x) + 4.5));
        set_vertex(left ? "3.9" : "3.10", row_near(c, eye_row_ - 15, eye_row_ - 1, shape_.eye.lower(x) - 3.5));
        const int in = left ? eye_in_col_ : mirror(eye_in_col_), out = left ? eye_out_col_ : mirror(eye_out_col_);
        set_vertex(left ? "3.11" : "3.8", grid(in, eye_row_));
        set_vertex(left ? "3.7" : "3.12", grid(out, eye_row_));
        set_vertex(left ? "3.5" : "3.6", face.eyeballs[side].vertices.first);
    }
    // Skin points found by target position.
    const int skin_end = static_cast<int>(base_.size());
    auto nearest_front = [&](double x, double y) {
        int best = -1;
        double best_d = std::numeric_limits<double>::max();
        for (int v = 0; v < skin_end; ++v) {
            const auto n = face.mesh.normal(TriMesh::VertexHandle(v));
            if (n[2] < 0.25) continue;
            const double d = std::hypot(px(v) - x, py(v) - y);
            if (d < best_d) {
                best_d = d;
                best = v;
            }
        }
        return best;
    };
    auto nearest_3d = [&](glm::dvec3 t) {
        int best = 0;
        double best_d = std::numeric_limits<double>::max();
        for (int v = 0; v < skin_end; ++v) {
            const double d = glm::length(symmetric(v) - t);
            if (d < best_d) {
                best_d = d;
                best = v;
            }
        }
        return best;
    };
    // Brows (4.1 inner, 4.3 uppermost, 4.5 outer; right side mirrored).
    const char* brow_ids[3][2] = {{"4.1", "4.2"}, {"4.3", "4.4"}, {"4.5", "4.6"}};
    for (int k = 0; k < 3; ++k) {
        set_vertex(brow_ids[k][0], nearest_front(p_.brow_points[k][0], p_.brow_points[k][1]));
        set_vertex(brow_ids[k][1], nearest_front(-p_.brow_points[k][0], p_.brow_points[k][1]));
    }
    // Nose tip: the most forward skin point near the midline.
    {
        int best = -1;
        for (int v = 0; v < skin_end; ++v) {
            if (std::abs(px(v)) > 2.0 || py(v) > 0 || py(v) < p_.mouth_y) continue;
            if (best < 0 || face.mesh.point(TriMesh::VertexHandle(v))[2] > face.mesh.point(TriMesh::VertexHandle(best))[2])
                best = v;
        }
        set_vertex("9.3", best);
    }
    // Ears: top, back, lobe and the lower and upper contact with the head,
    // at their places in the ear's own coordinates: the skin vertex on the
    // side of the head nearest that side point (y, z).
    {
        struct EarPoint {
            const char* left;
            const char* right;
            double a, s;
        } ears[] = {{"10.1", "10.2", 0.97, -0.15}, {"10.3", "10.4", 0.15, -0.97}, {"10.5", "10.6", -0.97, 0.0},
                    {"10.7", "10.8", -0.72, 0.9},  {"10.9", "10.10", 0.7, 0.85}};
        for (const EarPoint& e : ears) {
            const glm::dvec2 yz = shape_.ear_point(e.a, e.s);
            for (const double side : {1.0, -1.0}) {
                int best = 0;
                double best_d = std::numeric_limits<double>::max();
                for (int v = 0; v < skin_end; ++v) {
                    const glm::dvec3 q = symmetric(v);
                    if (q[0] * side < 40.0) continue;
                    const double d = std::hypot(q[1] - yz[0], q[2] - yz[1]);
                    if (d < best_d) {
                        best_d = d;
                        best = v;
                    }
                }
                set_vertex(side > 0 ? e.left : e.right, best);
            }
        }
    }
    // Mouth interior.
    {
        const int segs = tongue_segments_;
        const int mid_ring = tongue_rings_ / 2 - 1;  // ring at pi/2
        set_vertex("6.1", tongue_first_);
        set_vertex("6.2", tongue_first_ + 1 + mid_ring * segs + segs / 4);
        set_vertex("6.3", tongue_first_ + 1 + mid_ring * segs);
        set_vertex("6.4", tongue_first_ + 1 + mid_ring * segs + segs / 2);
        set_vertex("9.8", upper_gum_point_);
        set_vertex("9.9", lower_gum_point_);
        set_vertex("9.10", upper_edge_point_);
        set_vertex("9.11", lower_edge_point_);
    }
    set_vertex("11.4", pole_);
    {
        const auto top = face.mesh.point(TriMesh::VertexHandle(pole_));
        set_free("11.5", {top[0], top[1] + 6.0, top[2]});
    }
    set_free("7.1", {p_.head_pivot[0], p_.head_pivot[1], p_.head_pivot[2]});

    for (const auto& [id, target] : p_.feature_targets) {
        const FileLoc at{p_.file, 0, detail::json_key_path("feature_points", id)};
        const auto k = fap::find_feature_point(id);
        if (!k) fail_data("expression", at, "an MPEG-4 feature point id as the key", "\"" + id + "\"");
        if (placed[*k]) fail_data("expression", at, "a point the generator does not place", "one it places (remove it)");
        const int v = target.size() == 2 ? nearest_front(target[0], target[1])
                                         : nearest_3d({target[0], target[1], target[2]});
        if (v < 0) fail_data("expression", at, "a target near front-facing skin", "none there");
        set_vertex(id.c_str(), v);
    }
    for (int k = 0; k < fap::kFeaturePointCount; ++k)
        if (!placed[k])
            fail_data("expression", FileLoc{p_.file, 0, "feature_points"},
                      fmt::format("a target for \"{}\"", fap::feature_points()[k].id), "none");
}

Face Generator::build(int texture_size) {
    Face face;
    face.name = "default";
    face.mesh.request_vertex_normals();
    face.mesh.request_vertex_texcoords2D();
    make_columns();
    make_rows();
    compute_warps();
    build_skin(face);
    // Lashes are skin (the renderer splits the mesh into runs of one part).
    for (int side = 0; side < 2; ++side) {
        build_lashes(face, side, true);
        build_lashes(face, side, false);
    }
    const int skin_count = face.vertex_count();
    build_eyeball(face, 0);
    build_eyeball(face, 1);
    build_mouth_interior(face);
    if (rejected_faces_ > 0)
        fail("expression: {}: {} triangles could not be added (the grid folds); check resolution rows", p_.file,
             rejected_faces_);

    face.mesh.request_face_normals();
    face.mesh.update_normals();
    // The seam at the back of the head doubles a column for the texture; give
    // both copies the same normal so shading does not show it, and weld them.
    for (int j = 0; j < static_cast<int>(rows_.size()); ++j) {
        face.welded.push_back({grid(0, j), grid(ncols_, j)});
        const TriMesh::VertexHandle a(grid(0, j)), b(grid(ncols_, j));
        auto n = face.mesh.normal(a) + face.mesh.normal(b);
        const float l = n.norm();
        if (l > 0) n /= l;
        face.mesh.set_normal(a, n);
        face.mesh.set_normal(b, n);
    }
    (void)skin_count;

    place_feature_points(face);
    face.jaw_pivot = {p_.jaw_pivot[0], p_.jaw_pivot[1], p_.jaw_pivot[2]};
    face.head_pivot = {p_.head_pivot[0], p_.head_pivot[1], p_.head_pivot[2]};
    face.texture_box.min = {float(p_.texture_box_min[0]), float(p_.texture_box_min[1])};
    face.texture_box.max = {float(p_.texture_box_max[0]), float(p_.texture_box_max[1])};
    update_fapu(face);
    face.base_colour = detail::paint_base_colour(shape_, face.mesh, texture_size);
    return face;
}

}  // namespace

Face make_default_face(const std::string& params_dir, const DefaultFaceOptions& options) {
    const FaceParams params = detail::read_face_params(params_dir);
    if (!(options.resolution_scale > 0.05 && options.resolution_scale <= 4.0))
        fail<InputError>("expression: resolution_scale must be in (0.05, 4], found {}", options.resolution_scale);
    if (options.texture_size != 0 && (options.texture_size < 16 || options.texture_size > 8192))
        fail<InputError>("expression: texture_size must be 0 or in [16, 8192], found {}", options.texture_size);
    Generator generator(params, options);
    return generator.build(options.texture_size > 0 ? options.texture_size : params.texture_size);
}

}  // namespace emoface::expression
