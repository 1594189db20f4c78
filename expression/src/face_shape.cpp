#include "face_shape.h"

#include <algorithm>
#include <initializer_list>
#include <limits>

namespace emoface::expression::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

double ellipsoid_field(glm::dvec3 p, const Ellipsoid& e) {
    const glm::dvec3 d{p.x - e.centre[0], p.y - e.centre[1], p.z - e.centre[2]};
    double ly = d.y, lz = d.z;
    if (e.tilt_deg != 0.0) {
        const double t = e.tilt_deg * kPi / 180.0, c = std::cos(t), s = std::sin(t);
        ly = d.y * c + d.z * s;
        lz = -d.y * s + d.z * c;
    }
    const glm::dvec3 q{d.x / e.radii[0], ly / e.radii[1], lz / e.radii[2]};
    const double rmin = std::min({e.radii[0], e.radii[1], e.radii[2]});
    // The exponent-norm of q is at most its length for exponents above 2, so
    // the field stays 1-Lipschitz (a lower bound of the distance): cast()
    // relies on it.
    const double len = e.exponent == 2.0
                           ? glm::length(q)
                           : std::pow(std::pow(std::abs(q.x), e.exponent) + std::pow(std::abs(q.y), e.exponent) +
                                          std::pow(std::abs(q.z), e.exponent),
                                      1.0 / e.exponent);
    return (len - 1.0) * rmin;
}

double capsule_field(glm::dvec3 p, const Capsule& c, double sign) {
    const glm::dvec3 a{c.from.x * sign, c.from.y, c.from.z}, b{c.to.x * sign, c.to.y, c.to.z};
    const glm::dvec3 ab = b - a;
    const double t = clamp01(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-12));
    return glm::length(p - (a + ab * t)) - mix(c.radii[0], c.radii[1], t);
}

// |x| rounded over the band |x| < w (a parabola meeting the two lines with
// their slopes): smooth across the midline.
double soft_abs(double x, double w) {
    const double a = std::abs(x);
    return a >= w ? a : 0.5 * (a * a / w + w);
}

double part_field(glm::dvec3 p, const HeadPart& part) {
    if (!part.is_capsule) return ellipsoid_field(p, part.shape);
    if (!part.capsule.mirror) return capsule_field(p, part.capsule, 1.0);
    // A capsule and its mirror image: the nearer of the two is the one on
    // the point's side, so the pair is the capsule seen from |x|. Its slope
    // across the midline flips there; the plain minimum of the two was a
    // crease on x = 0 wherever the pair shaped the surface, a seam down the
    // throat and chest (the sternocleidomastoids' lower ends) lit on one
    // side and shaded on the other. Rounded over kMidlineRound mm, the two
    // join as one smooth hollow or ridge.
    constexpr double kMidlineRound = 6.0;
    const double side = part.capsule.from.x + part.capsule.to.x >= 0.0 ? 1.0 : -1.0;
    return capsule_field({side * soft_abs(p.x, kMidlineRound), p.y, p.z}, part.capsule, 1.0);
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

// A nostril: the bump's ellipse narrowed towards its medial end (a
// teardrop, wide at the ala, its point towards the columella), so the
// opening reads as a nostril's, not a drilled round dot.
double nostril_value(const Bump& b, double x, double y, double sign) {
    constexpr double kMedialWidth = 0.55;  // the medial end's width, of the lateral end's
    const double cx = b.centre[0] * sign;
    const double a = b.angle_deg * kPi / 180.0 * sign;
    const double dx = x - cx, dy = y - b.centre[1];
    const double u = (dx * std::cos(a) + dy * std::sin(a)) / b.radius[0];
    const double lateral = std::clamp(0.5 * (1.0 + u * sign), 0.0, 1.0);  // 0 medial end .. 1 lateral end
    const double v = (-dx * std::sin(a) + dy * std::cos(a)) / (b.radius[1] * mix(kMedialWidth, 1.0, std::sqrt(lateral)));
    const double r2 = u * u + v * v;
    if (r2 >= 1.0) return 0.0;
    const double k = 1.0 - r2;
    return k * k * k;
}

double nostrils_value(const Bump& b, double x, double y) {
    double v = nostril_value(b, x, y, 1.0);
    if (b.mirror) v += nostril_value(b, x, y, -1.0);
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
    // A rounded crest: the distance eases in over apex_round (its square
    // root form is flat to fourth order at the crest line), and the width
    // gives back what that takes, so the footprint stays where it was. A
    // tall, narrow ridge (the nose) otherwise has a crest of about 1 mm
    // radius, which shades as a seam down the midline.
    const double a = std::min(r.apex_round, 0.5 * best_w);
    const double d = a > 0 ? std::sqrt(best_d2 + a * a) - a : std::sqrt(best_d2);
    const double w = best_w - a;
    const double q = d * d / (w * w);
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
// border (t = 1, `height_mm` from the meeting line) and onto the skin beyond
// (t > 1, `beyond` in mm). Past the border the lip's fall continues at the
// slope it reaches there, easing out into the skin: a fall that stopped on a
// flat shelf (a Gaussian tail) drew the border as a crease, the outline of a
// separate lip shape laid on the face.
double lip_bulge(double t, double peak, double beyond_mm, double height_mm) {
    constexpr double kAtBorder = 0.35;
    if (t <= 0) return 0.0;
    if (t < peak) return std::sin(0.5 * kPi * t / peak);
    if (t <= 1.0) return mix(kAtBorder, 1.0, std::cos(0.5 * kPi * (t - peak) / (1.0 - peak)));
    const double slope = (1.0 - kAtBorder) * 0.5 * kPi / ((1.0 - peak) * std::max(height_mm, 0.5));  // per mm
    return kAtBorder * std::exp(-beyond_mm * slope / kAtBorder);
}

}  // namespace

double EyeOpening::upper(double ax) const {
    return slit(ax) + upper_height * lid_profile(s(ax), upper_peak);
}
double EyeOpening::lower(double ax) const {
    return slit(ax) - lower_height * lid_profile(s(ax), lower_peak);
}

FaceShape::FaceShape(const FaceParams& params)
    : p_(params), neck_lean_tan_(std::tan(params.neck_lean_deg * kPi / 180.0)) {
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
    double f = part_field(p, p_.head_parts.front());
    for (std::size_t i = 1; i < p_.head_parts.size(); ++i)
        f = smooth_min(f, part_field(p, p_.head_parts[i]), p_.head_parts[i].blend);
    // The neck: an elliptic cylinder leaning forward (its axis' z grows with
    // y), capped inside the head.
    const double axis_z = p_.neck_centre_z + (p.y - p_.neck_top_y) * neck_lean_tan_;
    const double qx = p.x / p_.neck_radii[0], qz = (p.z - axis_z) / p_.neck_radii[1];
    const double cyl = (std::sqrt(qx * qx + qz * qz) - 1.0) * std::min(p_.neck_radii[0], p_.neck_radii[1]);
    const double neck = std::max(cyl, p.y - p_.neck_top_y);
    f = smooth_min(f, neck, p_.neck_blend);
    return smooth_min(f, ellipsoid_field(p, p_.shoulders), p_.shoulders_blend);
}

glm::dvec3 FaceShape::field_normal(glm::dvec3 p) const {
    const double h = 0.05;
    const glm::dvec3 g{field({p.x + h, p.y, p.z}) - field({p.x - h, p.y, p.z}),
               field({p.x, p.y + h, p.z}) - field({p.x, p.y - h, p.z}),
               field({p.x, p.y, p.z + h}) - field({p.x, p.y, p.z - h})};
    return normalised(g);
}

double FaceShape::cast(glm::dvec3 origin, glm::dvec3 dir) const {
    // Sphere tracing: the field is (nearly) 1-Lipschitz, so from a point
    // inside at field value f the surface is at least |f| away; 0.8 of that
    // leaves room for the neck's lean. Then bisection of the last step.
    constexpr double kMinStep = 0.3, kMax = 600.0;
    double lo = 0.0, hi = 0.0;
    for (;;) {
        const double f = field(origin + dir * hi);
        if (f >= 0.0 || hi >= kMax) break;
        lo = hi;
        hi += std::max(-0.8 * f, kMinStep);
    }
    for (int i = 0; i < 20; ++i) {
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
    // The lips thin out into the corners, where they tuck in under the
    // modiolus: with the square root of (1 - t^2) they kept most of their
    // fullness to the corner and ended there as a rounded rim (puffy lips
    // laid on the face, blind review, session 8).
    const double corner_fade = inside * std::pow(std::max(1.0 - (ax / hw) * (ax / hw), 0.0), 0.85);
    // The lips roll inwards where they meet: a crease as deep as the mouth
    // line, continuing a little past the corners (the commissures).
    const double along = ax < hw ? 1.0 - 0.4 * std::pow(ax / hw, 4) : 0.6 * std::exp(-std::pow((ax - hw) / 2.5, 2));
    double h = -p_.lip_crease_depth * std::exp(-std::pow((y - ys) / p_.lip_crease_width, 2)) * along;
    if (corner_fade <= 0) return h;
    if (y >= ys) {
        const double height = std::max(upper_border(x) - ys, 0.5);
        const double t = (y - ys) / height;
        h += p_.upper_lip_protrusion * corner_fade * lip_bulge(t, 0.55, std::max(0.0, y - ys - height), height);
    } else {
        const double height = std::max(ys - lower_border(x), 0.5);
        const double t = (ys - y) / height;
        const double below = std::max(0.0, ys - y - height);
        h += p_.lower_lip_protrusion * corner_fade * lip_bulge(t, 0.45, below, height);
        // Under the lower lip the skin tucks in before the chin (the
        // mentolabial sulcus' upper wall), so the lip's underside faces down
        // and holds a shadow: a fall that eased straight into the chin read
        // as a lip roll stuck on a flat face. Zero slope at the border.
        const double b = below / p_.lower_lip_tuck_at;
        h -= p_.lower_lip_tuck * corner_fade * b * b * std::exp(2.0 * (1.0 - b));
    }
    return h;
}

double FaceShape::relief(double x, double y) const {
    double h = 0.0;
    for (const Bump& b : p_.bumps) h += b.height * bumps_value(b, x, y);
    for (const Bump& b : p_.nostrils) h += b.height * nostrils_value(b, x, y);
    for (const Ridge& r : p_.ridges) {
        h += ridge_value(r, x, y, 1.0);
        if (r.mirror) h += ridge_value(r, x, y, -1.0);
    }
    return h + lip_relief(x, y);
}

double FaceShape::nostril_amount(double x, double y) const {
    double a = 0.0;
    for (const Bump& b : p_.nostrils) a += nostrils_value(b, x, y);
    return std::min(a, 1.0);
}

double FaceShape::lid_z(double x, double y, double margin_distance) const {
    const double cx = x >= 0 ? p_.eye_centre[0] : -p_.eye_centre[0];
    const double dx = x - cx, dy = y - p_.eye_centre[1];
    const double r = std::sqrt(dx * dx + dy * dy);
    // The lid hugs the eyeball over its tarsus and then leaves it for the
    // orbital rim: its skin stands lid_rise * d^2 further off the globe d mm
    // from the margin. On the globe's shell alone the lower lid was a tube
    // over a trench, below it a wall up to the cheek (a swim-goggle ring,
    // blind review round 15).
    const double md = std::max(margin_distance, 0.0);
    const double radius = p_.eye_radius + p_.lid_clearance + p_.lid_thickness * (1.0 - std::exp(-md / 0.8)) +
                          p_.lid_rise * md * md;
    if (r < radius) return p_.eye_centre[2] + std::sqrt(radius * radius - r * r);
    // Beyond the shell's outline (past the corners) it sinks gently: at 2 mm
    // per mm, blended with the face, it dug a pit beside the nose at the
    // inner corner and a notch past the outer one.
    constexpr double kSinkPastTheShell = 0.5;
    return p_.eye_centre[2] - (r - radius) * kSinkPastTheShell;
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

namespace {

// The ear's half breadth at a (-1 lobe .. 1 top) as a fraction of the
// widest: the upper ear is broad, the lobe narrower.
double ear_width(double a) { return 0.62 + 0.38 * glm::smoothstep(-1.0, 0.35, a); }

// Distance from (a, s) to a polyline of ear coordinates, in ear units.
double ear_curve_distance(double a, double s, std::initializer_list<glm::dvec2> pts) {
    double best = 1e9;
    const glm::dvec2 p{a, s};
    const glm::dvec2* prev = nullptr;
    for (const glm::dvec2& q : pts) {
        if (prev) {
            const glm::dvec2 e = q - *prev;
            const double t = clamp01(glm::dot(p - *prev, e) / std::max(glm::dot(e, e), 1e-12));
            best = std::min(best, glm::length(p - (*prev + e * t)));
        }
        prev = &q;
    }
    return best;
}

double gauss(double d, double w) { return std::exp(-(d / w) * (d / w)); }

}  // namespace

glm::dvec2 FaceShape::ear_point(double a, double s) const {
    const double t = p_.ear_tilt_deg * kPi / 180.0;
    const double u = a * p_.ear_radii_yz[0], v = s * p_.ear_radii_yz[1] * ear_width(a);
    // u runs up the tilted axis (up and back), v across it (forward).
    return {p_.ear_centre_yz[0] + u * std::cos(t) + v * std::sin(t),
            p_.ear_centre_yz[1] - u * std::sin(t) + v * std::cos(t)};
}

// The auricle as a height field over the side of the head: the helix rim
// round the top and back, the scapha inside it, the Y of the antihelix and
// its crura, the concha bowl sunk nearly to the scalp, the tragus in front
// of it, the antitragus and a fleshy lobe without a rim. The ear is attached
// along its front edge and stands off the head towards its free back rim
// (the ear's plane about 20-30 degrees off the scalp, FIDELITY.md "Ear").
double FaceShape::ear_relief(double y, double z) const {
    const double t = p_.ear_tilt_deg * kPi / 180.0;
    const double dy = y - p_.ear_centre_yz[0], dz = z - p_.ear_centre_yz[1];
    const double L = p_.ear_radii_yz[0];
    const double a = (dy * std::cos(t) - dz * std::sin(t)) / L;
    if (a < -1.1 || a > 1.1) return 0.0;
    const double W = p_.ear_radii_yz[1] * ear_width(std::clamp(a, -1.0, 1.0));
    const double s = (dy * std::sin(t) + dz * std::cos(t)) / W;
    const double rho = std::sqrt(a * a + s * s);
    if (rho >= 1.0) return 0.0;
    const double H = p_.ear_height;
    const double mm = std::min(L, W);  // ear units to mm near the rim
    const double rim_d = (1.0 - rho) * mm;  // mm in from the outline
    // The shell: low where it joins the head, high at the free rim; the lobe
    // hangs flatter.
    const double lobe = glm::smoothstep(-0.45, -0.8, a);
    double h = H * (0.22 + 0.78 * glm::smoothstep(0.85, -0.85, s)) * (1.0 - 0.45 * lobe);
    // The helix: from the front top, round the top and down the back; not
    // along the front below its root, nor on the lobe.
    const double helix = (1.0 - glm::smoothstep(0.25, 0.7, s) * glm::smoothstep(0.45, 0.1, a)) * (1.0 - lobe);
    // Rim and groove are a few grid steps wide (the skin grid is about
    // 1.4 mm here): a 1.4 mm rim sampled on it saw-toothed along the ear.
    h += helix * (0.27 * H * gauss(rim_d - 2.4, 2.2) - 0.24 * H * gauss(rim_d - 6.2, 2.4));
    // Antihelix and its two crura, an inner ridge parallel to the rim.
    const double anti = ear_curve_distance(a, s, {{-0.55, -0.3}, {-0.1, -0.48}, {0.32, -0.42}, {0.68, 0.05}});
    const double crus = ear_curve_distance(a, s, {{0.32, -0.42}, {0.3, 0.35}});
    h += 0.27 * H * gauss(std::min(anti, 1.1 * crus) * mm, 2.8);
    // Concha: a deep bowl in front of the antihelix, behind the tragus.
    const double cu = (a + 0.08) / 0.36, cv = (s - 0.2) / 0.42;
    const double bowl = std::max(0.0, 1.0 - cu * cu - cv * cv);
    h = mix(h, 0.06 * H, glm::smoothstep(0.0, 0.6, bowl));
    // Triangular fossa between the crura: shallow.
    const double fa = (a - 0.55) / 0.18, fs = (s - 0.05) / 0.22;
    h -= 0.1 * H * std::max(0.0, 1.0 - fa * fa - fs * fs);
    // The lobe: soft and fleshy, fuller in its middle.
    h += 0.12 * H * lobe * gauss(std::hypot((a + 0.82) * L, (s + 0.1) * W), 6.0);
    // Tragus over the concha's front, antitragus behind the notch below it.
    h += 0.3 * H * gauss(std::hypot((a + 0.2) * L, (s - 0.78) * W), 3.5);
    h += 0.1 * H * gauss(std::hypot((a + 0.52) * L, (s + 0.05) * W), 3.0);
    // The outline: a steep edge at the free rim, a gentler one where the
    // front joins the face.
    const double edge = 1.0 - glm::smoothstep(s > 0.6 ? 0.7 : 0.9, 1.0, rho);
    return std::max(h * edge, 0.0);
}

glm::dvec2 FaceShape::ear_rim_pull(double y, double z) const {
    // Grid points near the ear's outline are drawn onto it (the band
    // rho 1 +- kBand is mapped onto itself by d -> d|d|, flat at the
    // outline), so the wall where the rim drops to the scalp runs along
    // the outline's smooth curve instead of stepping from one grid cell to
    // the next: a saw-tooth rim at any grid spacing.
    constexpr double kBand = 0.16;
    const double t = p_.ear_tilt_deg * kPi / 180.0;
    const double dy = y - p_.ear_centre_yz[0], dz = z - p_.ear_centre_yz[1];
    const double a = (dy * std::cos(t) - dz * std::sin(t)) / p_.ear_radii_yz[0];
    if (a < -1.3 || a > 1.3) return {0.0, 0.0};
    const double s = (dy * std::sin(t) + dz * std::cos(t)) / (p_.ear_radii_yz[1] * ear_width(std::clamp(a, -1.0, 1.0)));
    const double rho = std::sqrt(a * a + s * s);
    const double d = (rho - 1.0) / kBand;
    if (std::abs(d) >= 1.0 || rho <= 0.0) return {0.0, 0.0};
    const double k = (1.0 + kBand * d * std::abs(d)) / rho;
    return ear_point(a * k, s * k) - glm::dvec2{y, z};
}

double FaceShape::hairline(glm::dvec3 q) const {
    const double ax = std::abs(q.x);
    const double tx = std::min(ax / p_.hairline_temple[0], 1.0);
    // The temples recede (the hairline's M): a rise beside the centre's
    // rounded front, before the line comes down to the temple point.
    const glm::dvec3& rc = p_.hair_recession;
    const double recession = rc[1] * std::exp(-((ax - rc[0]) / rc[2]) * ((ax - rc[0]) / rc[2]));
    const double ear_top = p_.ear_centre_yz[0] + p_.ear_radii_yz[0] + 5.0;
    // Past the temple point the line runs back and down the side of the
    // head to the sideburn's top (over temple_depth mm of z), instead of
    // dropping straight down the temple as a helmet's rim.
    const double temple_side =
        mix(ear_top, p_.hairline_temple[1], glm::smoothstep(p_.sideburn_z, p_.sideburn_z + p_.temple_depth, q.z));
    const double front_drop = mix(p_.hairline_y, p_.hairline_temple[1], tx * tx) + recession -
                              std::max(ax - p_.hairline_temple[0], 0.0) * 2.5;
    const double k = 4.0;  // a smooth maximum: no corner where the two meet
    const double front_line = 0.5 * (front_drop + temple_side + std::sqrt((front_drop - temple_side) * (front_drop - temple_side) + k * k));
    const double ear_front = p_.ear_centre_yz[1] + p_.ear_radii_yz[1] + 3.0;
    const double ear_back = p_.ear_centre_yz[1] - p_.ear_radii_yz[1] - 3.0;
    double side_line;
    if (q.z > ear_front) side_line = mix(ear_top, p_.sideburn_bottom_y, glm::smoothstep(ear_front, ear_front + 5.0, q.z));
    else if (q.z > ear_back) side_line = ear_top;
    else side_line = mix(ear_top, p_.hair_back_bottom_y, glm::smoothstep(ear_back, ear_back - 35.0, q.z));
    const double line = mix(side_line, front_line, glm::smoothstep(p_.sideburn_z - 6.0, p_.sideburn_z + 6.0, q.z));
    // The line wanders at two scales (about 9 and 3.5 mm along it), in x
    // and z so it does on the front and the sides alike, and with the
    // sign of x so the two sides differ: no drawn curve, no mirror image.
    const double wander = 0.65 * noise(q.x / 9.0 + 40.0, q.z / 9.0, 1.0) + 0.35 * noise(q.x / 3.5, q.z / 3.5 + 40.0, 2.0);
    return line + p_.hairline_wander * 2.0 * (wander - 0.5);
}

double FaceShape::hair_height(glm::dvec3 q) const {
    // The line's slope over the head (across x and z, at about 3 mm so the
    // wander's finest wiggles do not decide it).
    constexpr double h = 1.5;
    const double lx = (hairline(q + glm::dvec3{h, 0.0, 0.0}) - hairline(q - glm::dvec3{h, 0.0, 0.0})) / (2.0 * h);
    const double lz = (hairline(q + glm::dvec3{0.0, 0.0, h}) - hairline(q - glm::dvec3{0.0, 0.0, h})) / (2.0 * h);
    const double raw = q.y - hairline(q);
    const double along_head = raw / std::sqrt(1.0 + lx * lx + lz * lz);
    // Far above the line its steepness says nothing: where the side's line
    // hands over to the front's (sideburn_z) it rises 70 mm in 12 mm of z,
    // and divided by that slope the crown read as near the hairline there,
    // a groove in the volume from the crown to the temple (a helmet's
    // seam). So the plain height, less a band, takes over with distance.
    constexpr double kBand = 12.0;
    const double far = raw - kBand;
    const double k = 2.0;  // smooth maximum and minimum: no crease where they meet
    const double height = 0.5 * (along_head + far + std::sqrt((along_head - far) * (along_head - far) + k * k));
    // Below the sideburn's bottom the line's steepness misleads the other
    // way: where it hands over to the front's (the band of sideburn_z) it
    // is as steep at the lobe's height as at the sideburn's, and the skin
    // down to the jaw read as a few mm from the hairline (a strip of fine
    // hairs down the cheek). No hair grows below the line's lowest point,
    // so a point below that is at least that far from it.
    const double ear_back = p_.ear_centre_yz[1] - p_.ear_radii_yz[1] - 3.0;
    const double lowest = mix(p_.hair_back_bottom_y, p_.sideburn_bottom_y, glm::smoothstep(ear_back - 35.0, ear_back, q.z)) -
                          p_.hairline_wander;
    const double below_lowest = q.y - lowest;
    return 0.5 * (height + below_lowest - std::sqrt((height - below_lowest) * (height - below_lowest) + k * k));
}

FaceShape::HairFlow FaceShape::hair_flow(glm::dvec3 q) const {
    // Strand coordinates round the crown. The azimuth's wrap (+-pi) lies
    // behind and below the crown, on the nape, where no view of the face
    // sees the seam it makes in the strands.
    const glm::dvec3 rel = q - p_.hair_crown;
    const double along = glm::length(rel);
    const glm::dvec3 axis = glm::normalize(p_.hair_crown);
    const glm::dvec3 e1 = -glm::normalize(glm::cross(axis, glm::dvec3{1.0, 0.0, 0.0}));
    const glm::dvec3 e2 = glm::cross(axis, e1);
    // The whorl's spiral: strands turn round the crown with distance, most
    // over the front (the hair sweeps across the forehead instead of
    // falling straight onto it as a fringe) and not at all at the nape,
    // so the azimuth's wrap stays there.
    const double straight = std::atan2(glm::dot(rel, e2), glm::dot(rel, e1));
    const double facing = std::cos(0.5 * straight);
    const double azimuth = straight + p_.hair_swirl * (along / 100.0) * facing * facing;
    // Across in mm at a typical distance; fanning out with distance is the whorl.
    return {azimuth, azimuth * 70.0, along};
}

double FaceShape::hair_tuft(glm::dvec3 q) const {
    const glm::dvec2 size = p_.hair_volume.tuft_size;
    const HairFlow f = hair_flow(q);
    // Lanes across the flow whose course sways as they run, so the partings
    // are not parallel grooves.
    const double sway = 0.9 * size.x * (noise(f.across / (2.5 * size.x), f.along / 30.0, 31.0) - 0.5);
    const double u = (f.across + sway) / size.x;
    const int i = static_cast<int>(std::floor(u));
    // Each lane's tufts start where its neighbours' are half grown: shingles.
    const double v = f.along / size.y + hash(i, 3, 71);
    const int j = static_cast<int>(std::floor(v));
    const double fu = u - i, fv = v - j;
    // Across: round-topped, down to the parting at the lane's edges. Along:
    // a tuft swells from its root and thins to its tip over the next one's
    // root, gently enough that the head's 5 mm rows over the crown
    // (face.json resolution) follow it without facets; both profiles are 0
    // where the next lane or tuft begins, so the tufts' own strengths join
    // without a step.
    const double across = std::pow(std::sin(kPi * fu), 0.7);
    const double along = glm::smoothstep(0.0, 0.55, fv) * glm::smoothstep(1.0, 0.6, fv);
    return across * (0.35 + 0.65 * along * (0.55 + 0.45 * hash(i, j, 73)));
}

double FaceShape::hair_thickness(glm::dvec3 base, glm::dvec3 n) const {
    const FaceParams::HairVolume& v = p_.hair_volume;
    const double above = hair_height(base);
    if (above <= 0.0) return 0.0;
    // A short haircut: fullest over the crown, close on the sides and
    // thinning down the nape; it rises from nothing at the hairline over
    // `fade` mm, so no ledge stands there.
    const double side = std::abs(n.x);
    double t = mix(v.top, v.sides, glm::smoothstep(0.35, 0.9, side));
    t = mix(v.nape, t, glm::smoothstep(-60.0, 20.0, base.y));
    // Broad lumps: the volume swells and dips by +-lumps.
    const glm::dvec3 l = base / v.lump_size;
    t *= 1.0 + v.lumps * (2.0 * (0.7 * noise(l.x, l.y, l.z + 60.0) + 0.3 * noise(2.3 * l.x, 2.3 * l.y, 2.3 * l.z)) - 1.0);
    // Clumps: crests stand up and partings sink between them, so the
    // silhouette is broken by tufts and not a helmet's smooth shell.
    t *= 1.0 + v.tufts * (2.0 * hair_tuft(base) - 1.0);
    return t * glm::smoothstep(0.0, v.fade, above);
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
        const glm::dvec2 pull = ear_rim_pull(base.y, base.z) * side;
        p.y += pull.x;
        p.z += pull.y;
    }
    const double hair = hair_thickness(base, n);
    if (hair > 0.0) p = p + n * hair;
    const double cloth = shirt_thickness(base);
    if (cloth > 0.0) p = p + n * cloth;
    return p + asymmetry(base);
}

FaceShape::ShirtPlace FaceShape::shirt_place(glm::dvec3 q) const {
    const FaceParams::Shirt& sh = p_.shirt;
    // Azimuth about the neck's leaning axis (0 in front, pi at the back),
    // on the neck's elliptic section so it is even round the neck.
    const double axis_z = p_.neck_centre_z + (q.y - p_.neck_top_y) * neck_lean_tan_;
    const double dz = q.z - axis_z;
    const double ax = std::abs(q.x);
    const double dip = sh.dip_half_angle_deg * kPi / 180.0;
    // The neckline's height at azimuth a: a flat-bottomed dip in front
    // rising to the sides, then on up behind them at once (over the
    // trapezius' slope, which stands above the side's height just behind
    // the neck: a slower rise left a rim of skin on the shoulders' outline).
    auto neckline = [&](double a) {
        if (a < 0.5 * kPi) return mix(sh.neckline_front, sh.neckline_side, glm::smoothstep(0.0, dip, a));
        return mix(sh.neckline_side, sh.neckline_back, std::sin(a - 0.5 * kPi));
    };
    const double a = std::atan2(ax / p_.neck_radii[0], dz / p_.neck_radii[1]);
    const double r = std::max(std::hypot(ax, dz), 30.0);  // mm per radian along the neck's surface
    constexpr double kDa = 0.01;
    const double slope = (neckline(std::min(a + kDa, kPi)) - neckline(std::max(a - kDa, 0.0))) / (2.0 * kDa * r);
    return {(neckline(a) - q.y) / std::sqrt(1.0 + slope * slope), (q.x < 0 ? -1.0 : 1.0) * r * a};
}

double FaceShape::shirt_thickness(glm::dvec3 base) const {
    const FaceParams::Shirt& sh = p_.shirt;
    if (base.y > std::max({sh.neckline_front, sh.neckline_side, sh.neckline_back}) + 2.0) return 0.0;
    const double below = shirt_place(base).below;
    if (below <= 0.0) return 0.0;
    // The collar's folded band stands off the neck by its thickness, its
    // top edge rounded over about its thickness; the body's single layer
    // is thinner.
    const double band = 1.0 - glm::smoothstep(sh.collar_mm - 2.0, sh.collar_mm + 2.0, below);
    return glm::smoothstep(0.0, 1.2 * sh.thickness_mm[0], below) * mix(sh.thickness_mm[1], sh.thickness_mm[0], band);
}

// No face is its mirror image (FIDELITY.md, "Perfect, symmetric"): the
// lower face and chin deviate a little to the face's left and the nose tip
// the other way, the right cheek is a little fuller, the left brow and ear
// sit a little higher. Each term is a broad smooth field (no fold), and
// none reaches the eyelids, which must stay on the eyeballs.
glm::dvec3 FaceShape::asymmetry(glm::dvec3 p) const {
    const double a = p_.asymmetry_mm;
    if (a == 0.0) return glm::dvec3{0.0};
    auto bell = [](double d, double w) { return std::exp(-0.5 * (d / w) * (d / w)); };
    const double front = glm::smoothstep(10.0, 50.0, p.z);
    glm::dvec3 o{0.0};
    // Lower face: the chin and mouth shift sideways, fading in below the
    // nose and out down the neck.
    o.x += a * glm::smoothstep(-35.0, -80.0, p.y) * glm::smoothstep(-150.0, -112.0, p.y) * front;
    // The nose tip deviates the other way.
    o.x -= 0.6 * a * bell(p.x, 10.0) * bell(p.y + 36.0, 9.0) * front;
    // The right cheek is fuller.
    o.z += 0.8 * a * bell(p.x + 42.0, 14.0) * bell(p.y + 28.0, 14.0) * glm::smoothstep(-8.0, -16.0, p.y) * front;
    // The left brow and forehead sit higher, fading out above the lid crease.
    o.y += 0.8 * a * bell(p.x - 30.0, 16.0) * bell(p.y - 24.0, 14.0) * glm::smoothstep(9.0, 15.0, p.y) * front;
    // The left ear sits higher and stands off a little further.
    const double ear = bell(p.y - p_.ear_centre_yz[0], 30.0) * bell(p.z - p_.ear_centre_yz[1], 30.0) *
                       glm::smoothstep(45.0, 65.0, p.x);
    o.y += 1.5 * a * ear;
    o.x += 1.2 * a * ear;
    return o;
}

}  // namespace emoface::expression::detail
