#include "emoface/expression/wrinkle_map.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/geometric.hpp>

#include "emoface/common/error.h"
#include "json_reader.h"
#include "emoface/common/parallel.h"

namespace emoface::expression {
namespace {

// ---------------------------------------------------------------- loading

using detail::JsonReader;

int feature_index(const JsonReader& value) {
    if (!value.is_string()) value.fail("a feature point id such as \"4.1\"");
    const auto index = fap::find_feature_point(value.as_string());
    if (!index) value.fail("an MPEG-4 feature point id such as \"4.1\"");
    return *index;
}

glm::vec2 read_vec2(const JsonReader& value) {
    const auto xy = value.as_numbers<2>();
    return {static_cast<float>(xy[0]), static_cast<float>(xy[1])};
}

float read_number(JsonReader& object, const char* key, float fallback, float min, float max) {
    return static_cast<float>(object.number_in(key, min, max, fallback));
}

AnchoredPoint read_point(JsonReader item) {
    item = item.as_object();
    AnchoredPoint point;
    const JsonReader fp = item.at("fp");
    if (fp.is_array()) {
        const std::vector<JsonReader> ends = fp.elements();
        if (ends.size() != 2) fp.fail("2 feature point ids");
        point.from = feature_index(ends[0]);
        point.to = feature_index(ends[1]);
        point.t = read_number(item, "t", 0.5f, -2.0f, 3.0f);
    } else {
        point.from = feature_index(fp);
    }
    if (item.has("offset")) point.offset = read_vec2(item.at("offset"));
    point.depth_factor = read_number(item, "depth_factor", 1.0f, 0.0f, 1.0f);
    item.finish();
    return point;
}

WrinkleProfile read_profile(JsonReader& object) {
    const std::string name = object.string("profile", "groove");
    if (name == "groove") return WrinkleProfile::Groove;
    if (name == "fold") return WrinkleProfile::Fold;
    if (name == "bulge") return WrinkleProfile::Bulge;
    if (name == "dimple") return WrinkleProfile::Dimple;
    object.at("profile").fail("groove, fold, bulge or dimple");
}

WrinkleSpec read_wrinkle(JsonReader item) {
    item = item.as_object();
    item.comment("why");
    WrinkleSpec w;
    w.name = item.string("name", "");
    w.profile = read_profile(item);
    const JsonReader points = item.at("points");
    for (const JsonReader& p : points.elements()) w.points.push_back(read_point(p));
    if (w.points.empty()) points.fail("at least one point");
    w.depth = read_number(item, "depth", w.depth, 0.0f, 1.0f);
    w.width = read_number(item, "width", w.width, 1e-3f, 1.0f);
    w.taper = read_number(item, "taper", w.taper, 0.0f, 0.5f);
    w.taper_end = read_number(item, "taper_end", w.taper, 0.0f, 0.9f);
    w.crease = item.has("crease") ? read_number(item, "crease", 0.0f, 0.0f, 1.0f) : -1.0f;
    w.count = item.has("count") ? item.integer_in("count", 1, 12) : 1;
    if (item.has("step")) w.step = read_vec2(item.at("step"));
    w.depth_falloff = read_number(item, "depth_falloff", 1.0f, 0.0f, 2.0f);
    w.side = read_number(item, "side", 1.0f, -1.0f, 1.0f) < 0.0f ? -1.0f : 1.0f;
    w.shoulder = item.has("shoulder") ? read_number(item, "shoulder", 0.0f, 0.0f, 1.0f) : -1.0f;
    w.asymmetry = item.has("asymmetry") ? read_number(item, "asymmetry", 0.0f, 0.0f, 0.8f) : -1.0f;
    item.finish();
    return w;
}

// ---------------------------------------------------------------- geometry

// A wrinkle copy resolved at a layout, in normalised texture units.
struct Stroke {
    WrinkleProfile profile;
    std::vector<glm::vec2> polyline;
    std::vector<float> arc;  // cumulative arc length at each polyline vertex
    std::vector<float> keep;  // depth factor at each vertex (1; less near the hairline)
    std::vector<float> along;  // the points' depth_factor at each vertex (depth and width)
    float depth, sigma, taper, taper_end, crease, side, shoulder, asymmetry;
    float swell_phase;  // where along the swell noise this stroke starts
    bool fine;          // a fine secondary line: a plain valley, no shoulders
    float split = 0.0f;  // +1 / -1: only the face's left / right half of it (an `across` wrinkle on one side)
    glm::vec2 box_min, box_max;
};

// Deterministic lattice value noise in [-1, 1].
float lattice(int x, int y, int octave) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u ^
                      static_cast<std::uint32_t>(octave) * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xffffu) / 32767.5f - 1.0f;
}

float smoothstep01(float x) {
    x = std::clamp(x, 0.0f, 1.0f);
    return x * x * (3.0f - 2.0f * x);
}

// Smooth 1D value noise in [-1, 1]; `seed` picks an independent row.
float noise1(float x, int seed) {
    const float fx = std::floor(x);
    const int ix = static_cast<int>(fx);
    const float t = smoothstep01(x - fx);
    const float a = lattice(ix, seed, 7), b = lattice(ix + 1, seed, 7);
    return a + (b - a) * t;
}

// A seeded random number in [0, 1) per (wrinkle, copy, purpose).
float random01(std::uint32_t seed, int copy, int purpose) {
    return 0.5f * (lattice(static_cast<int>(seed & 0x7fffffffu), copy, 100 + purpose) + 1.0f) * 0.99998f;
}

std::uint32_t name_seed(const std::string& name) {
    std::uint32_t h = 2166136261u;  // FNV-1a
    for (const char c : name) h = (h ^ static_cast<std::uint8_t>(c)) * 16777619u;
    return h;
}

glm::vec2 resolve(const AnchoredPoint& p, const FeatureLayout& layout, float unit) {
    const auto check = [&](int index) {
        if (!layout.present[index])
            fail("expression: wrinkle point needs feature point {}, which this face lacks",
                 fap::feature_points()[index].id);
        return layout.points[index];
    };
    glm::vec2 base = check(p.from);
    if (p.to >= 0) base += p.t * (check(p.to) - base);
    // Spec offsets are +y up the face; the image's y grows downwards.
    return base + unit * glm::vec2(p.offset.x, -p.offset.y);
}

constexpr int kSamplesPerSpan = 12;

std::vector<glm::vec2> catmull_rom(const std::vector<glm::vec2>& points) {
    if (points.size() < 3) return points;
    std::vector<glm::vec2> out;
    const int n = static_cast<int>(points.size());
    for (int i = 0; i + 1 < n; ++i) {
        const glm::vec2 p0 = points[std::max(i - 1, 0)], p1 = points[i], p2 = points[i + 1],
                        p3 = points[std::min(i + 2, n - 1)];
        for (int s = 0; s < kSamplesPerSpan; ++s) {
            const float t = static_cast<float>(s) / kSamplesPerSpan, t2 = t * t, t3 = t2 * t;
            out.push_back(0.5f * (2.0f * p1 + (p2 - p0) * t + (2.0f * p0 - 5.0f * p1 + 4.0f * p2 - p3) * t2 +
                                  (3.0f * p1 - p0 - 3.0f * p2 + p3) * t3));
        }
    }
    out.push_back(points.back());
    return out;
}

std::vector<float> arc_lengths(const std::vector<glm::vec2>& line) {
    std::vector<float> arc(line.size(), 0.0f);
    for (size_t i = 1; i < line.size(); ++i) arc[i] = arc[i - 1] + glm::distance(line[i - 1], line[i]);
    return arc;
}

// The part of a curve between arc fractions u0 < u1, resampled at even arc
// steps, so meander and swell are even along it.
constexpr int kSamples = 40;

std::vector<glm::vec2> resample(const std::vector<glm::vec2>& line, float u0, float u1) {
    const std::vector<float> arc = arc_lengths(line);
    const float total = arc.back();
    std::vector<glm::vec2> out;
    size_t seg = 0;
    for (int i = 0; i <= kSamples; ++i) {
        const float at = total * (u0 + (u1 - u0) * static_cast<float>(i) / kSamples);
        while (seg + 2 < line.size() && arc[seg + 1] < at) ++seg;
        const float len = arc[seg + 1] - arc[seg];
        const float t = len > 0.0f ? std::clamp((at - arc[seg]) / len, 0.0f, 1.0f) : 0.0f;
        out.push_back(line[seg] + t * (line[seg + 1] - line[seg]));
    }
    return out;
}

// Each vertex moved sideways (perpendicular to the curve) by offset(arc).
template <typename OffsetFn>
std::vector<glm::vec2> displace(const std::vector<glm::vec2>& line, OffsetFn&& offset) {
    const std::vector<float> arc = arc_lengths(line);
    std::vector<glm::vec2> out(line.size());
    for (size_t i = 0; i < line.size(); ++i) {
        const glm::vec2 a = line[i == 0 ? 0 : i - 1], b = line[std::min(i + 1, line.size() - 1)];
        const glm::vec2 d = b - a;
        const float len = glm::length(d);
        const glm::vec2 normal = len > 0.0f ? glm::vec2(-d.y, d.x) / len : glm::vec2(0.0f);
        out[i] = line[i] + offset(arc[i]) * normal;
    }
    return out;
}

Stroke make_stroke(WrinkleProfile profile, std::vector<glm::vec2> polyline, std::vector<float> along, float depth,
                   float sigma, float taper, float taper_end, float crease, float side, float shoulder,
                   float asymmetry, float swell_phase, bool fine, float reach) {
    Stroke s;
    s.profile = profile;
    s.polyline = std::move(polyline);
    s.arc = arc_lengths(s.polyline);
    s.keep.assign(s.polyline.size(), 1.0f);
    s.along = std::move(along);
    s.along.resize(s.polyline.size(), 1.0f);
    s.shoulder = shoulder;
    s.asymmetry = asymmetry;
    s.depth = depth;
    s.sigma = sigma;
    s.taper = taper;
    s.taper_end = taper_end;
    s.crease = crease;
    s.side = side;
    s.swell_phase = swell_phase;
    s.fine = fine;
    s.box_min = s.box_max = s.polyline[0];
    for (const glm::vec2& p : s.polyline) {
        s.box_min = glm::min(s.box_min, p);
        s.box_max = glm::max(s.box_max, p);
    }
    s.box_min -= glm::vec2(reach);
    s.box_max += glm::vec2(reach);
    return s;
}

// The points' depth_factor along a curve through them, by the curve's arc
// fraction: smooth (smoothstep) between the points, which the Catmull-Rom
// curve passes at every kSamplesPerSpan-th vertex.
struct DepthAlong {
    std::vector<float> at, factor;  // arc fraction of each point, its factor
    DepthAlong(const WrinkleSpec& spec, const std::vector<glm::vec2>& curve) {
        const std::vector<float> arc = arc_lengths(curve);
        const size_t n = spec.points.size();
        const size_t stride = n < 3 ? 1 : kSamplesPerSpan;
        for (size_t k = 0; k < n; ++k) {
            at.push_back(arc.back() > 0.0f ? arc[std::min(k * stride, arc.size() - 1)] / arc.back() : 0.0f);
            factor.push_back(spec.points[k].depth_factor);
        }
    }
    float operator()(float u) const {
        if (u <= at.front()) return factor.front();
        for (size_t k = 0; k + 1 < at.size(); ++k)
            if (u <= at[k + 1]) {
                const float span = at[k + 1] - at[k];
                const float t = span > 0.0f ? smoothstep01((u - at[k]) / span) : 1.0f;
                return factor[k] + t * (factor[k + 1] - factor[k]);
            }
        return factor.back();
    }
    // At n + 1 even steps over the arc fractions [u0, u1].
    std::vector<float> sample(float u0, float u1, int n) const {
        std::vector<float> out;
        for (int i = 0; i <= n; ++i) out.push_back((*this)(u0 + (u1 - u0) * static_cast<float>(i) / n));
        return out;
    }
};

// Appends the strokes of `specs` at `layout`, depths times `scale`, each
// limited to one half of the face by `split` (0: whole).
void resolve_strokes(const std::vector<WrinkleSpec>& specs, const FoldShape& shape, const FeatureLayout& layout,
                     float scale, float split, std::vector<Stroke>& strokes) {
    const float unit = layout.face_unit();
    const std::size_t first = strokes.size();
    for (const WrinkleSpec& spec : specs) {
        std::vector<glm::vec2> base;
        for (const AnchoredPoint& p : spec.points) base.push_back(resolve(p, layout, unit));
        const std::vector<glm::vec2> curve = catmull_rom(base);
        const std::uint32_t seed = name_seed(spec.name);
        const float sigma = spec.width * unit;
        const float taper_end = spec.taper_end < 0.0f ? spec.taper : spec.taper_end;
        const float crease = spec.crease < 0.0f ? shape.core : spec.crease;
        const float shoulder = spec.shoulder < 0.0f ? shape.shoulder : spec.shoulder;
        const float asymmetry = spec.asymmetry < 0.0f ? shape.asymmetry : spec.asymmetry;
        const DepthAlong depth_along(spec, curve);
        // A valley with its shoulders on the wide flank reaches this far.
        const float wide = 1.0f + asymmetry;
        const float reach = std::max(spec.profile == WrinkleProfile::Fold
                                         ? 8.5f * sigma
                                         : (shape.shoulder_offset + 3.0f * shape.shoulder_width) * wide * sigma,
                                     3.0f * shape.wall_width * wide * sigma);
        if (curve.size() == 1) {  // a round mark: no along-the-fold shape
            strokes.push_back(make_stroke(spec.profile, curve, {spec.points[0].depth_factor},
                                          scale * spec.depth * unit, sigma, 0.0f, 0.0f, crease, spec.side, shoulder,
                                          asymmetry, 0.0f, false, 3.0f * sigma));
            continue;
        }
        const bool varied = spec.count > 1;
        float depth = scale * spec.depth;
        glm::vec2 shift{0.0f};
        for (int copy = 0; copy < spec.count; ++copy, depth *= spec.depth_falloff) {
            // Parallel folds differ: spacing, length and depth each vary a
            // little, seeded by the wrinkle's name, so the result is
            // deterministic yet no two copies are the same stroke.
            if (copy > 0)
                shift += (1.0f + shape.copy_spacing * (2.0f * random01(seed, copy, 0) - 1.0f)) * unit *
                         glm::vec2(spec.step.x, -spec.step.y);
            const float u0 = varied ? shape.copy_length * random01(seed, copy, 1) : 0.0f;
            const float u1 = varied ? 1.0f - shape.copy_length * random01(seed, copy, 2) : 1.0f;
            const float copy_depth =
                depth * (varied ? 1.0f + shape.copy_depth * (2.0f * random01(seed, copy, 3) - 1.0f) : 1.0f);
            std::vector<glm::vec2> line = resample(curve, u0, u1);
            for (glm::vec2& p : line) p += shift;
            const int meander_row = static_cast<int>((seed >> 8) & 0xffff) + 31 * copy;
            const float wavelength = shape.meander_wavelength * unit;
            line = displace(line, [&](float at) { return shape.meander * sigma * noise1(at / wavelength, meander_row); });
            const float phase = 97.0f * random01(seed, copy, 4);
            if (spec.profile == WrinkleProfile::Groove && shape.fine_depth > 0.0f) {
                // The finer scale: one shallow line beside the fold, on a
                // seeded side, over a seeded stretch of its middle.
                const float side = random01(seed, copy, 5) < 0.5f ? -1.0f : 1.0f;
                const float start = (1.0f - shape.fine_length) * random01(seed, copy, 6);
                std::vector<glm::vec2> fine = resample(line, start, start + shape.fine_length);
                fine = displace(fine, [&](float) { return side * shape.fine_offset * sigma; });
                const float f0 = u0 + (u1 - u0) * start, f1 = u0 + (u1 - u0) * (start + shape.fine_length);
                strokes.push_back(make_stroke(WrinkleProfile::Groove, std::move(fine),
                                              depth_along.sample(f0, f1, kSamples),
                                              shape.fine_depth * copy_depth * unit, shape.fine_width * sigma, 0.4f,
                                              0.4f, 0.0f, spec.side, 0.0f, asymmetry, phase + 13.0f, true,
                                              3.0f * shape.fine_width * sigma));
            }
            strokes.push_back(make_stroke(spec.profile, std::move(line), depth_along.sample(u0, u1, kSamples),
                                          copy_depth * unit, sigma, spec.taper, taper_end, crease, spec.side,
                                          shoulder, asymmetry, phase, false, reach));
        }
    }
    for (std::size_t i = first; i < strokes.size(); ++i) strokes[i].split = split;
}

// A Gaussian that reaches exactly zero at 3 sigma, so skin away from a
// wrinkle stays exactly flat.
float bump(float d, float sigma) {
    const float x = std::abs(d) / sigma;
    if (x >= 3.0f) return 0.0f;
    constexpr float kTail = 0.011108996538f;  // exp(-4.5)
    return (std::exp(-0.5f * x * x) - kTail) / (1.0f - kTail);
}

float stroke_height(const Stroke& s, const FoldShape& shape, float unit, glm::vec2 x) {
    float best = 1e30f, signed_best = 0.0f, arc_at = 0.0f, keep = 1.0f, along = 1.0f;
    if (s.polyline.size() == 1) {
        best = glm::distance(x, s.polyline[0]);
    } else {
        for (size_t i = 0; i + 1 < s.polyline.size(); ++i) {
            const glm::vec2 a = s.polyline[i], ab = s.polyline[i + 1] - a;
            const float len2 = glm::dot(ab, ab);
            const float t = len2 > 0.0f ? std::clamp(glm::dot(x - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
            const float d = glm::distance(x, a + t * ab);
            if (d < best) {
                best = d;
                arc_at = s.arc[i] + t * (s.arc[i + 1] - s.arc[i]);
                keep = s.keep[i] + t * (s.keep[i + 1] - s.keep[i]);
                along = s.along[i] + t * (s.along[i + 1] - s.along[i]);
                // Image y points down: a positive cross is the face's-left side of travel.
                const float cross = ab.x * (x.y - a.y) - ab.y * (x.x - a.x);
                signed_best = cross >= 0.0f ? d : -d;
            }
        }
    }
    if (s.polyline.size() == 1) {
        switch (s.profile) {
            case WrinkleProfile::Bulge: return s.along[0] * s.depth * bump(best, s.sigma);
            default: return -s.along[0] * s.depth * bump(best, s.sigma);
        }
    }
    // Along the fold: depth fades in smoothly at both ends and follows the
    // points' depth factors, the width narrows with it (no blunt ends), and
    // the depth swells and thins gently.
    float window = along;
    const float u = arc_at / std::max(s.arc.back(), 1e-12f);
    if (s.taper > 0.0f) window *= smoothstep01(u / s.taper);
    if (s.taper_end > 0.0f) window *= smoothstep01((1.0f - u) / s.taper_end);
    if (window <= 0.0f) return 0.0f;
    const float swell = 1.0f + shape.swell * noise1(arc_at / (shape.meander_wavelength * unit) + s.swell_phase, 3);
    const float depth = s.depth * window * swell * keep;
    const float sigma = s.sigma * (shape.width_taper + (1.0f - shape.width_taper) * std::sqrt(window));
    if (s.fine) return -depth * bump(best, sigma);
    // Across: the flank on the `side` of the curve is steeper than the other.
    const bool steep = s.side * signed_best >= 0.0f;
    const float flank = sigma * (steep ? 1.0f - s.asymmetry : 1.0f + s.asymmetry);
    // The valley: a sharp narrow core (dark in its cavity) in broad shallow
    // walls, so the wall that faces the light catches little of it.
    const float valley = s.crease * bump(best, shape.core_width * flank) +
                         (1.0f - s.crease) * bump(best, shape.wall_width * flank);
    switch (s.profile) {
        case WrinkleProfile::Groove:
        case WrinkleProfile::Dimple:
            // Compressed skin buckles into a narrow valley with broad rounded
            // crests beside it (FIDELITY.md 6, HARR).
            // The skin bunches higher beside the steep flank than the gentle one.
            return depth * (-valley + s.shoulder * (steep ? 1.0f + 0.5f * s.asymmetry : 1.0f - 0.5f * s.asymmetry) *
                                          bump(best - shape.shoulder_offset * flank, shape.shoulder_width * flank));
        case WrinkleProfile::Bulge:
            return depth * bump(best, sigma);
        case WrinkleProfile::Fold: {
            // The cheek rounds broadly over the `side` flank; the other keeps
            // a small shoulder. The cheek's rise reaches 8 sigma out, so it
            // fades in over at least kRiseTaper of the fold's length: faded
            // in over the valley's short taper (a nasolabial fold starts
            // deep at the nose wing), its edge ran from the fold's top out
            // across the cheek as a line (joy: a streak from the nose wing
            // towards the outer eye corner, blind review round 14).
            constexpr float kRiseTaper = 0.4f;
            const float valley_fade = s.taper > 0.0f ? smoothstep01(u / s.taper) : 1.0f;  // in `window`
            const float rise = std::min(smoothstep01(u / std::max(s.taper, kRiseTaper)) / valley_fade, 1.0f);
            return depth * (-valley + 0.55f * rise * bump(s.side * signed_best - 2.5f * sigma, 2.0f * sigma) +
                            0.5f * s.shoulder *
                                bump(-s.side * signed_best - shape.shoulder_offset * flank,
                                     shape.shoulder_width * flank));
        }
    }
    return 0.0f;
}

float value_noise(glm::vec2 p, int octave) {
    const float fx = std::floor(p.x), fy = std::floor(p.y);
    const int ix = static_cast<int>(fx), iy = static_cast<int>(fy);
    const float tx = smoothstep01(p.x - fx), ty = smoothstep01(p.y - fy);
    const float a = lattice(ix, iy, octave), b = lattice(ix + 1, iy, octave);
    const float c = lattice(ix, iy + 1, octave), d = lattice(ix + 1, iy + 1, octave);
    return (a + (b - a) * tx) + ((c + (d - c) * tx) - (a + (b - a) * tx)) * ty;
}

// Fine skin detail only inside the face: an ellipse from hairline to chin
// and jaw corner to jaw corner, fading out at its rim.
struct SkinMask {
    glm::vec2 centre{0.0f}, radius{0.0f};
    bool valid = false;
    explicit SkinMask(const FeatureLayout& layout) {
        const auto idx = [](const char* id) { return fap::feature_point_index(id); };
        const int top = idx("11.1"), chin = idx("2.1"), left = idx("2.13"), right = idx("2.14");
        if (!(layout.present[top] && layout.present[chin] && layout.present[left] && layout.present[right]))
            return;
        centre = 0.5f * (layout.points[top] + layout.points[chin]);
        radius = {0.5f * std::abs(layout.points[left].x - layout.points[right].x),
                  0.5f * std::abs(layout.points[chin].y - layout.points[top].y)};
        valid = radius.x > 0.0f && radius.y > 0.0f;
    }
    float weight(glm::vec2 x) const {
        if (!valid) return 0.0f;
        const glm::vec2 q = (x - centre) / radius;
        return smoothstep01((1.0f - glm::length(q)) / 0.15f);
    }
};

// Where wrinkles may be: below the hairline (a polyline through the hair
// border points 11.2, 11.1, 11.3, flat beyond its ends) and inside the map.
// A fold reaching the hair fades out over `fade` below the hairline (by its
// centreline, so it tapers along its length), and no height at all lands on
// or above the hairline (by pixel).
struct WrinkleArea {
    std::vector<glm::vec2> hairline;  // sorted by x
    float fade = 0.0f, edge = 0.0f;
    explicit WrinkleArea(const FeatureLayout& layout) {
        for (const char* id : {"11.2", "11.1", "11.3"}) {
            const int i = fap::feature_point_index(id);
            if (layout.present[i]) hairline.push_back(layout.points[i]);
        }
        std::sort(hairline.begin(), hairline.end(), [](glm::vec2 a, glm::vec2 b) { return a.x < b.x; });
        fade = 0.12f * layout.face_unit();
        edge = 0.03f * layout.face_unit();
    }
    float hair_y(float x) const {
        if (hairline.empty()) return -1e30f;
        if (x <= hairline.front().x) return hairline.front().y;
        for (size_t i = 0; i + 1 < hairline.size(); ++i)
            if (x <= hairline[i + 1].x) {
                const float span = hairline[i + 1].x - hairline[i].x;
                const float t = span > 0.0f ? (x - hairline[i].x) / span : 0.0f;
                return hairline[i].y + t * (hairline[i + 1].y - hairline[i].y);
            }
        return hairline.back().y;
    }
    // For a fold's centreline point: 1 well below the hairline, 0 at it.
    float centreline(glm::vec2 p) const { return smoothstep01((p.y - hair_y(p.x)) / fade); }
    // For any pixel: 0 on or above the hairline and at the map's edge.
    float pixel(glm::vec2 p) const {
        const float to_edge = std::min({p.x, 1.0f - p.x, p.y, 1.0f - p.y});
        return smoothstep01((p.y - hair_y(p.x)) / (0.3f * fade)) * smoothstep01(to_edge / edge);
    }
};

// The face's midline, x at each image row: the polyline through the midline
// points the face has; a wrinkle `across` it given to one side fades over
// `blend` on either side of it, the two sides' weights summing to 1.
struct Midline {
    std::vector<glm::vec2> points;  // sorted by y
    float blend = 0.0f;
    explicit Midline(const FeatureLayout& layout) {
        for (const char* id : {"11.1", "8.1", "8.2", "2.10", "2.1"}) {
            const int i = fap::feature_point_index(id);
            if (layout.present[i]) points.push_back(layout.points[i]);
        }
        std::sort(points.begin(), points.end(), [](glm::vec2 a, glm::vec2 b) { return a.y < b.y; });
        blend = 0.04f * layout.face_unit();
    }
    float x_at(float y) const {
        if (points.empty()) return 0.5f;
        if (y <= points.front().y) return points.front().x;
        for (size_t i = 0; i + 1 < points.size(); ++i)
            if (y <= points[i + 1].y) {
                const float span = points[i + 1].y - points[i].y;
                const float t = span > 0.0f ? (y - points[i].y) / span : 0.0f;
                return points[i].x + t * (points[i + 1].x - points[i].x);
            }
        return points.back().x;
    }
    // The share of a wrinkle at `p` that belongs to `split`'s side (the
    // face's left is the image's right).
    float weight(glm::vec2 p, float split) const {
        if (split == 0.0f) return 1.0f;
        return smoothstep01(0.5f + split * (p.x - x_at(p.y)) / (2.0f * blend));
    }
};

// The strokes of a key's sources at `layout`.
std::vector<Stroke> key_strokes(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                                const FeatureLayout& layout) {
    std::vector<Stroke> strokes;
    // The neutral key is the resting face: its lines stay under every AU
    // key, which adds its own on top (render::key_weights keeps neutral at 1).
    static const WrinkleSources resting{kRestingLinesSource};
    for (const WrinkleSource& source : sources.empty() ? resting : sources) {
        const AuWrinkles* au = spec.find(source.au);
        if (!au || source.intensity <= 0.0f) continue;
        // A side's wrinkles stay on its half (a glabella furrow's shoulder
        // fades out at the midline), so a one-sided AU leaves the other half
        // flat and the two halves of an AU sum to the whole AU.
        const bool left = source.side != AuSide::Right, right = source.side != AuSide::Left;
        if (left) resolve_strokes(au->left, spec.fold, layout, source.intensity, 1.0f, strokes);
        if (right) resolve_strokes(au->right, spec.fold, layout, source.intensity, -1.0f, strokes);
        const float split = source.side == AuSide::Both ? 0.0f : (left ? 1.0f : -1.0f);
        resolve_strokes(au->across, spec.fold, layout, source.intensity, split, strokes);
    }
    return strokes;
}

// Rows on the shared pool, a few at a time; each row is written by one call.
template <typename RowFn>
void for_each_row_band(int rows, RowFn&& fn) {
    parallel_for(rows, 8, [&](int begin, int end) {
        for (int row = begin; row < end; ++row) fn(row);
    });
}

}  // namespace

const AuWrinkles* WrinkleLibrarySpec::find(int au) const {
    if (au == kRestingLines) return resting.empty() ? nullptr : &resting;
    for (const AuWrinkles& a : action_units)
        if (a.au == au) return &a;
    return nullptr;
}

namespace {

// An AU's entry, or the resting lines': its "left", "right" and "across" lists.
AuWrinkles read_sided_wrinkles(const JsonReader& value, int au_number) {
    JsonReader entry = value.as_object();
    entry.comment("why");
    AuWrinkles w;
    w.au = au_number;
    const auto read_list = [&](const char* key, std::vector<WrinkleSpec>& out) {
        if (!entry.has(key)) return;
        for (const JsonReader& item : entry.at(key).elements()) out.push_back(read_wrinkle(item));
    };
    read_list("left", w.left);
    read_list("right", w.right);
    read_list("across", w.across);
    entry.finish();
    if (w.empty()) entry.fail("wrinkles in \"left\", \"right\" or \"across\"");
    return w;
}

}  // namespace

WrinkleLibrarySpec load_wrinkle_spec(const std::string& path) {
    return detail::read_json_file(path, [](JsonReader& root) {
        root.comment("about");
        WrinkleLibrarySpec spec;
        JsonReader units = root.object("action_units");
        for (auto& [name, value] : units.entries()) {
            std::string error;
            const std::optional<AuTerm> term = parse_au_term(name, &error);
            if (!term || term->side != AuSide::Both)
                fail<InputError>("expression: {}: expected an AU such as \"AU4\" as the key (its sides are its "
                                 "\"left\" and \"right\" lists), found \"{}\"",
                                 value.loc().str(), name);
            if (spec.find(term->number))
                fail<InputError>("expression: {}: expected each AU once, found AU{} again", value.loc().str(),
                                 term->number);
            spec.action_units.push_back(read_sided_wrinkles(value, term->number));
        }
        if (root.has("resting")) spec.resting = read_sided_wrinkles(root.at("resting"), kRestingLines);
        if (root.has("fold_shape")) {
            JsonReader f = root.object("fold_shape");
            f.comment("why");
            FoldShape& fs = spec.fold;
            fs.shoulder = read_number(f, "shoulder", fs.shoulder, 0.0f, 1.0f);
            fs.shoulder_offset = read_number(f, "shoulder_offset", fs.shoulder_offset, 0.5f, 5.0f);
            fs.shoulder_width = read_number(f, "shoulder_width", fs.shoulder_width, 0.2f, 3.0f);
            fs.asymmetry = read_number(f, "asymmetry", fs.asymmetry, 0.0f, 0.8f);
            fs.core = read_number(f, "core", fs.core, 0.0f, 1.0f);
            fs.core_width = read_number(f, "core_width", fs.core_width, 0.1f, 1.0f);
            fs.wall_width = read_number(f, "wall_width", fs.wall_width, 1.0f, 3.0f);
            fs.meander = read_number(f, "meander", fs.meander, 0.0f, 3.0f);
            fs.meander_wavelength = read_number(f, "meander_wavelength", fs.meander_wavelength, 0.01f, 2.0f);
            fs.swell = read_number(f, "swell", fs.swell, 0.0f, 0.9f);
            fs.width_taper = read_number(f, "width_taper", fs.width_taper, 0.05f, 1.0f);
            fs.copy_length = read_number(f, "copy_length", fs.copy_length, 0.0f, 0.45f);
            fs.copy_depth = read_number(f, "copy_depth", fs.copy_depth, 0.0f, 0.9f);
            fs.copy_spacing = read_number(f, "copy_spacing", fs.copy_spacing, 0.0f, 0.9f);
            fs.fine_depth = read_number(f, "fine_depth", fs.fine_depth, 0.0f, 1.0f);
            fs.fine_width = read_number(f, "fine_width", fs.fine_width, 0.1f, 1.0f);
            fs.fine_offset = read_number(f, "fine_offset", fs.fine_offset, 1.0f, 8.0f);
            fs.fine_length = read_number(f, "fine_length", fs.fine_length, 0.1f, 1.0f);
            f.finish();
        }
        if (root.has("cavity")) {
            JsonReader c = root.object("cavity");
            c.comment("why");
            spec.cavity.full_depth = read_number(c, "full_depth", spec.cavity.full_depth, 1e-4f, 1.0f);
            spec.cavity.darkest = read_number(c, "darkest", spec.cavity.darkest, 0.0f, 1.0f);
            spec.cavity.radius = read_number(c, "radius", spec.cavity.radius, 1e-3f, 0.5f);
            c.finish();
        }
        if (root.has("neutral_skin_detail")) {
            JsonReader d = root.object("neutral_skin_detail");
            spec.neutral_detail.amplitude = read_number(d, "amplitude", 0.0f, 0.0f, 0.05f);
            spec.neutral_detail.scale = read_number(d, "scale", 0.02f, 1e-3f, 1.0f);
            spec.neutral_detail.octaves = d.has("octaves") ? d.integer_in("octaves", 1, 6) : 3;
            d.finish();
        }
        return spec;
    });
}

WrinkleRegion wrinkle_region(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                             const FeatureLayout& layout) {
    if (sources.empty()) return {};
    WrinkleRegion r{glm::vec2(1.0f), glm::vec2(0.0f)};
    for (const Stroke& s : key_strokes(spec, sources, layout)) {
        r.min = glm::min(r.min, s.box_min);
        r.max = glm::max(r.max, s.box_max);
    }
    r.min = glm::clamp(r.min, 0.0f, 1.0f);
    r.max = glm::clamp(r.max, 0.0f, 1.0f);
    return r;
}

namespace {

// A key's height field and, when asked, the same wrinkles by how the midline
// shares them: parts[split + 1] holds the strokes of that split (-1, 0, +1)
// at full strength, before the share. A valley's depth below its
// surroundings is measured on these whole wrinkles and shared afterwards, so
// the halves of a wrinkle split between AU9L and AU9R have cavities that
// add up to the whole wrinkle's (measured on a half, the missing other half
// reads as open skin and darkens the midline).
struct KeyFields {
    std::vector<float> height;
    std::array<std::vector<float>, 3> parts;  // empty where no stroke has that split
};

KeyFields render_fields(const WrinkleLibrarySpec& spec, const WrinkleSources& sources, const FeatureLayout& layout,
                        int size, bool with_parts) {
    if (size < 16 || size > 8192)
        fail<InputError>("expression: render_height_field(): size must be in [16, 8192], found {}", size);
    std::vector<Stroke> strokes = key_strokes(spec, sources, layout);
    const WrinkleArea area(layout);
    const Midline midline(layout);
    for (Stroke& s : strokes) {
        // A fold fades along its length as its centreline nears the hair,
        // so it thins out before the hairline instead of being cut there.
        for (size_t i = 0; i < s.polyline.size(); ++i) s.keep[i] = area.centreline(s.polyline[i]);
        if (s.polyline.size() == 1) s.depth *= s.keep[0];
    }
    strokes.erase(std::remove_if(strokes.begin(), strokes.end(),
                                 [](const Stroke& s) {
                                     return std::all_of(s.keep.begin(), s.keep.end(), [](float k) { return k <= 0.0f; });
                                 }),
                  strokes.end());
    const bool detail = sources.empty() && spec.neutral_detail.amplitude > 0.0f;
    const SkinMask mask(layout);
    const float unit = layout.face_unit();
    KeyFields fields;
    fields.height.assign(static_cast<size_t>(size) * size, 0.0f);
    if (with_parts) {
        for (const Stroke& s : strokes) fields.parts[static_cast<int>(s.split) + 1].assign(fields.height.size(), 0.0f);
        if (detail) fields.parts[1].assign(fields.height.size(), 0.0f);
    }
    std::vector<float>& height = fields.height;
    const float inv = 1.0f / static_cast<float>(size);
    for_each_row_band(size, [&](int row) {
        const float y = (row + 0.5f) * inv;
        const size_t row_start = static_cast<size_t>(row) * size;
        float* out = height.data() + row_start;
        for (const Stroke& s : strokes) {
            if (y < s.box_min.y || y > s.box_max.y) continue;
            const int c0 = std::max(0, static_cast<int>(std::floor(s.box_min.x * size)));
            const int c1 = std::min(size - 1, static_cast<int>(std::ceil(s.box_max.x * size)));
            float* part = with_parts ? fields.parts[static_cast<int>(s.split) + 1].data() + row_start : nullptr;
            for (int col = c0; col <= c1; ++col) {
                const glm::vec2 x{(col + 0.5f) * inv, y};
                const float share = midline.weight(x, s.split);
                if (share <= 0.0f && !part) continue;
                const float h = stroke_height(s, spec.fold, unit, x);
                out[col] += share * h;
                if (part) part[col] += h;
            }
        }
        if (detail) {
            const SkinDetail& d = spec.neutral_detail;
            for (int col = 0; col < size; ++col) {
                const glm::vec2 x{(col + 0.5f) * inv, y};
                const float w = mask.weight(x);
                if (w <= 0.0f) continue;
                float n = 0.0f, amplitude = d.amplitude * unit, cell = d.scale * unit;
                for (int o = 0; o < d.octaves; ++o, amplitude *= 0.5f, cell *= 0.5f)
                    n += amplitude * value_noise(x / cell, o);
                out[col] += w * n;
                if (with_parts) fields.parts[1][row_start + col] += w * n;
            }
        }
        // Wrinkles and skin detail alike stop below the hairline.
        for (int col = 0; col < size; ++col) {
            const float keep = area.pixel({(col + 0.5f) * inv, y});
            if (out[col] != 0.0f) out[col] *= keep;
            for (std::vector<float>& part : fields.parts)
                if (!part.empty()) part[row_start + col] *= keep;
        }
    });
    return fields;
}

// Box-filters `line` (n values, `stride` apart) in place, `passes` times,
// each a running mean over 2 r + 1 values with the ends held: three passes
// are close to a Gaussian of sigma r.
void box_blur_line(float* line, int n, int stride, int r, int passes, std::vector<float>& scratch) {
    scratch.resize(static_cast<size_t>(n));
    const float inv = 1.0f / static_cast<float>(2 * r + 1);
    for (int pass = 0; pass < passes; ++pass) {
        for (int i = 0; i < n; ++i) scratch[i] = line[static_cast<size_t>(i) * stride];
        const auto at = [&](int i) { return scratch[std::clamp(i, 0, n - 1)]; };
        float sum = 0.0f;
        for (int i = -r; i <= r; ++i) sum += at(i);
        for (int i = 0; i < n; ++i) {
            line[static_cast<size_t>(i) * stride] = sum * inv;
            sum += at(i + r + 1) - at(i - r);
        }
    }
}

// How far each point of `field` lies below its surroundings (a Gaussian
// of sigma `blur` px: three box passes), over the window [w0, w1] x [h0, h1],
// row-major in the window.
std::vector<float> depth_below_surroundings(const std::vector<float>& field, int size, int blur, int w0, int w1,
                                            int h0, int h1) {
    const int ww = w1 - w0 + 1, wh = h1 - h0 + 1;
    std::vector<float> around(static_cast<size_t>(ww) * wh);
    for (int r = h0; r <= h1; ++r)
        std::memcpy(&around[static_cast<size_t>(r - h0) * ww], &field[static_cast<size_t>(r) * size + w0],
                    sizeof(float) * static_cast<size_t>(ww));
    parallel_for(wh, 16, [&](int begin, int end) {
        std::vector<float> scratch;
        for (int r = begin; r < end; ++r) box_blur_line(&around[static_cast<size_t>(r) * ww], ww, 1, blur, 3, scratch);
    });
    parallel_for(ww, 16, [&](int begin, int end) {
        std::vector<float> scratch;
        for (int c = begin; c < end; ++c) box_blur_line(&around[static_cast<size_t>(c)], wh, ww, blur, 3, scratch);
    });
    for (int r = h0; r <= h1; ++r)
        for (int c = w0; c <= w1; ++c)
            around[static_cast<size_t>(r - h0) * ww + (c - w0)] -= field[static_cast<size_t>(r) * size + c];
    return around;
}

// The normal map of `height` with its cavity in alpha; `below(r, c)` says
// how far a point lies below its surroundings (in the window the caller
// measured: the region and the blur's reach around it).
template <typename BelowFn>
NormalMap encode_normal_map(const std::vector<float>& height, int size, float face_unit, const CavitySpec& cavity,
                            const WrinkleRegion& region, BelowFn&& below);

// The window around `region` (one pixel more, for the differences) and the
// blur's reach beyond it, at `size`.
struct CavityWindow {
    int c0, c1, r0, r1;  // the region
    int blur;
    int w0, w1, h0, h1;  // the window measured
    CavityWindow(const WrinkleRegion& region, int size, float face_unit, const CavitySpec& cavity) {
        c0 = std::max(0, static_cast<int>(std::floor(region.min.x * size)) - 1);
        c1 = std::min(size - 1, static_cast<int>(std::ceil(region.max.x * size)) + 1);
        r0 = std::max(0, static_cast<int>(std::floor(region.min.y * size)) - 1);
        r1 = std::min(size - 1, static_cast<int>(std::ceil(region.max.y * size)) + 1);
        blur = std::max(1, static_cast<int>(std::lround(cavity.radius * face_unit * size)));
        w0 = std::max(0, c0 - 3 * blur), w1 = std::min(size - 1, c1 + 3 * blur);
        h0 = std::max(0, r0 - 3 * blur), h1 = std::min(size - 1, r1 + 3 * blur);
    }
    size_t at(int r, int c) const { return static_cast<size_t>(r - h0) * (w1 - w0 + 1) + (c - w0); }
};

}  // namespace

namespace {

template <typename BelowFn>
NormalMap encode_normal_map(const std::vector<float>& height, int size, float face_unit, const CavitySpec& cavity,
                            const WrinkleRegion& region, BelowFn&& below) {
    // Heights and positions share normalised units; the cavity's lengths
    // are in face units.
    const float full_depth = cavity.full_depth * face_unit;
    NormalMap map;
    map.width = map.height = size;
    map.rgba.resize(static_cast<size_t>(size) * size * 4);
    // Outside the region the height is 0 and so are its differences: flat.
    for (size_t i = 0; i < map.rgba.size(); i += 4) {
        map.rgba[i] = map.rgba[i + 1] = 128;
        map.rgba[i + 2] = map.rgba[i + 3] = 255;
    }
    if (region.empty()) return map;
    const CavityWindow win(region, size, face_unit, cavity);
    const float scale = static_cast<float>(size) * 0.5f;  // central difference over 2 px of 1/size
    const auto at = [&](int r, int c) {
        r = std::clamp(r, 0, size - 1);
        c = std::clamp(c, 0, size - 1);
        return height[static_cast<size_t>(r) * size + c];
    };
    const auto encode = [](float v) {
        return static_cast<std::uint8_t>(std::clamp(std::lround((0.5f + 0.5f * v) * 255.0f), 0L, 255L));
    };
    for_each_row_band(win.r1 - win.r0 + 1, [&](int band_row) {
        const int r = win.r0 + band_row;
        for (int c = win.c0; c <= win.c1; ++c) {
            const float dx = (at(r, c + 1) - at(r, c - 1)) * scale;
            const float dy = (at(r + 1, c) - at(r - 1, c)) * scale;
            const float len = std::sqrt(dx * dx + dy * dy + 1.0f);
            std::uint8_t* px = &map.rgba[(static_cast<size_t>(r) * size + c) * 4];
            px[0] = encode(-dx / len);
            px[1] = encode(-dy / len);
            px[2] = encode(1.0f / len);
            // The cavity: only valleys occlude, by how far they lie below
            // the skin around them. Linear, not saturating at full_depth, so
            // the keys' cavities add up in the morph as their heights do.
            if (height[static_cast<size_t>(r) * size + c] >= 0.0f) {
                px[3] = 255;
                continue;
            }
            const float occlusion = std::max(below(win, r, c) / full_depth, 0.0f);
            px[3] = encode(2.0f * std::max(1.0f - (1.0f - cavity.darkest) * occlusion, 0.0f) - 1.0f);
        }
    });
    return map;
}

}  // namespace

std::vector<float> render_height_field(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                                       const FeatureLayout& layout, int size) {
    return render_fields(spec, sources, layout, size, false).height;
}

NormalMap height_to_normal_map(const std::vector<float>& height, int size, float face_unit,
                               const CavitySpec& cavity, const WrinkleRegion& region) {
    // The skin around each point (a Gaussian of sigma cavity.radius): how far
    // a valley floor lies below it is how enclosed it is. A narrow crease
    // is nearly as deep below its surroundings as it is deep, and dark; a
    // broad shallow fold of the same depth lies in its own walls, and stays
    // open.
    std::vector<float> below;
    if (!region.empty()) {
        const CavityWindow w(region, size, face_unit, cavity);
        below = depth_below_surroundings(height, size, w.blur, w.w0, w.w1, w.h0, w.h1);
    }
    return encode_normal_map(height, size, face_unit, cavity, region,
                             [&](const CavityWindow& w, int r, int c) { return below[w.at(r, c)]; });
}

NormalMap generate_wrinkle_map(const WrinkleLibrarySpec& spec, const WrinkleSources& sources,
                               const FeatureLayout& layout, int size) {
    if (size < 256 || size > 4096)
        fail<InputError>("expression: generate_wrinkle_map(): size must be in [256, 4096], found {}", size);
    const KeyFields fields = render_fields(spec, sources, layout, size, true);
    const WrinkleRegion region = wrinkle_region(spec, sources, layout);
    const float unit = layout.face_unit();
    // Each part's depth below its surroundings, measured on whole wrinkles,
    // then shared at the midline as the heights are.
    std::array<std::vector<float>, 3> below;
    if (!region.empty()) {
        const CavityWindow w(region, size, unit, spec.cavity);
        for (int k = 0; k < 3; ++k)
            if (!fields.parts[k].empty())
                below[k] = depth_below_surroundings(fields.parts[k], size, w.blur, w.w0, w.w1, w.h0, w.h1);
    }
    const Midline midline(layout);
    const float inv = 1.0f / static_cast<float>(size);
    return encode_normal_map(fields.height, size, unit, spec.cavity, region, [&](const CavityWindow& w, int r, int c) {
        const glm::vec2 x{(c + 0.5f) * inv, (r + 0.5f) * inv};
        float sum = 0.0f;
        for (int k = 0; k < 3; ++k)
            if (!below[k].empty()) sum += midline.weight(x, static_cast<float>(k - 1)) * below[k][w.at(r, c)];
        return sum;
    });
}

}  // namespace emoface::expression
