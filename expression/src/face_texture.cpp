#include "face_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/common.hpp>
#include <glm/trigonometric.hpp>
#include <glm/geometric.hpp>

#include "emoface/common/parallel.h"
#include "eye_texture.h"

namespace emoface::expression::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

struct Rgb {
    double r = 0, g = 0, b = 0;
};
Rgb operator*(Rgb c, double s) { return {c.r * s, c.g * s, c.b * s}; }
Rgb operator*(Rgb a, Rgb b) { return {a.r * b.r, a.g * b.g, a.b * b.b}; }
Rgb blend(Rgb a, Rgb b, double t) { return {mix(a.r, b.r, t), mix(a.g, b.g, t), mix(a.b, b.b, t)}; }
Rgb from255(const glm::dvec3& c) { return {c[0] / 255.0, c[1] / 255.0, c[2] / 255.0}; }

double fbm(double x, double y, double z) {
    return 0.5 * noise(x, y, z) + 0.3 * noise(2.1 * x, 2.1 * y, 2.1 * z) + 0.2 * noise(4.3 * x, 4.3 * y, 4.3 * z);
}

struct Texel {
    Rgb colour;
    double gloss = 1.0;  // roughness scale (the base map's alpha)
};

// One brow hair: a stroke from its root along `dir` (unit, frontal x/y mm).
// `side` is the unit normal of `dir` the hair curves towards, `bend` how far
// its tip lies off the straight line (mm): the centre line is root +
// t length dir + t^2 bend side, t 0 .. 1. The forelock's strands are
// strokes of the same kind.
struct BrowHair {
    glm::dvec2 root, dir, side;
    double length, width, shade, bend;
};

// How much of the skin at p (frontal x/y mm) a hair stroke covers, and
// where along it (*t: 0 root .. 1 tip). It tapers to the tip; its edge is
// softened over about a texel so thin hairs stay continuous strokes in the
// texture.
double stroke_cover(const BrowHair& h, glm::dvec2 p, double* t) {
    const glm::dvec2 rel = p - h.root;
    const double along = glm::dot(rel, h.dir) / h.length;
    if (along < -0.05 || along > 1.05) return 0.0;
    const double across = std::abs(glm::dot(rel, h.side) - h.bend * along * along);
    *t = std::clamp(along, 0.0, 1.0);
    const double half = 0.5 * h.width * (1.0 - 0.55 * *t);
    return (1.0 - glm::smoothstep(half, half + 0.22, across)) * glm::smoothstep(-0.05, 0.05, along) *
           (1.0 - glm::smoothstep(0.92, 1.05, along));
}

// Hair strokes laid over one texel, one at a time: each covers part of the
// skin and lets some through (a hair is thinner than a texel), and tints
// what it covers with its shade of the hair's tone.
struct StrokeMix {
    double clear = 1.0;  // the share of skin no stroke covers
    Rgb sum{};
    double weight = 0.0;

    void add(const Rgb& tone, double cover, double opacity, double shade) {
        clear *= 1.0 - opacity * cover;
        sum = {sum.r + tone.r * shade * cover, sum.g + tone.g * shade * cover, sum.b + tone.b * shade * cover};
        weight += cover;
    }
    // How much of the texel hair covers (0: none, *colour untouched) and
    // the covering hairs' mean colour.
    double result(Rgb* colour) const {
        if (weight <= 0.0) return 0.0;
        *colour = sum * (1.0 / weight);
        return 1.0 - clear;
    }
};

class Painter {
public:
    explicit Painter(const FaceShape& shape);

    Texel skin(glm::dvec3 q) const;
    Rgb tile(double u, double v) const;

private:
    // Where (x, y) lies against a brow's centre line: t 0 (inner) .. 1
    // (outer), signed distance above the line (mm), and the line's outward
    // unit tangent there.
    struct BrowPlace {
        double t, above, distance, half;
        glm::dvec2 tangent;
    };
    BrowPlace brow_place(double x, double y) const;
    double brow_density(const BrowPlace& b) const;
    // Brow hairs' coverage at (x, y) and their colour.
    double brow_hairs(double x, double y, Rgb* colour) const;
    // Hair cover 0 (skin) .. 1 and its colour; *roots: how much the roots'
    // grey shows under the skin (the scalp under thinning hair).
    double hair(glm::dvec3 q, Rgb* colour, double* roots) const;
    // The forelock's stray strands at frontal (x, y): cover and colour.
    double forelock(double x, double y, Rgb* colour) const;
    // The T-shirt over the shoulders and chest: the colour at q given the
    // skin's colour c there (cloth below the neckline, the collar's shade
    // on the neck above it); *gloss becomes cloth's where it covers.
    Rgb shirt(glm::dvec3 q, Rgb c, double* gloss) const;
    void build_forelock();
    // The painted lash line at a point of the lids: how much of the lashes'
    // colour up the upper lid from its margin, on the upper margin's strip,
    // and the lower lid's roots. ax: |x|; s: 0 inner .. 1 outer corner; dy_up,
    // dy_lo: mm above the upper margin and below the lower one; along: the
    // fade past the corners. Painted whatever the depth: from the front the
    // margins' rounded edges, not the lids' front skin, meet the slit.
    struct LashLine {
        double upper = 0.0, on_margin = 0.0, lower = 0.0;
    };
    LashLine lash_line(double ax, double s, double dy_up, double dy_lo, double along) const;

    const FaceShape& s_;
    const FaceParams& p_;
    std::vector<BrowHair> hairs_;
    // hairs_ bucketed on a grid of kBucket mm over the brows' box.
    static constexpr double kBucket = 2.0;
    glm::dvec2 grid_min_{0.0};
    int grid_w_ = 0, grid_h_ = 0;
    std::vector<std::vector<int>> grid_;
    std::vector<BrowHair> locks_;
    glm::dvec2 locks_min_{0.0}, locks_max_{0.0};  // their frontal box (mm)
};

Painter::BrowPlace Painter::brow_place(double x, double y) const {
    const double sx = x >= 0 ? 1.0 : -1.0;
    const glm::dvec2 a{p_.brow_points[0][0] * sx, p_.brow_points[0][1]};
    const glm::dvec2 m{p_.brow_points[1][0] * sx, p_.brow_points[1][1]};
    const glm::dvec2 b{p_.brow_points[2][0] * sx, p_.brow_points[2][1]};
    // Quadratic curve through a, m (at t = 0.5) and b.
    const glm::dvec2 c = 2.0 * m - 0.5 * (a + b);
    auto at = [&](double t) { return (1 - t) * (1 - t) * a + 2 * t * (1 - t) * c + t * t * b; };
    double best = 1e9, best_t = 0;
    constexpr int kSamples = 48;
    for (int k = 0; k <= kSamples; ++k) {
        const double t = static_cast<double>(k) / kSamples;
        const double d = glm::length(glm::dvec2{x, y} - at(t));
        if (d < best) {
            best = d;
            best_t = t;
        }
    }
    BrowPlace p;
    p.t = best_t;
    p.distance = best;
    p.above = y - at(best_t)[1];
    const glm::dvec2 d = 2.0 * (1 - best_t) * (c - a) + 2.0 * best_t * (b - c);
    p.tangent = glm::length(d) > 1e-9 ? glm::normalize(d) : glm::dvec2{sx, 0.0};
    const double th = best_t < 0.5 ? mix(p_.brow_thickness[0], p_.brow_thickness[1], best_t * 2)
                                   : mix(p_.brow_thickness[1], p_.brow_thickness[2], best_t * 2 - 1);
    p.half = 0.5 * th;
    return p;
}

// How densely hairs grow: 1 in the brow's body, thinning at its edges and
// towards the inner end, with gaps.
double Painter::brow_density(const BrowPlace& b) const {
    const double q = b.distance / b.half;
    if (q > 1.4 || (b.t <= 0.0 && b.distance > 0.3 * b.half)) return 0.0;
    // Feathered edges: fewer hairs towards the brow's upper and lower rims,
    // so its outline is the hairs' own and not a drawn shape.
    double d = 1.0 - glm::smoothstep(0.35, 1.3, q);
    d *= 0.55 + 0.45 * glm::smoothstep(0.0, 0.3, b.t);  // sparser at the inner end
    d *= 1.0 - 0.7 * glm::smoothstep(0.6, 1.0, b.t);   // and thinning to the tail
    return d;
}

Painter::Painter(const FaceShape& shape) : s_(shape), p_(shape.params()) {
    const double step = p_.brow_hair_spacing;
    const double x0 = p_.brow_points[0][0] - 6.0, x1 = p_.brow_points[2][0] + 4.0;
    double y0 = 1e9, y1 = -1e9;
    for (const auto& bp : p_.brow_points) {
        y0 = std::min(y0, bp[1]);
        y1 = std::max(y1, bp[1]);
    }
    y0 -= 0.6 * p_.brow_thickness[0] + 2.0;
    y1 += 0.6 * p_.brow_thickness[0] + 2.0;
    const double medial = glm::radians(p_.brow_medial_angle), lateral = glm::radians(p_.brow_lateral_angle);
    for (int side = 0; side < 2; ++side) {
        const double sx = side == 0 ? 1.0 : -1.0;
        int j = 0;
        for (double y = y0; y < y1; y += step, ++j) {
            int i = 0;
            for (double x = x0; x < x1; x += step, ++i) {
                // The two sides get different hairs (no mirrored copy).
                const double jx = x + step * (hash(i, j, 31 + side) - 0.5), jy = y + step * (hash(i, j, 37 + side) - 0.5);
                const BrowPlace b = brow_place(sx * jx, jy);
                if (hash(i, j, 41 + side) > brow_density(b)) continue;
                // Direction: the medial hairs grow up (and a little outward),
                // the lateral ones outward along the line, converging on it.
                const glm::dvec2 along = b.tangent;
                const glm::dvec2 up{-along[1] * sx, along[0] * sx};  // the line's normal, pointing up
                const double side_tilt = -lateral * std::clamp(b.above / b.half, -1.0, 1.0);
                const double lateral_angle = side_tilt + 0.25 * (hash(i, j, 43 + side) - 0.5);
                const double w = glm::smoothstep(0.08, 0.32, b.t);
                // The medial hairs fan: the lowest stand upright, those
                // higher up lean outward, each a little its own way.
                const double fan = 0.35 * std::clamp(b.above / b.half, -1.0, 1.0);
                const double angle = mix(medial - fan + 0.45 * (hash(i, j, 47 + side) - 0.5), lateral_angle, w);
                glm::dvec2 dir = std::cos(angle) * along + std::sin(angle) * up;
                dir = glm::normalize(dir);
                BrowHair h;
                h.dir = dir;
                h.length = mix(p_.brow_hair_length[0], p_.brow_hair_length[1], w) * (0.75 + 0.5 * hash(i, j, 53 + side));
                // Hairs curve as they grow: the medial ones outward, the
                // lateral ones towards the line (those above it down, those
                // below up), most at the tail, where they follow the arch down.
                glm::dvec2 normal{-dir[1], dir[0]};
                const glm::dvec2 towards = w < 0.5 ? along : (b.above > 0.0 || b.t > 0.8 ? -up : up);
                if (glm::dot(normal, towards) < 0.0) normal = -normal;
                h.side = normal;
                h.bend = p_.brow_hair_bend * (0.4 + 0.6 * hash(i, j, 67 + side)) * (0.5 + 0.5 * w) * h.length /
                         p_.brow_hair_length[1];
                // Roots sit back along the hair, so the stroke covers where
                // it was drawn; a hair whose tip would leave the brow is cut
                // short (the medial hairs grew down past the brow's lower
                // edge, a fringe of strokes under it).
                h.root = glm::dvec2{sx * jx, jy} - 0.3 * h.length * dir;
                const BrowPlace rb = brow_place(h.root[0], h.root[1]);
                if (rb.distance > 1.2 * rb.half || (rb.t <= 0.0 && rb.distance > 0.3 * rb.half)) continue;
                for (int k = 0; k < 4; ++k) {
                    const glm::dvec2 tip = h.root + h.length * dir + h.bend * h.side;
                    const BrowPlace tb = brow_place(tip[0], tip[1]);
                    if (tb.distance < 1.15 * tb.half && tb.t > 0.0) break;
                    h.length *= 0.75;
                    h.bend *= 0.75;
                }
                h.width = p_.brow_hair_width * (0.8 + 0.4 * hash(i, j, 59 + side));
                // Tones differ hair to hair: most a little darker or lighter
                // than the brows' colour, a few much lighter (fair hairs
                // catch the light) or darker.
                const double tone = hash(i, j, 61 + side);
                h.shade = mix(p_.brow_hair_tone[0], p_.brow_hair_tone[1], tone * tone * (3.0 - 2.0 * tone));
                hairs_.push_back(h);
            }
        }
    }
    grid_min_ = {-x1 - 10.0, y0 - 10.0};
    grid_w_ = static_cast<int>(std::ceil((2.0 * x1 + 20.0) / kBucket));
    grid_h_ = static_cast<int>(std::ceil((y1 - y0 + 20.0) / kBucket));
    grid_.assign(static_cast<std::size_t>(grid_w_) * grid_h_, {});
    for (int k = 0; k < static_cast<int>(hairs_.size()); ++k) {
        const BrowHair& h = hairs_[static_cast<std::size_t>(k)];
        const glm::dvec2 tip = h.root + h.length * h.dir + h.bend * h.side;
        const double r = h.width + 0.5 + std::abs(h.bend);
        const int gx0 = static_cast<int>(std::floor((std::min(h.root[0], tip[0]) - r - grid_min_[0]) / kBucket));
        const int gx1 = static_cast<int>(std::floor((std::max(h.root[0], tip[0]) + r - grid_min_[0]) / kBucket));
        const int gy0 = static_cast<int>(std::floor((std::min(h.root[1], tip[1]) - r - grid_min_[1]) / kBucket));
        const int gy1 = static_cast<int>(std::floor((std::max(h.root[1], tip[1]) + r - grid_min_[1]) / kBucket));
        for (int gy = std::max(gy0, 0); gy <= std::min(gy1, grid_h_ - 1); ++gy)
            for (int gx = std::max(gx0, 0); gx <= std::min(gx1, grid_w_ - 1); ++gx)
                grid_[static_cast<std::size_t>(gy) * grid_w_ + gx].push_back(k);
    }
    build_forelock();
}

// Stray locks over the forehead: each from a root a few mm inside the front
// hairline, falling along the strands' flow (so they sweep the same way as
// the hair above them), its strands fanning out from the root.
void Painter::build_forelock() {
    const FaceParams::Forelock& fl = p_.hair_forelock;
    if (fl.locks <= 0) return;
    // The forehead's surface point at frontal (x, y).
    auto surface = [&](double x, double y) {
        const glm::dvec3 o{x, y, 0.0};
        return o + glm::dvec3{0.0, 0.0, 1.0} * s_.cast(o, {0.0, 0.0, 1.0});
    };
    constexpr double kSpan = 30.0;  // mm either side of the midline, inside the temples' recession
    locks_min_ = {1e9, 1e9};
    locks_max_ = {-1e9, -1e9};
    for (int k = 0; k < fl.locks; ++k) {
        const double x = kSpan * (2.0 * (k + 0.5 + 0.7 * (hash(k, 1, 201) - 0.5)) / fl.locks - 1.0);
        double y = p_.hairline_y;
        for (int it = 0; it < 3; ++it) y = s_.hairline(surface(x, y));
        y += 1.0 + 2.5 * hash(k, 2, 203);
        // Along the flow: across it stays constant, and down the forehead.
        constexpr double d = 1.0;
        auto across = [&](double px, double py) { return s_.hair_flow(surface(px, py)).across; };
        const glm::dvec2 g{across(x + d, y) - across(x - d, y), across(x, y + d) - across(x, y - d)};
        glm::dvec2 dir = glm::length(g) > 1e-9 ? glm::normalize(glm::dvec2{-g.y, g.x}) : glm::dvec2{0.0, -1.0};
        if (dir.y > 0.0) dir = -dir;
        // Loose strands fall: steeper than the flow the combed hair keeps.
        dir = glm::normalize(dir + glm::dvec2{0.0, -0.7});
        const double lean = 0.5 * (hash(k, 3, 205) - 0.5);
        dir = {dir.x * std::cos(lean) - dir.y * std::sin(lean), dir.x * std::sin(lean) + dir.y * std::cos(lean)};
        const glm::dvec2 side{-dir.y, dir.x};
        const double length = mix(fl.length[0], fl.length[1], hash(k, 4, 207));
        const double curl = (hash(k, 5, 209) - 0.5) * 0.3 * length;  // the lock's own curve
        for (int s = 0; s < fl.strands; ++s) {
            const double o = s - 0.5 * (fl.strands - 1);
            const double fan = 0.07 * o + 0.06 * (hash(k, s, 211) - 0.5);
            BrowHair h;
            h.root = glm::dvec2{x, y} + side * (0.3 * o);
            h.dir = {dir.x * std::cos(fan) - dir.y * std::sin(fan), dir.x * std::sin(fan) + dir.y * std::cos(fan)};
            h.side = {-h.dir.y, h.dir.x};
            h.length = length * (0.7 + 0.3 * hash(k, s, 213));
            h.bend = curl + 0.1 * length * (hash(k, s, 215) - 0.5);
            h.width = fl.width * (0.8 + 0.4 * hash(k, s, 217));
            h.shade = 0.85 + 0.4 * hash(k, s, 219);
            locks_.push_back(h);
            const glm::dvec2 tip = h.root + h.length * h.dir + h.bend * h.side;
            locks_min_ = glm::min(locks_min_, glm::min(h.root, tip) - 2.0);
            locks_max_ = glm::max(locks_max_, glm::max(h.root, tip) + 2.0);
        }
    }
}

double Painter::forelock(double x, double y, Rgb* colour) const {
    if (x < locks_min_.x || y < locks_min_.y || x > locks_max_.x || y > locks_max_.y) return 0.0;
    const Rgb hair = from255(p_.hair);
    StrokeMix mix;
    for (const BrowHair& h : locks_) {
        double along = 0.0;
        const double cover = stroke_cover(h, {x, y}, &along);
        // Thinner and lit through towards the tip.
        if (cover > 0.0) mix.add(hair, cover, 0.8, h.shade * (1.0 + 0.3 * along));
    }
    return mix.result(colour);
}

double Painter::brow_hairs(double x, double y, Rgb* colour) const {
    const int gx = static_cast<int>(std::floor((x - grid_min_[0]) / kBucket));
    const int gy = static_cast<int>(std::floor((y - grid_min_[1]) / kBucket));
    if (gx < 0 || gy < 0 || gx >= grid_w_ || gy >= grid_h_) return 0.0;
    const Rgb brow = from255(p_.brows);
    StrokeMix mix;
    for (int k : grid_[static_cast<std::size_t>(gy) * grid_w_ + gx]) {
        const BrowHair& h = hairs_[static_cast<std::size_t>(k)];
        double along = 0.0;
        const double cover = stroke_cover(h, {x, y}, &along);
        // Lighter towards the tip, where the hair is thinner.
        if (cover > 0.0) mix.add(brow, cover, 0.7, h.shade * (0.85 + 0.35 * along));
    }
    return mix.result(colour);
}

// Hair of the scalp: 0 (skin) .. 1, and its colour. The strands run from the
// crown over the surface; strand coordinates are the azimuth round the crown
// (across) and the distance from it (along).
double Painter::hair(glm::dvec3 q, Rgb* colour, double* roots) const {
    *roots = 0.0;
    const double ax = std::abs(q.x);
    // The hairline is the head's (FaceShape: the hair volume rises from the
    // same line, measured the same way along the head), so paint and
    // geometry agree.
    const double line = s_.hairline(q);
    // A cheap bound first: hair_height is the height over the line divided
    // by the line's steepness (at least 1), so nothing far below it paints.
    const double band = p_.hairline_band;
    const FaceParams::Albedo::FineHairs& fh = p_.albedo.fine_hairs;
    if (q.y - line < -0.4 * band - fh.length[1] - 30.0) return 0.0;
    // Height above the hairline along the head (whose course wanders:
    // FaceShape; a saw-tooth edge reads as a wig, the fine hairs below make
    // it irregular at the small scale).
    double edge = s_.hair_height(q);
    // Leave the ears bare.
    if (ax > 55 && s_.ear_relief(q.y, q.z) > 0.3) edge = std::min(edge, -4.0);
    if (edge < -0.4 * band - fh.length[1]) return 0.0;
    // Where hair grows the roots show grey through the skin; they thin out
    // with the hair below the line.
    *roots = glm::smoothstep(-0.5 * band, 0.6 * band, edge);

    const FaceShape::HairFlow flow = s_.hair_flow(q);
    const double azimuth = flow.azimuth, across = flow.across, along = flow.along;
    const double w = p_.hair_strand_width, len = p_.hair_strand_length;
    // Clumps: bands across whose course sways as they run (combed hair is
    // not a set of parallel grooves), each with its own width, tone and
    // phase along, so its tips (lighter, thinner) fall in different places.
    const double sway = 5.0 * (noise(across * 0.04, along * 0.03, 12.0) - 0.5) + 1.2 * (noise(across * 0.15, along * 0.07, 13.0) - 0.5);
    const double clump_w = 6.0 * w;
    const double cu = (across + sway) / clump_w;
    const int ci = static_cast<int>(std::floor(cu));
    const double phase = hash(ci, 7, 3);
    const double tip = std::fmod(along / len + phase + 100.0, 1.0);
    const double ac = across + sway;
    const double strands = 0.45 * noise(ac / w, along / (0.35 * len), 1.0) +
                           0.35 * noise(ac / (0.5 * w), along / (0.25 * len), 2.0) +
                           0.2 * noise(ac / (2.3 * w), along / len, 3.0);
    // 0 mid-clump .. 1 between clumps; clumps part unevenly.
    const double split = 0.35 + 0.3 * hash(ci, 13, 5);
    const double f = cu - ci;
    const double clump_edge = f < split ? 1.0 - f / split : (f - split) / (1.0 - split);
    const double part = 0.2 + 0.35 * hash(ci, 17, 5);  // how deep the gap to the next clump is
    double value = 0.85 + 0.55 * (strands - 0.5) - part * clump_edge * clump_edge * clump_edge;
    // A light sheen line along the middle of each clump, where its strands
    // lie flattest.
    value += 0.18 * (1.0 - glm::smoothstep(0.0, 0.45, clump_edge)) * noise(ac / (3.0 * w), along / (0.6 * len), 14.0);
    // Lighter towards each clump's tips, smoothly both ways (a ramp that
    // drops back at the next root draws a line across the clump).
    const double tip_light = std::sin(kPi * tip);
    value *= 1.0 + p_.hair_tip_lightening * tip_light * tip_light;
    // Clumps and tufts differ in tone, and broad patches (about 12 mm) are
    // lighter or darker: an even tone and one sheen over the crown read as a
    // cap; these break the albedo's relief, and with it the highlight, up.
    value *= 0.8 + 0.4 * hash(ci, 11, 5);
    value *= 0.75 + 0.5 * noise(cu * 0.4, along / 14.0, 15.0);  // tufts of a few clumps
    value *= 0.72 + 0.56 * noise(q.x * 0.08, q.y * 0.08, q.z * 0.08 + 9.0);
    // The volume's tufts (FaceShape::hair_tuft): their crests catch the
    // light and the partings between them are dark with roots and shadow.
    const double tuft = s_.hair_tuft(q);
    value *= 1.0 - p_.hair_tuft_shade * (1.0 - tuft) * (1.0 - tuft) + 0.25 * p_.hair_tuft_shade * tuft;
    const Rgb hair_colour = from255(p_.hair);
    *colour = hair_colour * std::max(value, 0.15);

    // The hairline: the mass of hair thins over the band, and single fine
    // hairs grow from it over the skin, fewer the further out; each lies
    // along the strands' flow, tip away from the crown.
    // The mass thins unevenly: its clumps reach further out than the
    // partings between them, and patches a few mm across thin early, so
    // the skin shows through in streaks along the strands. One smooth
    // gradient along the line read, where the temples turn away from the
    // camera and squeeze the band into a few pixels, as a helmet's hard
    // edge (blind review, issue 11).
    const double ragged = band * (0.25 * (0.5 - clump_edge) + 0.15 * (strands - 0.5) +
                                  0.3 * (noise(q.x * 0.22 + 5.0, q.y * 0.22, q.z * 0.22 + 31.0) - 0.5));
    const double density = glm::smoothstep(-0.2 * band, 0.7 * band, edge + ragged);
    if (density >= 1.0) return 1.0;
    // Hairs on a jittered grid in strand coordinates (mm across at the
    // hairline's distance from the crown, mm along).
    const double fa = azimuth * 120.0;
    const double sa = fh.spacing[0], sl = fh.spacing[1];
    const int ia = static_cast<int>(std::floor(fa / sa)), il = static_cast<int>(std::floor(along / sl));
    const int back = static_cast<int>(std::ceil(fh.length[1] / sl));
    double clear = 1.0;
    Rgb sum{};
    double weight = 0.0;
    for (int dl = -back; dl <= 0; ++dl)
        for (int da = -1; da <= 1; ++da) {
            const int i = ia + da, j = il + dl;
            const double root_a = (i + hash(i, j, 101)) * sa, root_l = (j + hash(i, j, 103)) * sl;
            const double length = mix(fh.length[0], fh.length[1], hash(i, j, 107));
            // Leaning a little off the flow, each its own way.
            const double lean = 0.5 * (hash(i, j, 109) - 0.5);
            const double t = (along - root_l) / length;
            if (t < 0.0 || t > 1.0) continue;
            const double off = std::abs(fa - root_a - lean * (along - root_l));
            const double half = 0.5 * fh.width * (1.0 - 0.6 * t);
            if (off > half + 0.2) continue;
            // The root's place against the hairline: the surface climbs
            // about a millimetre towards the crown per millimetre along.
            const double root_edge = edge + (along - root_l);
            // Patchy: tufts of fine hairs with gaps of bare skin between.
            const double grows = glm::smoothstep(-0.55 * band, 0.5 * band, root_edge) *
                                 std::clamp(0.45 + 0.8 * noise(fa * 0.1, along * 0.08, 21.0), 0.0, 1.0);
            if (hash(i, j, 113) > grows) continue;
            const double cover = (1.0 - glm::smoothstep(half, half + 0.2, off)) * (1.0 - glm::smoothstep(0.75, 1.0, t));
            clear *= 1.0 - 0.85 * cover;
            // Fine hairs are lighter at their tips and the outermost lighter still.
            const double shade = (0.8 + 0.4 * hash(i, j, 127)) * (1.0 + 0.3 * t) * (1.2 - 0.2 * grows);
            sum = {sum.r + hair_colour.r * shade * cover, sum.g + hair_colour.g * shade * cover,
                   sum.b + hair_colour.b * shade * cover};
            weight += cover;
        }
    const double fine = 1.0 - clear;
    if (fine > 0.0) *colour = blend(*colour, sum * (1.0 / weight), fine * (1.0 - density));
    return std::clamp(1.0 - (1.0 - density) * (1.0 - fine), 0.0, 1.0);
}

// Redness: haemoglobin absorbs green and blue, so a redder patch keeps its
// red and loses some of both. `amount` 1 is the strongest flush painted.
Rgb redden(Rgb c, double amount) {
    return blend(c, c * Rgb{1.02, 0.84, 0.83}, std::clamp(amount, -0.5, 1.5));
}
// A soft elliptical field, 1 at (cx, cy) falling off as a Gaussian of
// widths sx, sy (mm): regions of colour with no edge to see.
double field(double x, double y, double cx, double cy, double sx, double sy) {
    const double dx = (x - cx) / sx, dy = (y - cy) / sy;
    return std::exp(-0.5 * (dx * dx + dy * dy));
}
Rgb tint(Rgb c, const glm::dvec3& t, double amount) { return blend(c, c * Rgb{t[0], t[1], t[2]}, amount); }
// Redness at the luminance c had: the renderer bumps the base colour's
// luminance relief (render/src/skin_maps.cpp), so blood variation finer than
// a few mm must change the hue, not the value, or it turns into lumps.
Rgb redden_hue(Rgb c, double amount) {
    const Rgb r = redden(c, amount);
    auto luma = [](Rgb x) { return 0.2126 * x.r + 0.7152 * x.g + 0.0722 * x.b; };
    return r * (luma(c) / std::max(luma(r), 1e-6));
}

// Small round spots, one candidate per cell of a jittered grid of `spacing`
// mm, present with `chance`, of radius 0.5 .. 1.5 times `size` mm and each
// its own strength: 0 (none) .. 1 at (x, y). `seed` keeps sets apart.
double spots(double x, double y, double spacing, double chance, double size, int seed) {
    const int fx = static_cast<int>(std::floor(x / spacing)), fy = static_cast<int>(std::floor(y / spacing));
    double spot = 0.0;
    for (int dj = -1; dj <= 1; ++dj)
        for (int di = -1; di <= 1; ++di) {
            const int i = fx + di, j = fy + dj;
            if (hash(i, j, seed) > chance) continue;
            const double px = (i + hash(i, j, seed + 2)) * spacing, py = (j + hash(i, j, seed + 8)) * spacing;
            const double r = size * (0.5 + hash(i, j, seed + 12));
            spot = std::max(spot, (1.0 - glm::smoothstep(0.3 * r, r, std::hypot(x - px, y - py))) *
                                      (0.4 + 0.6 * hash(i, j, seed + 18)));
        }
    return spot;
}

// Pores: pits centred on a jittered lattice of `spacing` mm in 3D, each of
// its own radius, up to 1.25 `size` mm. The surface cuts each pit's sphere
// at its own depth, so the pits it shows differ in size and depth and lie
// irregularly, whatever way the surface faces. 0 (none) .. 1 at q.
double pore_pits(const glm::dvec3& q, double spacing, double size) {
    const glm::dvec3 f = q / spacing;
    const int cx = static_cast<int>(std::floor(f.x)), cy = static_cast<int>(std::floor(f.y)),
              cz = static_cast<int>(std::floor(f.z));
    const double reach = 1.25 * size / spacing;  // the largest radius, in cells
    // Points lie in [0.15, 0.85] of their cell: a cell whose range is
    // farther than the largest radius holds no pit that reaches q.
    auto gap = [&](double t, int c) { return std::max({0.0, c + 0.15 - t, t - (c + 0.85)}); };
    double pit = 0.0;
    for (int dz = -1; dz <= 1; ++dz) {
        const double gz = gap(f.z, cz + dz);
        if (gz > reach) continue;
        for (int dy = -1; dy <= 1; ++dy) {
            const double gy = gap(f.y, cy + dy);
            if (gy * gy + gz * gz > reach * reach) continue;
            for (int dx = -1; dx <= 1; ++dx) {
                const double gx = gap(f.x, cx + dx);
                if (gx * gx + gy * gy + gz * gz > reach * reach) continue;
                const int i = cx + dx, j = cy + dy, k = cz + dz;
                const int ik = i + 7919 * k;
                const glm::dvec3 centre{i + 0.15 + 0.7 * hash(ik, j, 301), j + 0.15 + 0.7 * hash(ik, j, 303),
                                        k + 0.15 + 0.7 * hash(ik, j, 307)};
                const double radius = reach * (0.6 + 0.4 * hash(ik, j, 311));
                const glm::dvec3 d = f - centre;
                const double t = glm::dot(d, d) / (radius * radius);
                if (t < 1.0) pit = std::max(pit, (1.0 - t) * (1.0 - t));
            }
        }
    }
    return pit;
}

Painter::LashLine Painter::lash_line(double ax, double s, double dy_up, double dy_lo, double along) const {
    const FaceParams::LashLine& ll = p_.lash_line;
    LashLine out;
    const double so = clamp01(s);
    // No lashes over the inner few mm (the punctum's stretch), the line
    // running on a little past the outer corner.
    const double grown = glm::smoothstep(0.02, 0.14, s) * along;
    if (dy_up > -1.0) {
        // Past the outer corner the line runs on for a couple of mm,
        // thinning and rising a little (the outermost lashes), instead of
        // filling the corner's fade as a block.
        const double past = std::max(0.0, (s - 1.0) * (s_.eye.x_out - s_.eye.x_in));
        const double flick = 1.0 - glm::smoothstep(0.0, 2.5, past);
        // Measured from the margin's front edge: seen from the front, the
        // rounded margin (the strip, darkened below) spans about 0.55 of
        // the lid's thickness up from the margin's curve (looked at in
        // 2048 px renders); measured from the curve, the line ended a
        // texel or two above the strip.
        const double rise = dy_up - 0.55 * p_.lid_thickness * (1.0 - glm::smoothstep(0.0, 1.5, past)) - 0.35 * past;
        const double amount = mix(ll.amount[0], ll.amount[1], so) * grown * flick;
        // The line's top: thicker towards the outer corner, ragged where
        // the lashes gather in clumps about 2.5 mm apart.
        const double clumps = 0.5 + 0.5 * std::sin(ax * 2.3 + 1.7 * std::sin(ax * 0.9));
        const double ragged = 0.75 + 0.35 * clumps + 0.3 * (noise(ax * 1.9, 0.0, 17.0) - 0.5);
        const double top = mix(ll.width[0], ll.width[1], so * so) * ragged * (0.4 + 0.6 * flick);
        const double below = past > 0.0 ? glm::smoothstep(-0.5 * top, 0.0, rise) : 1.0;
        double cover = (1.0 - glm::smoothstep(0.4 * top, top, rise)) * below;
        // Single roots standing above it, about 0.45 mm apart and of
        // uneven height, so its edge is hair, not a drawn line.
        const double cell = ax / 0.45;
        const int k = static_cast<int>(std::floor(cell));
        const double f = cell - k - 0.5 - 0.4 * (hash(k, 7, 211) - 0.5);
        const double reach = top + 0.2 + 0.6 * hash(k, 7, 213);
        const double root = std::exp(-(f / 0.2) * (f / 0.2)) * (1.0 - glm::smoothstep(0.6 * reach, reach, rise)) * below;
        cover = std::max(cover, 0.7 * root);
        out.upper = amount * cover;
        // On the strip's upper half (nearer the upper margin than the
        // lower); lighter over the inner third, where the lashes are fewer
        // and short.
        const double upper_half = glm::smoothstep(-0.3, 0.3, std::abs(dy_lo) - std::abs(dy_up));
        out.on_margin = ll.upper_margin * mix(0.6, 1.0, so) * grown * upper_half;
    }
    if (dy_lo > -1.0 && s < 1.0) {
        // Lower lashes: sparse and fine, about one root in two of a 0.9 mm
        // comb, just under the margin's front edge, which the front sees
        // about 0.45 mm under the margin's curve (the strip's pale line
        // above it; looked at in 2048 px renders). Within the opening only:
        // past the outer corner they drew a row of dots beside the canthus.
        const double edge = dy_lo - 0.45;
        const double cell = ax / 0.9;
        const int k = static_cast<int>(std::floor(cell));
        const double f = cell - k - 0.5 - 0.5 * (hash(k, 9, 221) - 0.5);
        const double present = hash(k, 9, 223) < 0.55 ? 0.5 + 0.5 * hash(k, 9, 227) : 0.0;
        const double root =
            present * std::exp(-(f / 0.22) * (f / 0.22)) * (1.0 - glm::smoothstep(0.15, 0.5, std::abs(edge - 0.15)));
        const double line = 0.35 * (1.0 - glm::smoothstep(0.05, 0.3, std::abs(edge)));
        out.lower = ll.lower * grown * (1.0 - glm::smoothstep(0.92, 1.0, s)) * std::max(root, line);
    }
    return out;
}

Texel Painter::skin(glm::dvec3 q) const {
    // Colour where the symmetric face's curves put it: the shape's
    // asymmetry carries the colour with it.
    q -= s_.asymmetry(q);
    const FaceParams::Albedo& al = p_.albedo;
    // -1 (the face's right) .. 1 (its left): the halves' colouring differs.
    const double half = std::clamp(q.x / 25.0, -1.0, 1.0) * p_.asymmetry_albedo;
    const Rgb skin = from255(p_.skin);
    double gloss = 1.0;
    // Gentle pigment variation at two scales (MATTS: even skin reads young,
    // so it stays within a few percent), and haemoglobin mottling apart from
    // it so the two do not move together.
    // Both have a broad component (tens of mm: the blotchiness seen at a
    // glance) under the finer one.
    // A third, broader scale (about 60 mm: one side of the forehead or a
    // cheek a shade lighter than the other) so the mottling reads at 512 px,
    // where the finer scales fall below a few pixels and average out. All
    // three are wider than the albedo relief's blur (skin.json
    // albedo_detail), so they stay colour and do not turn into lumps.
    const double pigment = 0.45 * fbm(q.x * 0.08, q.y * 0.08, q.z * 0.08) + 0.3 * noise(q.x * 0.03, q.y * 0.03, q.z * 0.03 + 21.0) +
                           0.25 * noise(q.x * 0.016 + 7.0, q.y * 0.016, q.z * 0.016 + 25.0);
    Rgb c = skin * (1.0 + al.pigment_variation * (pigment - 0.5) - 0.5 * half);
    const double blood = 0.55 * fbm(q.x * 0.21 + 11.0, q.y * 0.21, q.z * 0.21) + 0.45 * noise(q.x * 0.06, q.y * 0.06, q.z * 0.06 + 23.0);
    c = redden(c, al.mottling * (blood - 0.45));
    // Blotches: blood pools unevenly a few mm across (the blotchiness of
    // real skin seen close up), with soft irregular shapes (thresholded
    // noise, not discs); a browner set apart (melanin) that darkens a little.
    {
        // Depth varies a third as fast: where the surface faces the viewer
        // and curves (the nose's tip), a noise varying as fast in depth as
        // across drew its thresholded contours as rings round the tip.
        const glm::dvec3 b = glm::dvec3{q.x, q.y, 0.35 * q.z} / al.blotch_size;
        const double red = glm::smoothstep(0.5, 0.78, fbm(b.x + 3.1, b.y, b.z + 51.0));
        const double brown = glm::smoothstep(0.55, 0.8, fbm(0.7 * b.x, 0.7 * b.y + 5.3, 0.7 * b.z + 57.0));
        // The forehead is the least red site (HAN): its blotches are
        // fainter (evenly spread red patches over it read as a rash).
        c = redden_hue(c, al.blotch_strength * red * (1.0 - 0.6 * glm::smoothstep(12.0, 35.0, q.y)));
        c = blend(c, c * Rgb{0.95, 0.92, 0.88}, al.blotch_strength * brown);
    }
    // Pore-scale variation: the skin's grain lightens and darkens it at
    // under a millimetre, and pores darken it in pits, most on the nose and
    // the cheeks beside it; the renderer's albedo relief turns both into
    // fine bumps (the pits into pits).
    {
        const FaceParams::Albedo::Pores& po = al.pores;
        const glm::dvec3 f = q / po.grain_size;
        const double grain = 0.6 * noise(f.x, f.y, f.z + 70.0) + 0.4 * noise(2.7 * f.x, 2.7 * f.y, 2.7 * f.z);
        c = c * (1.0 + po.grain_strength * 2.0 * (grain - 0.5));
        double w = po.base;
        for (const auto& r : po.regions)
            w += r.amount * field(r.centre[0] == 0.0 ? q.x : std::abs(q.x), q.y, r.centre[0], r.centre[1], r.size[0], r.size[1]);
        w = clamp01(w);
        if (po.strength * w > 0.004) {
            const double pit = pore_pits(q, po.spacing, po.size * (0.55 + 0.45 * w));
            // A pore's mouth is shadowed and holds sebum and keratin: darker
            // and a little browner, not grey.
            c = blend(c, c * Rgb{0.84, 0.78, 0.74}, std::min(1.0, po.strength / 0.16 * w * pit));
        }
    }
    const double ax = std::abs(q.x);
    // Forehead: a shade darker and more yellow.
    c = tint(c, al.forehead_tint, al.forehead_amount * glm::smoothstep(18.0, 45.0, q.y));
    // Beard zone (shaved): below a line from the sideburn to the mouth
    // corner, round the jaw to below the ear, fading on the neck; the
    // stubble's dots under the skin make it grainy at the fine scale.
    {
        const double lateral = std::clamp((ax - 28.0) / 34.0, 0.0, 1.0);
        const double cheek_line = mix(-46.0, -14.0, lateral);
        // The moustache, chin and jaw carry the densest stubble; on the
        // cheeks it thins upwards over a wider band (a sharp upper line read
        // as a grey mask).
        const double ramp = mix(9.0, 24.0, glm::smoothstep(0.0, 0.6, lateral));
        const double below = cheek_line - q.y + 4.0 * (noise(q.x * 0.15, q.y * 0.15, 31.0) - 0.5);
        const double beard = glm::smoothstep(-3.0, ramp, below) *
                             glm::smoothstep(-150.0, -118.0, q.y) * glm::smoothstep(p_.sideburn_z - 25.0, p_.sideburn_z - 5.0, q.z) *
                             (0.75 + 0.5 * noise(q.x * 1.7, q.y * 1.7, q.z * 1.7)) *
                             (ax > 55.0 ? 1.0 - std::min(1.0, s_.ear_relief(q.y, q.z)) : 1.0);  // not on the lobe
        c = tint(c, al.beard_tint, al.beard_amount * beard);
        // Stubble: the cut hairs' dark ends in their follicles, about a
        // millimetre apart, each a dot a few tenths of a mm across, most
        // where the beard is densest. A grey cast alone read as a bluish
        // smear; the dots give it a grain at a 1024 px crop.
        if (beard > 0.05) {
            // Laid out round the head: the azimuth about an axis 20 mm
            // behind the face's centre, about 1 mm per mm of skin from the
            // chin round to the jaw's side, each side its own dots. (|x| - z
            // would stand still wherever the skin came forward as fast as
            // it went out, and its dots would run into lines there.)
            const double around = (q.x >= 0.0 ? 1.0 : -1.0) * (90.0 * std::atan2(ax, q.z + 20.0) + 200.0);
            const double dot = spots(around, q.y, 0.75, 0.8, 0.22, 171);
            c = blend(c, c * Rgb{0.62, 0.62, 0.66}, std::min(1.0, 1.1 * al.beard_amount * beard) * dot);
        }
    }
    // The face's own colouring (redness, freckles, lids, lips, brows) fades
    // in towards the front instead of starting at a cut.
    const double front = glm::smoothstep(36.0, 56.0, q.z);
    if (front > 0.0) {
        const Rgb side_colour = c;
        const double side_gloss = gloss;
        // Regional redness: broad fields whose strength is broken up by
        // large noise and carried by a fine capillary texture.
        const double breakup = 1.0 - al.flush_breakup + 2.0 * al.flush_breakup * noise(q.x * 0.07, q.y * 0.07, 4.0);
        const double capillaries = 0.75 + 0.5 * fbm(q.x * 0.9, q.y * 0.9, 6.0);
        double flush = 0.0;
        for (const auto& f : al.flush)
            flush += f.amount * field(f.centre[0] == 0.0 ? q.x : ax, q.y, f.centre[0], f.centre[1], f.size[0], f.size[1]);
        // Within the flush the blood pools unevenly, a few mm across: the
        // cheek's redness is a blotchy net, densest over the cheekbone, not
        // an even wash (an even wash at any strength read as rouge or as
        // one waxy tone). The broad share darkens as blood does; the
        // blotchy share is hue only, since the renderer's albedo relief
        // would bump a blotch's darkening into a lump.
        const double pooled = glm::smoothstep(0.3, 0.72, fbm(q.x * 0.3 + 17.0, q.y * 0.3, q.z * 0.1 + 33.0));
        const double amount = flush * breakup * (1.0 + 2.5 * half);
        c = redden(c, 0.75 * amount * capillaries);
        c = redden_hue(c, 0.6 * amount * (pooled - 0.35) * capillaries);
        // Regional casts: the bridge yellower, violet under the eyes, the
        // temples a little bluer (veins under thin skin); broken up like
        // the flush so none reads as a painted shape.
        for (const auto& t : al.tones) {
            const double f = field(t.centre[0] == 0.0 ? q.x : ax, q.y, t.centre[0], t.centre[1], t.size[0], t.size[1]);
            if (f > 1e-3) c = tint(c, t.tint, std::min(1.0, t.amount * f * breakup));
        }
        // Fine capillaries (telangiectasia) on the nose's wings and the
        // cheeks beside them: short meandering red threads where a noise
        // crosses its middle value, only in sparse patches; hue only, so
        // they stay colour and not ridges. The noise is of x and y alone:
        // one varying with depth drew its contours round the nose's tip as
        // the rings of a wood grain.
        {
            const double where = field(ax, q.y, 16.0, -38.0, 6.0, 6.0) + 0.6 * field(ax, q.y, 30.0, -30.0, 12.0, 9.0);
            if (where > 0.02) {
                const double thread = 1.0 - glm::smoothstep(0.0, 0.035, std::abs(noise(q.x * 0.7, q.y * 0.7, 61.0) - 0.5));
                const double patch = glm::smoothstep(0.55, 0.8, noise(q.x * 0.2, q.y * 0.2, 63.0));
                c = redden_hue(c, 0.9 * thread * patch * std::min(where, 1.0));
            }
        }
        // Freckles: one candidate per cell of a jittered grid, over the nose
        // and cheeks mostly.
        {
            const double spot = spots(q.x, q.y, al.freckle_spacing, 0.45, al.freckle_size, 71);
            const double where = field(ax, q.y, 22.0, -30.0, 26.0, 16.0) + field(q.x, q.y, 0.0, -25.0, 10.0, 16.0);
            c = blend(c, c * Rgb{0.86, 0.78, 0.72}, al.freckle_strength * 1.6 * spot * std::min(where, 1.0));
        }
        // Blemishes (small red spots: healing follicles, a broken capillary)
        // and a few moles, anywhere on the face: skin is never clean.
        c = redden(c, al.blemishes.strength * spots(q.x, q.y, al.blemishes.spacing, al.blemishes.chance, al.blemishes.size, 131));
        c = blend(c, c * Rgb{0.62, 0.5, 0.44}, al.moles.strength * spots(q.x, q.y, al.moles.spacing, al.moles.chance, al.moles.size, 151));
        // Periorbital: thin skin, a warmer darker cast, deepest under the inner lower lid.
        const double eye_x = p_.eye_centre[0], eye_y = p_.eye_centre[1];
        const double orbit = field(ax, q.y, eye_x - 3.0, eye_y - 6.0, 11.0, 5.5) + 0.5 * field(ax, q.y, eye_x, eye_y + 3.0, 12.0, 6.0);
        c = tint(c, al.periorbital_tint, al.periorbital_amount * std::min(orbit, 1.0));

        // T-zone: the forehead and the nose are oilier (glossier), the
        // cheeks drier. Sebum lies in patches (pooled around follicles,
        // rubbed off here and there), not as one even film: broken at a few
        // mm and, as sparse glints anywhere, at about a millimetre, so the
        // sheen along the forehead's curve is broken up instead of one
        // streak down its middle; the glabella between the forehead's
        // field and the nose's is drier.
        const double t_zone = std::max(field(q.x, q.y, 0.0, 42.0, 24.0, 14.0), field(q.x, q.y, 0.0, -24.0, 8.0, 18.0));
        const double patches = glm::smoothstep(0.3, 0.75, fbm(q.x * 0.22, q.y * 0.22, q.z * 0.22 + 41.0));
        const double glints = glm::smoothstep(0.55, 0.85, noise(q.x * 0.9, q.y * 0.9, q.z * 0.9 + 43.0));
        gloss = mix(1.0, p_.gloss.t_zone, std::min(t_zone, 1.0) * (0.3 + 0.7 * patches) + 0.2 * glints);

        // Lips: the vermilion fades into the skin over the border's width
        // (its course wanders a little: a drawn curve reads as lipstick), a
        // little lighter just outside it (the white roll). Darker towards
        // the line where the lips meet and on the upper lip, lighter on the
        // lower lip's centre (it faces the light and is fuller), fading
        // towards the skin's tone at the corners, with fine vertical lines.
        const double hw = s_.mouth_half_width();
        // The commissures: a small pocket where the lips' crease ends, in
        // the modiolus' shade, darker and a little redder (the mucosa shows
        // where the lips fold in). The face turns away there (z about 50),
        // so this is outside the vermilion's front-facing test below.
        if (q.z > 30.0) {
            const double corner_y = s_.mouth_line(hw);
            const double pocket = field(ax, q.y, hw + 0.8, corner_y - 0.3, 2.4, 1.5);
            // and its fold runs on a few mm past the corner, down and out.
            const double past = ax - hw;
            const double fold = past > 0.0 && past < 4.0
                                    ? (1.0 - past / 4.0) * std::exp(-std::pow((q.y - corner_y + 0.35 * past) / 0.6, 2))
                                    : 0.0;
            c = blend(c, c * Rgb{0.52, 0.4, 0.4}, std::min(0.8 * pocket + 0.5 * fold, 0.85));
        }
        if (ax < hw + 4.0 && q.z > 60.0) {
            const double up = s_.upper_border(q.x), lo = s_.lower_border(q.x);
            // The shade under the lower lip, in the tuck above the
            // mentolabial sulcus (face_shape.cpp): the baked occlusion of a
            // few mm of tuck is faint under the frontal key, and without a
            // shade there the lip read as a roll laid on a flat chin.
            {
                const double under = lo - q.y;
                // Starting a little below the border: begun at it, the
                // shade drew an outline along the lower lip.
                const double band = glm::smoothstep(0.5, 3.5, under) * (1.0 - glm::smoothstep(4.5, 9.0, under));
                const double across = 1.0 - glm::smoothstep(0.45 * hw, 0.95 * hw, ax);
                c = blend(c, c * Rgb{0.8, 0.74, 0.72}, 0.5 * band * across);
            }
            const double wander = 0.35 * (noise(q.x * 0.6, q.y * 0.6, 3.0) - 0.5);
            const double inside = std::min({up - q.y, q.y - lo, (hw - ax) * 0.6}) + wander;
            const double line_y = s_.mouth_line(q.x);
            const bool upper = q.y > line_y;
            // The lower lip's border is softer than the upper's (no white
            // roll there: its red fades into the shade under the lip); one
            // crisp edge round both lips outlined them like a prop.
            const double border = al.lip_border_mm * (upper ? 1.0 : 1.8);
            const double m = glm::smoothstep(-0.5 * border, 0.8 * border, inside);
            const double roll = (1.0 - glm::smoothstep(0.0, 1.2, std::abs(inside + 0.6 * border))) * (upper ? 1.0 : 0.4);
            c = blend(c, c * 1.03, 0.5 * roll * (1.0 - m));
            if (m > 0) {
                const double to_line = std::abs(q.y - line_y);
                const double crease = glm::smoothstep(0.0, 2.5, to_line);
                // Lines run across the lip, fanning out from the mouth line,
                // unevenly spaced (each column its own phase and depth),
                // meandering; deepest mid-lip, gone at the border and the line.
                const double lx = q.x * 1.1 + 0.5 * std::sin(q.y * 0.9 + q.x * 0.2) + 0.8 * (noise(q.x * 0.3, q.y * 0.5, 5.0) - 0.5);
                const int column = static_cast<int>(std::floor(lx));
                const double f = lx - column - 0.5 * (hash(column, upper ? 1 : 2, 201) - 0.5);
                const double groove = std::exp(-std::pow((f - 0.5) / 0.16, 2)) * (0.4 + 0.9 * hash(column, upper ? 1 : 2, 203)) *
                                      (0.5 + noise(q.x * 0.8, q.y * 0.4, 2.0));
                const double mid = glm::smoothstep(0.2, 1.5, inside) * (0.3 + 0.7 * crease);
                const double fullness = field(q.x, q.y, 0.0, mix(line_y, lo, 0.45), 9.0, 2.6);
                Rgb lips = from255(p_.lips) * (0.78 + 0.22 * crease) * (upper ? 0.93 : 1.0) * (1.0 + 0.2 * fullness) *
                           (0.94 + 0.12 * noise(q.x * 1.3, q.y * 0.9, 1.0));
                lips = blend(lips, c * Rgb{0.95, 0.9, 0.9}, 0.45 * glm::smoothstep(0.55 * hw, hw, ax));
                // Just inside the border the vermilion is thinner-coloured,
                // nearer the skin's tone: the red deepens over a few mm
                // instead of stepping up at the border (an outline).
                lips = blend(lips, c * Rgb{0.97, 0.9, 0.88}, 0.35 * (1.0 - glm::smoothstep(0.0, 1.5 * border, inside)));
                // Grooves darker, the ridges between them a shade lighter:
                // the relief map raises the ridges, breaking the sheen.
                lips = lips * (1.0 + al.lip_lines * mid * (0.06 - 0.4 * groove));
                c = blend(c, lips, m);
                // The sheen: moist where the lips meet, drier towards the
                // border, in patches, and dull in the grooves; one even gloss
                // over the vermilion read as a varnish.
                const double sheen_patches = noise(q.x * 0.45, q.y * 0.7, 9.0);
                const double wet = 1.0 - glm::smoothstep(1.0, 3.5, to_line);
                const double dry = al.lip_sheen_breakup * std::clamp(0.4 * (1.0 - wet) + 0.5 * glm::smoothstep(0.35, 0.8, sheen_patches) +
                                                                         0.5 * groove * mid, 0.0, 1.0);
                gloss = mix(gloss, mix(p_.gloss.lips, 1.0, dry), m);
            }
        }
        // Eyelids: lash roots and slightly darker lids; the lid margin's
        // strip and the tear meniscus where the lid meets the eyeball.
        const EyeOpening& e = s_.eye;
        if (ax > e.x_in - 8 && ax < e.x_out + 10 && q.y > -18 && q.y < 22) {
            const bool within = ax >= e.x_in && ax <= e.x_out;
            const double up = within ? e.upper(ax) : (ax < e.x_in ? e.y_in : e.y_out);
            const double lo = within ? e.lower(ax) : (ax < e.x_in ? e.y_in : e.y_out);
            const double dy_up = q.y - up, dy_lo = lo - q.y;
            // Fade out past the corners instead of stopping at a box.
            const double past = ax < e.x_in ? e.x_in - ax : ax > e.x_out ? ax - e.x_out : 0.0;
            const double along = 1.0 - glm::smoothstep(0.0, ax < e.x_in ? 3.0 : 6.0, past);
            // How deep the point lies towards the eyeball: 0 on the lid's
            // front skin, 1 on the eyeball side of the margin.
            const glm::dvec3 centre{p_.eye_centre[0] * (q.x >= 0 ? 1.0 : -1.0), p_.eye_centre[1], p_.eye_centre[2]};
            const double shell = glm::length(q - centre) - p_.eye_radius;
            const double margin = 1.0 - glm::smoothstep(p_.lid_clearance + 0.35 * p_.lid_thickness,
                                                        p_.lid_clearance + 0.95 * p_.lid_thickness, shell);
            // The lids' own colour is only a shade off the face's: the
            // upper lid a little warmer near its margin, the lower lid's
            // pretarsal strip a little pinker and no darker. Darkened over
            // 9 and 6 mm, with the lash line, the socket's occlusion and
            // the albedo's lid tones on top, they drew a dark smudgy ring
            // round each eye (blind review, session 9).
            // The lash line (face.json eyes.lash_line): at 512 px a lash is
            // a fifth of a pixel and the strands draw as dots, so the line
            // that reads in a photograph, the lashes dense at their roots
            // and their shadow, is painted. It covers the margin's front
            // edge and reaches up the lid, further and darker towards the
            // outer corner, its top edge ragged with the clumps; a fine
            // even line of 0.35-0.75 mm at half strength drew no lash line
            // at all, only the pink strip below it ("no lashes seen", "lid
            // edges thick and pink": blind review, session 10).
            const LashLine line = lash_line(ax, e.s(ax), dy_up, dy_lo, along);
            if (dy_up > -1.0) {
                const double lid = (1.0 - glm::smoothstep(0.0, 5.0, dy_up)) * along;
                c = tint(c, {0.96, 0.9, 0.9}, 0.35 * lid);
                c = blend(c, from255(p_.lashes), line.upper);
                // The crease, where the lid's skin folds in under the
                // orbital skin above it: a soft shade line, highest mid-lid
                // and nearer the margin at the corners, fading past them.
                // The socket's broad shade alone left the lid one smooth
                // band between lash line and brow, a mask's shell.
                const FaceParams::LidCrease& lc = p_.lid_crease;
                const double crease_at = lc.height * (0.45 + 0.55 * std::sqrt(std::sin(kPi * clamp01(e.s(ax)))));
                const double crease = std::exp(-std::pow((dy_up - crease_at) / lc.width, 2)) *
                                      (1.0 - glm::smoothstep(0.0, 4.0, ax < e.x_in ? e.x_in - ax : ax - e.x_out));
                const double a = lc.amount * crease;  // a little warmer than grey: skin in its own shade
                c = c * Rgb{1.0 - a, 1.0 - 1.15 * a, 1.0 - 1.2 * a};
            }
            if (dy_lo > -1.0) {
                // Sparse fine lower lashes: broken roots under the margin's
                // front edge, not a line.
                c = blend(c, Rgb{0.36, 0.24, 0.21}, line.lower);
                const double pretarsal = (1.0 - glm::smoothstep(0.5, 3.5, dy_lo)) * along * (1.0 - margin);
                c = tint(c, {1.03, 0.97, 0.97}, 0.5 * pretarsal);
            }
            const double near_slit = 1.0 - glm::smoothstep(1.0, 2.5, std::min(std::abs(dy_up), std::abs(dy_lo)));
            const double strip = margin * near_slit * (within ? 1.0 : along);
            if (strip > 0.0) {
                c = blend(c, from255(al.lid_margin), 0.85 * strip);
                // The upper margin is seen from below the lashes' roots, in
                // their shade: dark, not the lower margin's moist pink.
                c = blend(c, from255(p_.lashes), line.on_margin * strip);
                gloss = mix(gloss, p_.gloss.lid_margin, strip);
                // The margin's posterior edge, where it rests on the eyeball:
                // wet conjunctiva in the lid's own shade, a dark line that
                // moves with the lid (the eyeball's tile cannot follow it).
                // The lit pink strip ran straight into the white as a pale
                // band, the eye "pasted in" (blind review, issue 11).
                const double contact = strip * (1.0 - glm::smoothstep(p_.lid_clearance + 0.15 * p_.lid_thickness,
                                                                      p_.lid_clearance + 0.5 * p_.lid_thickness, shell));
                // On the lower lid the tear meniscus lies along that edge
                // instead (below): a dark line there as well outlined the
                // eye all round.
                const double lower_lid = 1.0 - glm::smoothstep(-0.3, 0.3, std::abs(dy_lo) - std::abs(dy_up));
                c = blend(c, from255(al.lid_margin) * Rgb{0.62, 0.5, 0.5}, 0.6 * contact * (1.0 - 0.6 * lower_lid));
                gloss = mix(gloss, p_.gloss.tear_line, contact);
                // The tear meniscus: along the lower margin where it meets
                // the eyeball, a thin pale wet line (the tear film over the
                // margin's back edge catches the room), its highlight the
                // gloss's.
                const double tear = (1.0 - glm::smoothstep(p_.lid_clearance + 0.1, p_.lid_clearance + 0.6, shell)) *
                                    (dy_lo > -1.5 && q.y < e.slit(ax) ? 1.0 : 0.0) * along;
                c = blend(c, Rgb{0.94, 0.84, 0.8}, 0.4 * tear);
                gloss = mix(gloss, p_.gloss.tear_line, tear);
                // The caruncle in the inner corner, on the deep part only: a
                // moist pink mound about 3 mm across. At 0.6 of a duller pink
                // over 2 mm it vanished in the corner's shade and the white
                // ran into a grey corner (blind review: eyes "pasted in").
                const double car = (1.0 - glm::smoothstep(0.8, 2.8, std::hypot(ax - e.x_in - 0.9, q.y - e.y_in)));
                c = blend(c, Rgb{0.86, 0.5, 0.47}, 0.85 * car * strip);
                gloss = mix(gloss, p_.gloss.tear_line, car * strip);
            }
        }
        // Brows: individual hairs over a faint shadow of the fine ones.
        if (q.y > 0 && q.y < 40 && ax < 65) {
            const BrowPlace b = brow_place(q.x, q.y);
            const double d = brow_density(b);
            if (d > 0) c = blend(c, c * Rgb{0.84, 0.8, 0.78}, 0.25 * d);
            Rgb hc;
            const double cover = brow_hairs(q.x, q.y, &hc);
            if (cover > 0) c = blend(c, hc, cover);
        }
        // Nostrils.
        const double n = s_.nostril_amount(q.x, q.y);
        // Dark only deep in the opening; its rim is skin, shaded by the dent.
        if (n > 0) c = blend(c, Rgb{0.25, 0.12, 0.11}, glm::smoothstep(0.2, 0.85, n));
        c = blend(side_colour, c, front);
        gloss = mix(side_gloss, gloss, front);
    }
    // Ears: thin, well perfused, redder than the face beside them, most
    // in the hollows (concha, scapha, fossa), where the skin is seen through
    // less light and in its own shadow; the ridges (helix, antihelix,
    // tragus) a shade lighter. Painted from the relief's curvature, so the
    // detail map's bump (from this colour) deepens the folds too.
    if (ax > 55.0) {
        const double e = s_.ear_relief(q.y, q.z);
        if (e > 0.0) {
            constexpr double r = 2.5;  // mm: about a fold's half width
            const double around = 0.25 * (s_.ear_relief(q.y + r, q.z) + s_.ear_relief(q.y - r, q.z) +
                                          s_.ear_relief(q.y, q.z + r) + s_.ear_relief(q.y, q.z - r));
            const double fold = std::clamp((e - around) / 2.0, -1.0, 1.0);  // < 0 hollow, > 0 ridge
            const double inside = std::min(1.0, e / 3.0);
            c = redden(c, al.ear_flush * inside * (1.0 + 0.8 * std::max(-fold, 0.0)));
            c = c * (1.0 + inside * (0.12 * std::max(fold, 0.0) - al.ear_fold_shade * std::max(-fold, 0.0)));
            // The free rim (helix, lobe) is thin enough for light to pass
            // through: redder and more saturated over its last few mm,
            // where a step outwards leaves the ear (ear_relief is 0 off
            // it). Without it the ears read as pale flaps beside the face.
            const double dy = q.y - p_.ear_centre_yz[0], dz = q.z - p_.ear_centre_yz[1];
            const double out = std::hypot(dy, dz);
            if (out > 1e-6) {
                constexpr double kRim = 4.0;  // mm
                const double beyond = s_.ear_relief(q.y + kRim * dy / out, q.z + kRim * dz / out);
                const double rim = inside * (1.0 - std::min(1.0, beyond / 2.0));
                c = redden(c, 0.6 * al.ear_flush * rim);
                c = c * (1.0 + 0.06 * rim);
            }
        }
    }
    Rgb hc;
    double roots = 0.0;
    const double h = hair(q, &hc, &roots);
    if (roots > 0) c = tint(c, al.fine_hairs.roots_tint, al.fine_hairs.roots_amount * roots);
    if (h > 0) {
        c = blend(c, hc, h);
        gloss = mix(gloss, 1.0, h);
    }
    if (q.z > 20.0) {
        const double fl = forelock(q.x, q.y, &hc);
        if (fl > 0) {
            c = blend(c, hc, fl);
            gloss = mix(gloss, 1.0, fl);
        }
    }
    c = shirt(q, c, &gloss);
    return {c, gloss};
}

Rgb Painter::shirt(glm::dvec3 q, Rgb c, double* gloss) const {
    const FaceParams::Shirt& sh = p_.shirt;
    if (q.y > std::max({sh.neckline_front, sh.neckline_side, sh.neckline_back}) + sh.neck_shade_mm + 2.0) return c;
    const FaceShape::ShirtPlace place = s_.shirt_place(q);
    const double below = place.below;
    const double ax = std::abs(q.x);
    if (below < 0.0) {
        const double shade = sh.neck_shade * (1.0 - glm::smoothstep(0.0, sh.neck_shade_mm, -below));
        return c * (1.0 - shade);
    }
    // Cloth: broad mottling and a few soft folds fanning from the neck's
    // base out to the shoulders, wandering, under a fine jersey weave (its
    // wales run down the body, about weave_mm apart: the base map's relief
    // turns them into a faint texture that catches the light).
    Rgb cloth = from255(sh.colour);
    const double broad = fbm(q.x * 0.02, q.y * 0.02, q.z * 0.02 + 91.0) - 0.5;
    const double fan = std::atan2(sh.neckline_side + 20.0 - q.y, ax + 1.0);  // 0 across to the shoulder .. pi/2 down the chest
    const double wander = 1.2 * (noise(q.x * 0.015, q.y * 0.015, 93.0) - 0.5);
    const double fold = std::sin(sh.fold_count * 2.0 * fan + wander + (q.x < 0 ? 0.7 : 0.0));
    const double fold_reach = glm::smoothstep(0.0, 12.0, below) * (1.0 - 0.6 * glm::smoothstep(40.0, 120.0, below));
    // The wales follow the columns (about 80 mm of arc per radian of
    // azimuth round the body) and fade out on the shoulders, where they
    // would be a few mm apart, and down the chest, where the bust's rows get
    // a texel or less a mm: stretched along those rows they drew streaks.
    const double weave = std::cos(2.0 * kPi * 80.0 * std::atan2(q.x, q.z + 30.0) / sh.weave_mm) *
                         (1.0 - glm::smoothstep(70.0, 110.0, ax)) * (1.0 - glm::smoothstep(20.0, 35.0, below));
    cloth = cloth * (1.0 + 2.0 * sh.mottling * broad + sh.folds * fold * fold_reach + sh.weave * weave);
    // The collar: a ribbed band below the neckline, its ribs across it, its
    // folded top edge rounded (lighter where it turns up to the light, a
    // shade darker under it), a thin shadow along the seam under it.
    if (below < sh.collar_mm + 2.0) {
        const double band = 1.0 - glm::smoothstep(sh.collar_mm - 0.5, sh.collar_mm + 0.5, below);
        const double rib = std::cos(2.0 * kPi * place.around / sh.rib_mm);
        const double roll = std::exp(-std::pow((below - 1.2) / 1.0, 2)) - 0.5 * std::exp(-std::pow((below - 3.2) / 0.9, 2));
        Rgb collar = from255(sh.colour) * (sh.collar_shade * (1.0 + 2.0 * sh.mottling * broad) + sh.rib_contrast * rib +
                                           sh.collar_roll * roll);
        cloth = blend(cloth, collar, band);
        const double seam = std::exp(-std::pow((below - sh.collar_mm) / 0.8, 2));
        cloth = cloth * (1.0 - sh.seam_shade * seam);
    }
    // The collar's edge against the neck, over edge_mm: the rows there are
    // a few mm apart and get the texture of two rows each (face.json
    // resolution.bust), so it stays a crisp line.
    const double cover = glm::smoothstep(0.0, sh.edge_mm, below);
    *gloss = mix(*gloss, 1.0, cover);
    return blend(c * (1.0 - sh.neck_shade), cloth, cover);
}

Rgb Painter::tile(double u, double v) const {
    const int t = std::clamp(static_cast<int>(u / kTile), 0, 3);
    const double lu = u / kTile - t, lv = v / kTile;
    const double r = std::hypot(lu - 0.5, lv - 0.5) / 0.48;  // polar angle / pi for the round tiles
    const double beta = std::atan2(lv - 0.5, lu - 0.5);
    switch (static_cast<Tile>(t)) {
        case Tile::Eye: {
            // The tile's corners, outside the eyeball's disc, hold the lashes' colour.
            if (r > 1.1) return from255(p_.lashes);
            const auto c = eye_colour(s_, r * kPi, beta);
            return {c[0], c[1], c[2]};
        }
        case Tile::Cavity:
            // Lit only through the lips' opening (face_occlusion.cpp), so its
            // albedo stays a mid red to the back: 0.3 there rendered black.
            // 0.6 at the back still read as a shallow red box behind the
            // teeth (blind review, session 8): the back wall now a deep
            // shade, the rim by the lips as before. At 0.42 the strip of it
            // above the tongue rendered flat black (session 9): 0.5.
            return from255(p_.mouth) * (0.5 + 0.42 * glm::smoothstep(0.2, 1.0, std::min(r, 1.0)));
        case Tile::Teeth: {
            const bool upper = lv >= 0.5;
            const double c = ((upper ? lv - 0.5 : lv) - 0.02) / 0.46 * 3.0;  // 0 root, 1 edge (front), 3 root (back)
            const double k = (lu - 0.02) / 0.96;                              // along the arch
            const double tau = (k - 0.5) * kPi * 0.92;
            const double w = p_.teeth_half_width;
            const double s = std::abs(w * tau);  // arc length from the midline, roughly
            const double bounds[] = {0.0, 4.3, 10.6, 17.8, 24.6, 31.4, 41.0};
            double gap = 1e9;
            for (double b : bounds) gap = std::min(gap, std::abs(s - b * (upper ? 1.0 : 0.8)));
            // Each crown darker towards its contacts (its sides turn away
            // and the gaps between crowns are in shadow), softly: a black
            // seam round every crown read as a grille.
            // The shade grows over the crown's whole half-width, so the
            // labial face reads rounded, brightest down its middle.
            Rgb teeth = from255(p_.teeth) * (1.0 - 0.42 * (1.0 - glm::smoothstep(0.1, 2.8, gap)));
            // Each crown its own shade, and the arch darker from the
            // incisors back (it turns away from the light into the mouth's
            // shade): one even white read as a bright strip of plastic.
            const double crown = std::floor((k - 0.5) * 14.0);
            teeth = teeth * (0.93 + 0.1 * hash(static_cast<int>(crown), upper ? 1 : 2, 211)) *
                    (1.0 - 0.5 * glm::smoothstep(5.0, 24.0, s));
            // Enamel is thin at the neck, where the yellower, darker dentin
            // shows, and translucent at the biting edge, grey-blue against
            // the dark mouth behind it.
            const double front = c <= 1.5 ? c : 3.0 - c;  // 0 gum .. 1 edge, either face
            teeth = blend(teeth * Rgb{0.82, 0.74, 0.6}, teeth, glm::smoothstep(0.3, 0.7, front));
            teeth = blend(teeth, teeth * Rgb{0.72, 0.74, 0.8}, glm::smoothstep(0.78, 1.0, front));
            // The gum: pink, a darker red along its margin on the crown.
            const double gum = 1.0 - glm::smoothstep(0.22, 0.3, front);
            const Rgb gums{0.74, 0.4, 0.4};
            return blend(teeth, gums * (0.85 + 0.15 * glm::smoothstep(0.1, 0.25, front)), gum);
        }
        case Tile::Tongue: {
            // Its tip (the tile's centre) lit through the lips, its body
            // falling into the mouth's shade: an even red filled the open
            // mouth as a flat red mass. The occlusion bake darkens the body
            // with its depth too, so the fall here is gentle: at 0.55 the
            // dorsum the open mouth shows was a dark red slab.
            Rgb tongue = from255(p_.tongue) * (0.85 + 0.25 * noise(lu * 40, lv * 40, 2.0)) *
                         (1.0 - 0.4 * glm::smoothstep(0.2, 0.75, std::min(r, 1.0)));
            // The median sulcus: a shallow groove down the dorsum's middle
            // (the top half of the tile, beta = pi / 2), from behind the tip
            // to the back; about 1.5 mm either side of the midline on a
            // tongue 34 mm wide.
            const double across = std::sin(kPi * std::min(r, 1.0)) * std::cos(beta) * 17.0;
            const double sulcus = std::exp(-(across / 1.5) * (across / 1.5)) * glm::smoothstep(0.12, 0.3, r) *
                                  glm::smoothstep(0.0, 0.3, std::sin(beta));
            return tongue * (1.0 - 0.25 * sulcus);
        }
    }
    return {};
}

}  // namespace

Image paint_base_colour(const FaceShape& shape, const TriMesh& mesh, int size) {
    Image img;
    img.width = img.height = size;
    img.rgba.assign(static_cast<std::size_t>(size) * size * 4, 0);
    std::vector<std::uint8_t> filled(static_cast<std::size_t>(size) * size, 0);
    const Painter painter(shape);
    auto put = [&](int x, int y, Rgb c, double gloss) {
        const std::size_t i = static_cast<std::size_t>(y) * size + x;
        auto to8 = [](double v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
        img.rgba[i * 4 + 0] = to8(c.r);
        img.rgba[i * 4 + 1] = to8(c.g);
        img.rgba[i * 4 + 2] = to8(c.b);
        img.rgba[i * 4 + 3] = to8(gloss);
        filled[i] = 1;
    };

    // The triangles in texel coordinates, and which bands of rows each
    // touches: bands are painted in parallel, each by one thread, every
    // band's triangles in mesh order, so the image does not depend on the
    // thread count.
    struct Triangle {
        double tu[3], tv[3];
        glm::dvec3 pos[3];
        bool skin;
        int y0, y1;
    };
    constexpr int kBandRows = 16;
    const int bands = (size + kBandRows - 1) / kBandRows;
    std::vector<Triangle> triangles;
    triangles.reserve(mesh.n_faces());
    std::vector<std::vector<int>> in_band(static_cast<std::size_t>(bands));
    for (auto fh : mesh.faces()) {
        Triangle t;
        int k = 0;
        for (auto vh : mesh.fv_range(fh)) {
            const auto uv = mesh.texcoord2D(vh);
            const auto q = mesh.point(vh);
            t.tu[k] = uv[0] * size - 0.5;
            t.tv[k] = (1.0 - uv[1]) * size - 0.5;
            t.pos[k] = {q[0], q[1], q[2]};
            ++k;
        }
        t.skin = std::min({t.tu[0], t.tu[1], t.tu[2]}) >= -1 &&
                 (1.0 - (std::max({t.tv[0], t.tv[1], t.tv[2]}) + 0.5) / size) >= kSkinV0 - 1e-6;
        t.y0 = std::max(0, static_cast<int>(std::floor(std::min({t.tv[0], t.tv[1], t.tv[2]}))));
        t.y1 = std::min(size - 1, static_cast<int>(std::ceil(std::max({t.tv[0], t.tv[1], t.tv[2]}))));
        if (t.y0 > t.y1) continue;
        const int index = static_cast<int>(triangles.size());
        triangles.push_back(t);
        for (int b = t.y0 / kBandRows; b <= t.y1 / kBandRows; ++b) in_band[static_cast<std::size_t>(b)].push_back(index);
    }
    parallel_for(bands, 1, [&](int band_begin, int band_end) {
        for (int band = band_begin; band < band_end; ++band) {
            const int row0 = band * kBandRows, row1 = std::min(size - 1, row0 + kBandRows - 1);
            for (int index : in_band[static_cast<std::size_t>(band)]) {
                const Triangle& t = triangles[static_cast<std::size_t>(index)];
                const double* tu = t.tu;
                const double* tv = t.tv;
                const int x0 = std::max(0, static_cast<int>(std::floor(std::min({tu[0], tu[1], tu[2]}))));
                const int x1 = std::min(size - 1, static_cast<int>(std::ceil(std::max({tu[0], tu[1], tu[2]}))));
                const double area = (tu[1] - tu[0]) * (tv[2] - tv[0]) - (tu[2] - tu[0]) * (tv[1] - tv[0]);
                if (std::abs(area) < 1e-12) continue;
                for (int y = std::max(t.y0, row0); y <= std::min(t.y1, row1); ++y) {
                    for (int x = x0; x <= x1; ++x) {
                        const double w0 = ((tu[1] - x) * (tv[2] - y) - (tu[2] - x) * (tv[1] - y)) / area;
                        const double w1 = ((tu[2] - x) * (tv[0] - y) - (tu[0] - x) * (tv[2] - y)) / area;
                        const double w2 = 1.0 - w0 - w1;
                        constexpr double kEps = -1e-4;
                        if (w0 < kEps || w1 < kEps || w2 < kEps) continue;
                        if (t.skin) {
                            const Texel texel = painter.skin(t.pos[0] * w0 + t.pos[1] * w1 + t.pos[2] * w2);
                            put(x, y, texel.colour, texel.gloss);
                        } else {
                            put(x, y, painter.tile((x + 0.5) / size, 1.0 - (y + 0.5) / size), 1.0);
                        }
                    }
                }
            }
        }
    });
    // Grow the painted texels into the empty ones around them, so bilinear
    // filtering and mipmaps near a chart's border never fetch black. A pass
    // reads only texels filled before it and writes only empty ones, so its
    // rows can run in parallel.
    for (int pass = 0; pass < 8; ++pass) {
        std::vector<std::uint8_t> next = filled;
        parallel_for(size, kBandRows, [&](int row_begin, int row_end) {
            for (int y = row_begin; y < row_end; ++y) {
                for (int x = 0; x < size; ++x) {
                    const std::size_t i = static_cast<std::size_t>(y) * size + x;
                    if (filled[i]) continue;
                    int sum[4] = {0, 0, 0, 0}, n = 0;
                    for (int dy = -1; dy <= 1; ++dy)
                        for (int dx = -1; dx <= 1; ++dx) {
                            const int xx = x + dx, yy = y + dy;
                            if (xx < 0 || yy < 0 || xx >= size || yy >= size) continue;
                            const std::size_t j = static_cast<std::size_t>(yy) * size + xx;
                            if (!filled[j]) continue;
                            for (int c = 0; c < 4; ++c) sum[c] += img.rgba[j * 4 + c];
                            ++n;
                        }
                    if (n == 0) continue;
                    for (int c = 0; c < 4; ++c) img.rgba[i * 4 + c] = static_cast<std::uint8_t>(sum[c] / n);
                    next[i] = 1;
                }
            }
        });
        filled.swap(next);
    }
    for (std::size_t i = 0; i < filled.size(); ++i)
        if (!filled[i]) img.rgba[i * 4 + 3] = 255;
    return img;
}

}  // namespace emoface::expression::detail
