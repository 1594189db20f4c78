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

constexpr std::array<const char*, kWrinkleKeyCount> kKeyNames = {
    "neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise"};

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
    w.count = item.has("count") ? item.integer_in("count", 1, 12) : 1;
    if (item.has("step")) w.step = read_vec2(item.at("step"));
    w.depth_falloff = read_number(item, "depth_falloff", 1.0f, 0.0f, 2.0f);
    w.side = read_number(item, "side", 1.0f, -1.0f, 1.0f) < 0.0f ? -1.0f : 1.0f;
    item.finish();
    return w;
}

// ---------------------------------------------------------------- geometry

// A wrinkle copy resolved at a layout, in normalised texture units.
struct Stroke {
    WrinkleProfile profile;
    std::vector<glm::vec2> polyline;
    std::vector<float> arc;  // cumulative arc length at each polyline vertex
    float depth, sigma, taper, side;
    glm::vec2 box_min, box_max;
};

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

std::vector<glm::vec2> catmull_rom(const std::vector<glm::vec2>& points) {
    if (points.size() < 3) return points;
    constexpr int kSamplesPerSpan = 12;
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

std::vector<Stroke> resolve_strokes(const std::vector<WrinkleSpec>& specs, const FeatureLayout& layout) {
    const float unit = layout.face_unit();
    std::vector<Stroke> strokes;
    for (const WrinkleSpec& spec : specs) {
        std::vector<glm::vec2> base;
        for (const AnchoredPoint& p : spec.points) base.push_back(resolve(p, layout, unit));
        const std::vector<glm::vec2> curve = catmull_rom(base);
        float depth = spec.depth;
        for (int copy = 0; copy < spec.count; ++copy, depth *= spec.depth_falloff) {
            Stroke s;
            s.profile = spec.profile;
            const glm::vec2 shift = static_cast<float>(copy) * unit * glm::vec2(spec.step.x, -spec.step.y);
            for (const glm::vec2& p : curve) s.polyline.push_back(p + shift);
            s.arc.assign(s.polyline.size(), 0.0f);
            for (size_t i = 1; i < s.polyline.size(); ++i)
                s.arc[i] = s.arc[i - 1] + glm::distance(s.polyline[i - 1], s.polyline[i]);
            s.depth = depth * unit;
            s.sigma = spec.width * unit;
            s.taper = spec.taper;
            s.side = spec.side;
            const float reach = (spec.profile == WrinkleProfile::Fold ? 5.0f : 3.0f) * s.sigma;
            s.box_min = s.box_max = s.polyline[0];
            for (const glm::vec2& p : s.polyline) {
                s.box_min = glm::min(s.box_min, p);
                s.box_max = glm::max(s.box_max, p);
            }
            s.box_min -= glm::vec2(reach);
            s.box_max += glm::vec2(reach);
            strokes.push_back(std::move(s));
        }
    }
    return strokes;
}

// A Gaussian that reaches exactly zero at 3 sigma, so skin away from a
// wrinkle stays exactly flat.
float bump(float d, float sigma) {
    const float x = d / sigma;
    if (x >= 3.0f) return 0.0f;
    constexpr float kTail = 0.011108996538f;  // exp(-4.5)
    return (std::exp(-0.5f * x * x) - kTail) / (1.0f - kTail);
}

float smoothstep01(float x) {
    x = std::clamp(x, 0.0f, 1.0f);
    return x * x * (3.0f - 2.0f * x);
}

float stroke_height(const Stroke& s, glm::vec2 x) {
    float best = 1e30f, signed_best = 0.0f, arc_at = 0.0f;
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
                // Image y points down: a positive cross is the face's-left side of travel.
                const float cross = ab.x * (x.y - a.y) - ab.y * (x.x - a.x);
                signed_best = cross >= 0.0f ? d : -d;
            }
        }
    }
    float window = 1.0f;
    if (s.polyline.size() > 1 && s.taper > 0.0f) {
        const float u = arc_at / std::max(s.arc.back(), 1e-12f);
        window = smoothstep01(u / s.taper) * smoothstep01((1.0f - u) / s.taper);
    }
    switch (s.profile) {
        case WrinkleProfile::Groove:
        case WrinkleProfile::Dimple:
            return -s.depth * window * bump(best, s.sigma);
        case WrinkleProfile::Bulge:
            return s.depth * window * bump(best, s.sigma);
        case WrinkleProfile::Fold:
            return s.depth * window *
                   (-bump(best, s.sigma) + 0.5f * bump(s.side * signed_best - 2.0f * s.sigma, 1.5f * s.sigma));
    }
    return 0.0f;
}

// Deterministic lattice value noise in [-1, 1].
float lattice(int x, int y, int octave) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 0x8da6b343u ^ static_cast<std::uint32_t>(y) * 0xd8163841u ^
                      static_cast<std::uint32_t>(octave) * 0xcb1ab31fu;
    h ^= h >> 13;
    h *= 0x5bd1e995u;
    h ^= h >> 15;
    return static_cast<float>(h & 0xffffu) / 32767.5f - 1.0f;
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

// Rows on the shared pool, a few at a time; each row is written by one call.
template <typename RowFn>
void for_each_row_band(int rows, RowFn&& fn) {
    parallel_for(rows, 8, [&](int begin, int end) {
        for (int row = begin; row < end; ++row) fn(row);
    });
}

}  // namespace

const char* wrinkle_key_name(WrinkleKey key) { return kKeyNames[static_cast<int>(key)]; }

WrinkleLibrarySpec load_wrinkle_spec(const std::string& path) {
    return detail::read_json_file(path, [](JsonReader& root) {
        root.comment("about");
        WrinkleLibrarySpec spec;
        JsonReader emotions = root.object("emotions");
        for (int key = 0; key < kWrinkleKeyCount; ++key) {
            if (!emotions.has(kKeyNames[key])) continue;
            for (const JsonReader& item : emotions.at(kKeyNames[key]).elements())
                spec.wrinkles[key].push_back(read_wrinkle(item));
        }
        emotions.finish();
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

std::vector<float> render_height_field(const WrinkleLibrarySpec& spec, WrinkleKey key,
                                       const FeatureLayout& layout, int size) {
    if (size < 16 || size > 8192)
        fail<InputError>("expression: render_height_field(): size must be in [16, 8192], found {}", size);
    const std::vector<Stroke> strokes = resolve_strokes(spec.wrinkles[static_cast<int>(key)], layout);
    const bool detail = key == WrinkleKey::Neutral && spec.neutral_detail.amplitude > 0.0f;
    const SkinMask mask(layout);
    const float unit = layout.face_unit();
    std::vector<float> height(static_cast<size_t>(size) * size, 0.0f);
    const float inv = 1.0f / static_cast<float>(size);
    for_each_row_band(size, [&](int row) {
        const float y = (row + 0.5f) * inv;
        float* out = height.data() + static_cast<size_t>(row) * size;
        for (const Stroke& s : strokes) {
            if (y < s.box_min.y || y > s.box_max.y) continue;
            const int c0 = std::max(0, static_cast<int>(std::floor(s.box_min.x * size)));
            const int c1 = std::min(size - 1, static_cast<int>(std::ceil(s.box_max.x * size)));
            for (int col = c0; col <= c1; ++col) out[col] += stroke_height(s, {(col + 0.5f) * inv, y});
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
            }
        }
    });
    return height;
}

NormalMap height_to_normal_map(const std::vector<float>& height, int size, float face_unit) {
    (void)face_unit;  // heights and positions share normalised units; kept for painted maps
    NormalMap map;
    map.width = map.height = size;
    map.rgba.resize(static_cast<size_t>(size) * size * 4);
    const float scale = static_cast<float>(size) * 0.5f;  // central difference over 2 px of 1/size
    const auto at = [&](int r, int c) {
        r = std::clamp(r, 0, size - 1);
        c = std::clamp(c, 0, size - 1);
        return height[static_cast<size_t>(r) * size + c];
    };
    const auto encode = [](float v) {
        return static_cast<std::uint8_t>(std::clamp(std::lround((0.5f + 0.5f * v) * 255.0f), 0L, 255L));
    };
    for_each_row_band(size, [&](int r) {
        for (int c = 0; c < size; ++c) {
            const float dx = (at(r, c + 1) - at(r, c - 1)) * scale;
            const float dy = (at(r + 1, c) - at(r - 1, c)) * scale;
            const float len = std::sqrt(dx * dx + dy * dy + 1.0f);
            std::uint8_t* px = &map.rgba[(static_cast<size_t>(r) * size + c) * 4];
            px[0] = encode(-dx / len);
            px[1] = encode(-dy / len);
            px[2] = encode(1.0f / len);
            px[3] = 255;
        }
    });
    return map;
}

NormalMap generate_wrinkle_map(const WrinkleLibrarySpec& spec, WrinkleKey key,
                               const FeatureLayout& layout, int size) {
    if (size < 256 || size > 4096)
        fail<InputError>("expression: generate_wrinkle_map(): size must be in [256, 4096], found {}", size);
    return height_to_normal_map(render_height_field(spec, key, layout, size), size, layout.face_unit());
}

}  // namespace emoface::expression
