#include "face_texture.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

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

double hash(int x, int y, int z) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 374761393u + static_cast<std::uint32_t>(y) * 668265263u +
                      static_cast<std::uint32_t>(z) * 2147483647u;
    h = (h ^ (h >> 13)) * 1274126177u;
    h ^= h >> 16;
    return (h & 0xffffff) / static_cast<double>(0xffffff);
}

// Value noise in [0, 1], smooth between integer lattice points.
double noise(double x, double y, double z = 0.0) {
    const int xi = static_cast<int>(std::floor(x)), yi = static_cast<int>(std::floor(y)),
              zi = static_cast<int>(std::floor(z));
    auto fade = [](double t) { return t * t * (3 - 2 * t); };
    const double fx = fade(x - xi), fy = fade(y - yi), fz = fade(z - zi);
    double v[2];
    for (int k = 0; k < 2; ++k) {
        const double a = mix(hash(xi, yi, zi + k), hash(xi + 1, yi, zi + k), fx);
        const double b = mix(hash(xi, yi + 1, zi + k), hash(xi + 1, yi + 1, zi + k), fx);
        v[k] = mix(a, b, fy);
    }
    return mix(v[0], v[1], fz);
}

double fbm(double x, double y, double z) {
    return 0.5 * noise(x, y, z) + 0.3 * noise(2.1 * x, 2.1 * y, 2.1 * z) + 0.2 * noise(4.3 * x, 4.3 * y, 4.3 * z);
}

class Painter {
public:
    explicit Painter(const FaceShape& shape) : s_(shape), p_(shape.params()) {}

    Rgb skin(glm::dvec3 q) const;
    Rgb tile(double u, double v) const;

private:
    double brow_density(double x, double y) const;
    bool hair(glm::dvec3 q, double* amount) const;

    const FaceShape& s_;
    const FaceParams& p_;
};

double Painter::brow_density(double x, double y) const {
    const double sx = x >= 0 ? 1.0 : -1.0;
    const glm::dvec2 a{p_.brow_points[0][0] * sx, p_.brow_points[0][1]};
    const glm::dvec2 m{p_.brow_points[1][0] * sx, p_.brow_points[1][1]};
    const glm::dvec2 b{p_.brow_points[2][0] * sx, p_.brow_points[2][1]};
    // Quadratic curve through a, m (at t = 0.5) and b.
    const glm::dvec2 c{2 * m[0] - 0.5 * (a[0] + b[0]), 2 * m[1] - 0.5 * (a[1] + b[1])};
    double best = 1e9, best_t = 0, best_sd = 0;
    constexpr int kSamples = 48;
    for (int k = 0; k <= kSamples; ++k) {
        const double t = static_cast<double>(k) / kSamples;
        const double px = (1 - t) * (1 - t) * a[0] + 2 * t * (1 - t) * c[0] + t * t * b[0];
        const double py = (1 - t) * (1 - t) * a[1] + 2 * t * (1 - t) * c[1] + t * t * b[1];
        const double d = std::hypot(x - px, y - py);
        if (d < best) {
            best = d;
            best_t = t;
            best_sd = y - py;
        }
    }
    const double th = best_t < 0.5 ? mix(p_.brow_thickness[0], p_.brow_thickness[1], best_t * 2)
                                   : mix(p_.brow_thickness[1], p_.brow_thickness[2], best_t * 2 - 1);
    // Brows sit mostly above their centre line at the inner end.
    const double half = 0.5 * th;
    const double q = best / half;
    if (q > 1.3) return 0.0;
    double m_edge = 1.0 - glm::smoothstep(0.55, 1.15, q);
    m_edge *= 0.55 + 0.45 * glm::smoothstep(0.0, 0.22, best_t);  // sparse at the inner end
    (void)best_sd;
    // Hair strands: noise stretched along the brow (mostly horizontal).
    const double strands = noise(x * 0.9, y * 3.2, 7.0) * 0.6 + noise(x * 2.3, y * 6.0, 3.0) * 0.4;
    return std::clamp(m_edge * (0.55 + 0.7 * strands), 0.0, 1.0);
}

bool Painter::hair(glm::dvec3 q, double* amount) const {
    const double ax = std::abs(q.x);
    // Front: the hairline over the forehead, dropping at the temples.
    const double tx = std::min(ax / p_.hairline_temple[0], 1.0);
    const double front_line = mix(p_.hairline_y, p_.hairline_temple[1], tx * tx) -
                              std::max(ax - p_.hairline_temple[0], 0.0) * 2.5;
    // Side and back, by depth: the sideburn in front of the ear, a margin
    // over the ear, then down to the nape.
    const double ear_top = p_.ear_centre_yz[0] + p_.ear_radii_yz[0] + 5.0;
    const double ear_front = p_.ear_centre_yz[1] + p_.ear_radii_yz[1] + 3.0;
    const double ear_back = p_.ear_centre_yz[1] - p_.ear_radii_yz[1] - 3.0;
    double side_line;
    if (q.z > ear_front) side_line = mix(ear_top, p_.sideburn_bottom_y, glm::smoothstep(ear_front, ear_front + 5.0, q.z));
    else if (q.z > ear_back) side_line = ear_top;
    else side_line = mix(ear_top, p_.hair_back_bottom_y, glm::smoothstep(ear_back, ear_back - 35.0, q.z));
    const double line = mix(side_line, front_line, glm::smoothstep(p_.sideburn_z - 6.0, p_.sideburn_z + 6.0, q.z));
    double edge = q.y - line;
    // Leave the ears bare.
    if (ax > 55 && s_.ear_relief(q.y, q.z) > 0.3) edge = std::min(edge, -2.0);
    edge += (noise(q.x * 0.4, q.y * 0.4, q.z * 0.4) - 0.5) * 3.0;
    *amount = glm::smoothstep(-1.0, 2.5, edge);
    return *amount > 0.0;
}

// Redness: haemoglobin absorbs green and blue, so a redder patch keeps its
// red and loses some of both. `amount` 1 is the strongest flush painted.
Rgb redden(Rgb c, double amount) {
    return blend(c, c * Rgb{1.02, 0.83, 0.85}, std::clamp(amount, 0.0, 1.5));
}
// A soft elliptical field, 1 at (cx, cy) falling off as a Gaussian of
// widths sx, sy (mm): regions of colour with no edge to see.
double field(double x, double y, double cx, double cy, double sx, double sy) {
    const double dx = (x - cx) / sx, dy = (y - cy) / sy;
    return std::exp(-0.5 * (dx * dx + dy * dy));
}

Rgb Painter::skin(glm::dvec3 q) const {
    const Rgb skin = from255(p_.skin);
    // Gentle pigment variation at two scales (MATTS: even skin reads young,
    // so it stays within a few percent), and haemoglobin mottling apart from
    // it so the two do not move together.
    Rgb c = skin * (0.96 + 0.08 * fbm(q.x * 0.08, q.y * 0.08, q.z * 0.08));
    c = redden(c, 0.35 * (fbm(q.x * 0.21 + 11.0, q.y * 0.21, q.z * 0.21) - 0.45));
    const double ax = std::abs(q.x);
    const bool front = q.z > 45.0;
    if (front) {
        // Regional redness (HAN, XIAO: the cheek is the reddest site; the
        // nose and chin are flushed; the forehead is the darkest and least
        // red). Broad Gaussian fields, their strength broken up by noise, so
        // they read as blood under skin, not as painted discs.
        const double blotch = 0.75 + 0.5 * noise(q.x * 0.15, q.y * 0.15, 4.0);
        const double cheek = field(ax, q.y, 40.0, -26.0, 17.0, 15.0);
        const double nose = field(q.x, q.y, 0.0, -36.0, 8.0, 9.0) + 0.5 * field(ax, q.y, 11.0, -41.0, 5.0, 5.0);
        const double chin = field(q.x, q.y, 0.0, -96.0, 14.0, 9.0);
        c = redden(c, blotch * (0.55 * cheek + 0.5 * nose + 0.22 * chin));
        // Forehead: a shade darker and more yellow.
        const double forehead = glm::smoothstep(18.0, 45.0, q.y);
        c = blend(c, c * Rgb{0.97, 0.955, 0.92}, 0.8 * forehead);

        // Beard zone (shaved): a bluish-grey cast from the stubble under the
        // skin, over the upper lip, chin, jaw and lower cheeks, below a line
        // from the sideburn to the mouth corner, fading on the neck.
        const double cheek_line = ax < 28.0 ? -46.0 : mix(-46.0, -14.0, std::min((ax - 28.0) / 34.0, 1.0));
        const double beard = glm::smoothstep(2.0, -10.0, q.y - cheek_line) * glm::smoothstep(-150.0, -118.0, q.y) *
                             (0.8 + 0.4 * noise(q.x * 1.7, q.y * 1.7, q.z * 1.7));
        c = blend(c, c * Rgb{0.84, 0.88, 0.97}, 0.38 * beard);

        // Lips.
        const double hw = s_.mouth_half_width();
        if (ax < hw + 2.0 && q.z > 60.0) {
            const double up = s_.upper_border(q.x), lo = s_.lower_border(q.x);
            const double inside = std::min({up - q.y, q.y - lo, (hw - ax) * 0.6});
            const double m = glm::smoothstep(-0.3, 0.35, inside);
            if (m > 0) {
                const double crease = glm::smoothstep(0.0, 2.0, std::abs(q.y - s_.mouth_line(q.x)));
                Rgb lips = from255(p_.lips) * (0.78 + 0.22 * crease) *
                           (0.94 + 0.12 * noise(q.x * 2.5, q.y * 0.6, 1.0));
                c = blend(c, lips, m);
            }
        }
        // Eyelids: lash lines and slightly darker lids.
        const EyeOpening& e = s_.eye;
        if (ax > e.x_in - 4 && ax < e.x_out + 5 && q.y > -15 && q.y < 20) {
            const double s = clamp01(e.s(ax));
            const bool within = ax >= e.x_in && ax <= e.x_out;
            const double up = within ? e.upper(ax) : (ax < e.x_in ? e.y_in : e.y_out);
            const double lo = within ? e.lower(ax) : (ax < e.x_in ? e.y_in : e.y_out);
            const double dy_up = q.y - up, dy_lo = lo - q.y;
            if (dy_up > -0.3) {
                const double lid = (1.0 - glm::smoothstep(0.0, 9.0, dy_up)) * (within ? 1.0 : 0.5);
                c = blend(c, c * Rgb{0.86, 0.78, 0.8}, 0.5 * lid);
                const double reach = 0.6 + 0.9 * s;  // lashes thicken towards the outer corner
                const double lash = (1.0 - glm::smoothstep(0.15, reach, dy_up)) * (within ? 1.0 : glm::smoothstep(3.0, 0.0, std::min(std::abs(ax - e.x_in), std::abs(ax - e.x_out))));
                c = blend(c, Rgb{0.09, 0.06, 0.05}, 0.92 * lash);
            }
            if (dy_lo > -0.3 && within) {
                const double lash = 1.0 - glm::smoothstep(0.05, 0.55, dy_lo);
                c = blend(c, Rgb{0.25, 0.15, 0.13}, 0.55 * lash);
                const double shadow = 1.0 - glm::smoothstep(0.0, 6.0, dy_lo);
                c = blend(c, c * Rgb{0.88, 0.8, 0.82}, 0.35 * shadow);
            }
            // Inner corner (caruncle).
            const double car = 1.0 - glm::smoothstep(0.6, 2.2, std::hypot(ax - e.x_in - 0.6, q.y - e.y_in));
            c = blend(c, Rgb{0.78, 0.45, 0.45}, 0.7 * car);
        }
        // Brows.
        if (q.y > 0 && q.y < 40 && ax < 65) {
            const double d = brow_density(q.x, q.y);
            if (d > 0) c = blend(c, from255(p_.brows) * (0.85 + 0.3 * noise(q.x * 4, q.y * 4, 9)), 0.93 * d);
        }
        // Nostrils.
        const double n = s_.nostril_amount(q.x, q.y);
        if (n > 0) c = blend(c, Rgb{0.25, 0.12, 0.11}, glm::smoothstep(0.05, 0.5, n));
    }
    // Ears: thin, well perfused, redder than the face beside them.
    if (ax > 55.0 && s_.ear_relief(q.y, q.z) > 0.0)
        c = redden(c, 0.45 * std::min(1.0, s_.ear_relief(q.y, q.z) / 3.0));
    double h = 0;
    if (hair(q, &h)) {
        const Rgb hc = from255(p_.hair) *
                       (0.8 + 0.4 * noise(q.x * 0.5, q.y * 2.5, q.z * 0.5)) * (0.9 + 0.2 * noise(q.x * 3, q.y * 3, q.z * 3));
        c = blend(c, hc, h);
    }
    return c;
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
            return from255(p_.mouth) * (0.3 + 0.7 * std::min(r, 1.0));
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
            Rgb teeth = from255(p_.teeth) * (1.0 - 0.45 * (1.0 - glm::smoothstep(0.15, 0.5, gap)));
            const double edge = std::min(std::abs(c - 1.0), std::abs(c - 2.0));
            teeth = blend(teeth, teeth * Rgb{0.85, 0.87, 0.92}, 1.0 - glm::smoothstep(0.0, 0.25, edge));
            const double gum = c < 0.25 || c > 2.75 ? 1.0 : 0.0;
            return blend(teeth, Rgb{0.72, 0.36, 0.36}, gum);
        }
        case Tile::Tongue:
            return from255(p_.tongue) * (0.85 + 0.25 * noise(lu * 40, lv * 40, 2.0));
    }
    return {};
}

}  // namespace

Image paint_base_colour(const FaceShape& shape, const TriMesh& mesh, int size) {
    Image img;
    img.width = img.height = size;
    img.rgba.assign(static_cast<std::size_t>(size) * size * 4, 0);
    std::vector<std::uint8_t> filled(static_cast<std::size_t>(size) * size, 0);
    Painter painter(shape);
    auto put = [&](int x, int y, Rgb c) {
        const std::size_t i = static_cast<std::size_t>(y) * size + x;
        auto to8 = [](double v) { return static_cast<std::uint8_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0)); };
        img.rgba[i * 4 + 0] = to8(c.r);
        img.rgba[i * 4 + 1] = to8(c.g);
        img.rgba[i * 4 + 2] = to8(c.b);
        img.rgba[i * 4 + 3] = 255;
        filled[i] = 1;
    };

    for (auto fh : mesh.faces()) {
        double tu[3], tv[3];
        glm::dvec3 pos[3];
        int k = 0;
        for (auto vh : mesh.fv_range(fh)) {
            const auto t = mesh.texcoord2D(vh);
            const auto q = mesh.point(vh);
            tu[k] = t[0] * size - 0.5;
            tv[k] = (1.0 - t[1]) * size - 0.5;
            pos[k] = {q[0], q[1], q[2]};
            ++k;
        }
        const bool is_skin = std::min({tu[0], tu[1], tu[2]}) >= -1 &&
                             (1.0 - (std::max({tv[0], tv[1], tv[2]}) + 0.5) / size) >= kSkinV0 - 1e-6;
        const int x0 = std::max(0, static_cast<int>(std::floor(std::min({tu[0], tu[1], tu[2]}))));
        const int x1 = std::min(size - 1, static_cast<int>(std::ceil(std::max({tu[0], tu[1], tu[2]}))));
        const int y0 = std::max(0, static_cast<int>(std::floor(std::min({tv[0], tv[1], tv[2]}))));
        const int y1 = std::min(size - 1, static_cast<int>(std::ceil(std::max({tv[0], tv[1], tv[2]}))));
        const double area = (tu[1] - tu[0]) * (tv[2] - tv[0]) - (tu[2] - tu[0]) * (tv[1] - tv[0]);
        if (std::abs(area) < 1e-12) continue;
        for (int y = y0; y <= y1; ++y) {
            for (int x = x0; x <= x1; ++x) {
                const double w0 = ((tu[1] - x) * (tv[2] - y) - (tu[2] - x) * (tv[1] - y)) / area;
                const double w1 = ((tu[2] - x) * (tv[0] - y) - (tu[0] - x) * (tv[2] - y)) / area;
                const double w2 = 1.0 - w0 - w1;
                constexpr double kEps = -1e-4;
                if (w0 < kEps || w1 < kEps || w2 < kEps) continue;
                if (is_skin) {
                    put(x, y, painter.skin(pos[0] * w0 + pos[1] * w1 + pos[2] * w2));
                } else {
                    put(x, y, painter.tile((x + 0.5) / size, 1.0 - (y + 0.5) / size));
                }
            }
        }
    }
    // Grow the painted texels into the empty ones around them, so bilinear
    // filtering and mipmaps near a chart's border never fetch black.
    for (int pass = 0; pass < 8; ++pass) {
        std::vector<std::uint8_t> next = filled;
        for (int y = 0; y < size; ++y) {
            for (int x = 0; x < size; ++x) {
                const std::size_t i = static_cast<std::size_t>(y) * size + x;
                if (filled[i]) continue;
                int sum[3] = {0, 0, 0}, n = 0;
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int xx = x + dx, yy = y + dy;
                        if (xx < 0 || yy < 0 || xx >= size || yy >= size) continue;
                        const std::size_t j = static_cast<std::size_t>(yy) * size + xx;
                        if (!filled[j]) continue;
                        for (int c = 0; c < 3; ++c) sum[c] += img.rgba[j * 4 + c];
                        ++n;
                    }
                if (n == 0) continue;
                for (int c = 0; c < 3; ++c) img.rgba[i * 4 + c] = static_cast<std::uint8_t>(sum[c] / n);
                img.rgba[i * 4 + 3] = 255;
                next[i] = 1;
            }
        }
        filled.swap(next);
    }
    for (std::size_t i = 0; i < filled.size(); ++i)
        if (!filled[i]) img.rgba[i * 4 + 3] = 255;
    return img;
}

}  // namespace emoface::expression::detail
