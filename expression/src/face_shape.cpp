#include "face_shape.h"

#include <algorithm>
#include <limits>

namespace emoface::expression::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

double ellipsoid_field(glm::dvec3 p, const Ellipsoid& e) {
    const double t = e.tilt_deg * kPi / 180.0;
    const glm::dvec3 d{p.x - e.centre[0], p.y - e.centre[1], p.z - e.centre[2]};
    const double ly = d.y * std::cos(t) + d.z * std::sin(t);
    const double lz = -d.y * std::sin(t) + d.z * std::cos(t);
    const glm::dvec3 q{d.x / e.radii[0], ly / e.radii[1], lz / e.radii[2]};
    const double rmin = std::min({e.radii[0], e.radii[1], e.radii[2]});
    return (glm::length(q) - 1.0) * rmin;
}

// Polynomial smooth minimum: the union of two volumes with a fillet of size k.
double smooth_min(double a, double b, double k) {
    if (k <= 0) return std::min(a, b);
    const double h = std::max(k - std::abs(a - b), 0.0) / k;
    return std::min(a, b) - h * h * k * 0.25;
}

double bump_value(const Bump& b, double x, double y, double sign) {
    const double cx = b.centre[0] * sign;
    const double a = b.angle_deg * kPi / 180.0 * sign;
    const double dx = x - cx, dy = y - b.centre[1];
    const double u = (dx * std::cos(a) + dy * std::sin(a)) / b.radius[0];
    const double v = (-dx * std::sin(a) + dy * std::cos(a)) / b.radius[1];
    const double r2 = u * u + v * v;
    if (r2 >= 1.0) return 0.0;
    const double k = 1.0 - r2;
    return k * k * k;
}

double bumps_value(const Bump& b, double x, double y) {
    double v = bump_value(b, x, y, 1.0);
    if (b.mirror) v += bump_value(b, x, y, -1.0);
    return v;
}

double ridge_value(const Ridge& r, double x, double y, double sign) {
    double best_d2 = std::numeric_limits<double>::max();
    double best_w = 1, best_h = 0;
    for (std::size_t i = 0; i + 1 < r.points.size(); ++i) {
        const double ax = r.points[i][0] * sign, ay = r.points[i][1];
        const double bx = r.points[i + 1][0] * sign, by = r.points[i + 1][1];
        const double ex = bx - ax, ey = by - ay;
        const double len2 = ex * ex + ey * ey;
        double t = len2 > 0 ? ((x - ax) * ex + (y - ay) * ey) / len2 : 0.0;
        t = clamp01(t);
        const double px = ax + t * ex - x, py = ay + t * ey - y;
        const double d2 = px * px + py * py;
        if (d2 < best_d2) {
            best_d2 = d2;
            best_w = mix(r.width[i], r.width[i + 1], t);
            best_h = mix(r.height[i], r.height[i + 1], t);
        }
    }
    const double q = best_d2 / (best_w * best_w);
    if (q >= 1.0) return 0.0;
    const double k = 1.0 - q;
    return best_h * k * k * k;
}

// Eyelid opening profile along the fissure: 0 at both corners, 1 at `peak`
// (a fraction of the way from the inner corner), pointed at the corners.
double lid_profile(double s, double peak) {
    if (s <= 0.0 || s >= 1.0) return 0.0;
    const double a = std::log(0.5) / std::log(std::clamp(peak, 0.1, 0.9));
    const double w = std::pow(s, a);
    return std::pow(std::sin(kPi * w), 0.8);
}

// Cross-section of a lip from where the lips meet (t = 0) to the vermilion
// border (t = 1) and onto the skin beyond (t > 1, `beyond` in mm).
double lip_bulge(double t, double peak, double beyond_mm) {
    constexpr double kAtBorder = 0.35;
    if (t <= 0) return 0.0;
    if (t < peak) return std::sin(0.5 * kPi * t / peak);
    if (t <= 1.0) return mix(kAtBorder, 1.0, std::cos(0.5 * kPi * (t - peak) / (1.0 - peak)));
    return kAtBorder * std::exp(-(beyond_mm / 2.5) * (beyond_mm / 2.5));
}

}  // namespace

double EyeOpening::upper(double ax) const {
    return slit(ax) + upper_height * lid_profile(s(ax), upper_peak);
}
double EyeOpening::lower(double ax) const {
    return slit(ax) - lower_height * lid_profile(s(ax), lower_peak);
}

FaceShape::FaceShape(const FaceParams& params) : p_(params) {
    eye.x_in = p_.inner_corner[0];
    eye.y_in = p_.inner_corner[1];
    eye.x_out = p_.outer_corner[0];
    eye.y_out = p_.outer_corner[1];
    eye.upper_height = p_.upper_lid_height;
    eye.lower_height = p_.lower_lid_height;
    eye.upper_peak = p_.upper_lid_peak;
    eye.lower_peak = p_.lower_lid_peak;
    mouth_half_width_ = p_.mouth_half_width;
}

void FaceShape::set_eye_corners(double x_in, double x_out) {
    eye.x_in = x_in;
    eye.x_out = x_out;
}

double FaceShape::field(glm::dvec3 p) const {
    double f = smooth_min(ellipsoid_field(p, p_.skull), ellipsoid_field(p, p_.lower_face), p_.blend);
    f = smooth_min(f, ellipsoid_field(p, p_.jaw), p_.blend);
    // The neck: a vertical elliptic cylinder, capped inside the head.
    const double qx = p.x / p_.neck_radii[0], qz = (p.z - p_.neck_centre_z) / p_.neck_radii[1];
    const double cyl = (std::sqrt(qx * qx + qz * qz) - 1.0) * std::min(p_.neck_radii[0], p_.neck_radii[1]);
    const double neck = std::max(cyl, p.y - p_.neck_top_y);
    return smooth_min(f, neck, p_.neck_blend);
}

glm::dvec3 FaceShape::field_normal(glm::dvec3 p) const {
    const double h = 0.05;
    const glm::dvec3 g{field({p.x + h, p.y, p.z}) - field({p.x - h, p.y, p.z}),
               field({p.x, p.y + h, p.z}) - field({p.x, p.y - h, p.z}),
               field({p.x, p.y, p.z + h}) - field({p.x, p.y, p.z - h})};
    return normalised(g);
}

double FaceShape::cast(glm::dvec3 origin, glm::dvec3 dir) const {
    constexpr double kStep = 1.5, kMax = 600.0;
    double lo = 0.0, hi = kStep;
    while (hi < kMax && field(origin + dir * hi) < 0.0) {
        lo = hi;
        hi += kStep;
    }
    for (int i = 0; i < 40; ++i) {
        const double mid = 0.5 * (lo + hi);
        (field(origin + dir * mid) < 0.0 ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

double FaceShape::mouth_line(double x) const {
    const double t = std::min(std::abs(x) / mouth_half_width_, 1.0);
    return p_.mouth_y + p_.mouth_corner_rise * t * t;
}

double FaceShape::upper_border(double x) const {
    const double ax = std::abs(x);
    const double t = std::min(ax / mouth_half_width_, 1.0);
    const double body = p_.upper_lip_height * std::pow(std::max(1.0 - t * t, 0.0), 0.55);
    const double bow = p_.cupid_dip * (0.5 * std::exp(-std::pow((ax - p_.cupid_peak_x) / 2.5, 2)) -
                                       std::exp(-std::pow(ax / 2.2, 2)));
    return mouth_line(x) + std::max(body + bow * (1.0 - t), 0.0);
}

double FaceShape::lower_border(double x) const {
    const double t = std::min(std::abs(x) / mouth_half_width_, 1.0);
    return mouth_line(x) - p_.lower_lip_height * std::pow(std::max(1.0 - t * t, 0.0), 0.65);
}

double FaceShape::lip_relief(double x, double y) const {
    const double ax = std::abs(x);
    const double hw = mouth_half_width_;
    if (ax > hw + 8.0) return 0.0;
    const double ys = mouth_line(x);
    const double inside = ax < hw ? 1.0 : 0.0;
    const double corner_fade = inside * std::sqrt(std::max(1.0 - (ax / hw) * (ax / hw), 0.0));
    // The lips roll inwards where they meet: a crease as deep as the mouth
    // line, continuing a little past the corners (the commissures).
    const double along = ax < hw ? 1.0 - 0.4 * std::pow(ax / hw, 4) : 0.6 * std::exp(-std::pow((ax - hw) / 2.5, 2));
    double h = -p_.lip_crease_depth * std::exp(-std::pow((y - ys) / p_.lip_crease_width, 2)) * along;
    if (corner_fade <= 0) return h;
    if (y >= ys) {
        const double height = std::max(upper_border(x) - ys, 0.5);
        const double t = (y - ys) / height;
        h += p_.upper_lip_protrusion * corner_fade * lip_bulge(t, 0.55, std::max(0.0, y - ys - height));
    } else {
        const double height = std::max(ys - lower_border(x), 0.5);
        const double t = (ys - y) / height;
        h += p_.lower_lip_protrusion * corner_fade * lip_bulge(t, 0.45, std::max(0.0, ys - y - height));
    }
    return h;
}

double FaceShape::relief(double x, double y) const {
    double h = 0.0;
    for (const Bump& b : p_.bumps) h += b.height * bumps_value(b, x, y);
    for (const Bump& b : p_.nostrils) h += b.height * bumps_value(b, x, y);
    for (const Ridge& r : p_.ridges) {
        h += ridge_value(r, x, y, 1.0);
        if (r.mirror) h += ridge_value(r, x, y, -1.0);
    }
    return h + lip_relief(x, y);
}

double FaceShape::nostril_amount(double x, double y) const {
    double a = 0.0;
    for (const Bump& b : p_.nostrils) a += bumps_value(b, x, y);
    return std::min(a, 1.0);
}

double FaceShape::lid_z(double x, double y, double margin_distance) const {
    const double cx = x >= 0 ? p_.eye_centre[0] : -p_.eye_centre[0];
    const double dx = x - cx, dy = y - p_.eye_centre[1];
    const double r = std::sqrt(dx * dx + dy * dy);
    const double radius = p_.eye_radius + p_.lid_clearance +
                          p_.lid_thickness * (1.0 - std::exp(-std::max(margin_distance, 0.0) / 0.8));
    if (r < radius) return p_.eye_centre[2] + std::sqrt(radius * radius - r * r);
    return p_.eye_centre[2] - (r - radius) * 2.0;
}

double FaceShape::lid_blend(double x, double y, double* margin_distance) const {
    const double ax = std::abs(x);
    double d;
    if (eye.inside_x(ax)) {
        const double up = eye.upper(ax), lo = eye.lower(ax);
        d = y > up ? y - up : (y < lo ? lo - y : 0.0);
    } else {
        const double cx = ax <= eye.x_in ? eye.x_in : eye.x_out;
        const double cy = ax <= eye.x_in ? eye.y_in : eye.y_out;
        d = std::hypot(ax - cx, y - cy);
    }
    if (margin_distance) *margin_distance = d;
    return 1.0 - glm::smoothstep(p_.lid_blend_inner, p_.lid_blend_outer, d);
}

double FaceShape::ear_relief(double y, double z) const {
    const double u = (y - p_.ear_centre_yz[0]) / p_.ear_radii_yz[0];
    const double v = (z - p_.ear_centre_yz[1]) / p_.ear_radii_yz[1];
    const double rho = std::sqrt(u * u + v * v);
    if (rho >= 1.0) return 0.0;
    const double H = p_.ear_height;
    // Attached along the front edge (v > 0), standing off the head behind.
    const double flare = 0.3 + 0.7 * glm::smoothstep(0.7, -0.7, v);
    const double outline = 1.0 - glm::smoothstep(0.8, 1.0, rho);
    double h = H * flare * outline;
    h += 0.2 * H * flare * std::exp(-std::pow((rho - 0.78) / 0.08, 2));  // helix rim
    h -= 0.45 * H * flare * std::exp(-(std::pow((u + 0.15) / 0.34, 2) + std::pow((v - 0.05) / 0.3, 2)));  // concha
    return std::max(h, 0.0);
}

glm::dvec3 FaceShape::displace(glm::dvec3 base) const {
    const glm::dvec3 n = field_normal(base);
    glm::dvec3 p = base;
    const double front = glm::smoothstep(0.05, 0.45, n.z);
    if (front > 0.0) {
        p.z += relief(base.x, base.y) * front;
        double md = 0;
        const double b = lid_blend(base.x, base.y, &md) * front;
        if (b > 0.0) p.z = mix(p.z, lid_z(base.x, base.y, md), b);
    }
    const double side = glm::smoothstep(0.55, 0.85, std::abs(n.x));
    if (side > 0.0) {
        const double e = ear_relief(base.y, base.z) * side;
        if (e > 0.0) p = p + n * e;
    }
    return p;
}

}  // namespace emoface::expression::detail
