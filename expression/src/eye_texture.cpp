#include "eye_texture.h"

#include <algorithm>
#include <cmath>

#include "face_shape.h"

namespace emoface::expression::detail {
namespace {

constexpr double kPi = 3.14159265358979323846;

using Rgb = std::array<double, 3>;
Rgb scaled(Rgb c, double s) { return {c[0] * s, c[1] * s, c[2] * s}; }
Rgb tinted(Rgb c, Rgb t) { return {c[0] * t[0], c[1] * t[1], c[2] * t[2]}; }
Rgb blend(Rgb a, Rgb b, double t) { return {mix(a[0], b[0], t), mix(a[1], b[1], t), mix(a[2], b[2], t)}; }
Rgb from255(const glm::dvec3& c) { return {c[0] / 255.0, c[1] / 255.0, c[2] / 255.0}; }

// Angular difference wrapped to [-pi, pi].
double wrapped(double a) { return std::remainder(a, 2.0 * kPi); }

// Conjunctival vessels: thin meandering lines that run in from the corners
// (where the lids leave the sclera exposed to the air) and fade before the
// limbus. Each is fixed by its azimuth, meander phase and how near the iris
// it reaches; sums of sines stand in for noise, so the eye is the same on
// every platform.
double vessels(double polar, double azimuth, double radius, double iris_angle) {
    constexpr int kCount = 18;
    double v = 0.0;
    for (int k = 0; k < kCount; ++k) {
        const double phase = 2.399963 * k;  // the golden angle spreads the parameters
        // Most vessels come from the nasal and temporal corners, a few from above and below.
        const double base = (k % 2 ? 0.0 : kPi) + (k % 3 == 2 ? 1.1 : 0.35) * std::sin(phase * 1.7);
        const double path = base + 0.10 * std::sin(6.0 * polar + phase) + 0.04 * std::sin(15.0 * polar + 2.0 * phase);
        const double across = radius * std::sin(polar) * std::abs(wrapped(azimuth - path));  // mm
        const double width = 0.05 + 0.05 * (0.5 + 0.5 * std::sin(3.1 * phase));
        const double tip = iris_angle + 0.22 + 0.35 * (0.5 + 0.5 * std::sin(phase * 0.7));
        const double along = glm::smoothstep(tip, tip + 0.35, polar);
        v = std::max(v, along * std::exp(-(across / width) * (across / width)));
    }
    return v;
}

}  // namespace

std::array<double, 3> eye_colour(const FaceShape& shape, double polar, double azimuth) {
    const FaceParams& p = shape.params();
    const double R = p.eye_radius;
    const double ai = std::asin(p.iris_radius / R), ap = std::asin(p.pupil_radius / R);
    // Frontal position on the eyeball at rest (mm from its centre).
    const double x = R * std::sin(polar) * std::cos(azimuth), y = R * std::sin(polar) * std::sin(azimuth);

    // Sclera: the painted colour, greyer and pinker towards the corners,
    // where it is exposed and its vessels show, darker round the back.
    Rgb sclera = from255(p.sclera);
    const double corner = glm::smoothstep(ai + 0.1, 1.25, polar) * std::pow(std::cos(azimuth), 2);
    sclera = blend(sclera, tinted(sclera, {0.95, 0.82, 0.80}), p.sclera_corner_tint * corner);
    // Past about 100 degrees from the front pole the eyeball never shows
    // between the lids, whichever way it turns: no vessels there (they are
    // most of the eye tile's cost).
    const double shown = 1.0 - glm::smoothstep(1.6, 1.8, polar);
    if (shown > 0.0)
        sclera = blend(sclera, tinted(sclera, {0.80, 0.30, 0.30}), p.sclera_vessels * shown * vessels(polar, azimuth, R, ai));
    sclera = scaled(sclera, 1.0 - 0.25 * glm::smoothstep(0.3 * kPi, 0.8 * kPi, polar));

    Rgb c = sclera;
    if (polar < ai + 0.03) {
        // Iris: radial fibres (sums of sines in azimuth, bent a little as
        // they run out), a warmer collarette round the pupil, darker crypts,
        // and the limbal ring where the iris meets the sclera.
        const double t = std::clamp((polar - ap) / (ai - ap), 0.0, 1.0);
        const double bend = azimuth + 0.15 * t;
        const double fibres = 0.5 + 0.22 * std::sin(61.0 * bend + 3.0 * std::sin(7.0 * bend)) +
                              0.16 * std::sin(149.0 * bend + 5.0 * t) + 0.12 * std::sin(23.0 * bend - 2.0 * t);
        Rgb iris = from255(p.iris);
        iris = blend(iris, from255(p.iris_inner), 0.8 * (1.0 - glm::smoothstep(0.2, 0.45, t)));
        iris = scaled(iris, 0.72 + 0.56 * fibres);
        const double crypt = glm::smoothstep(0.6, 0.9, std::sin(19.0 * azimuth + 1.3) * std::sin(14.0 * t + 0.4));
        iris = scaled(iris, 1.0 - 0.25 * crypt * glm::smoothstep(0.3, 0.45, t) * (1.0 - glm::smoothstep(0.7, 0.8, t)));
        iris = scaled(iris, 1.0 - 0.6 * glm::smoothstep(0.78, 1.0, t));  // limbal ring
        const Rgb pupil{0.015, 0.014, 0.016};
        iris = blend(pupil, iris, glm::smoothstep(0.0, 0.05, t));
        c = polar > ai ? blend(iris, sclera, (polar - ai) / 0.03) : iris;
    }

    // The upper lid's shadow on the eyeball where it rests on it, and a
    // fainter one under the lower lid: the lids stand off the eye by their
    // thickness and the light comes from above.
    // Both eyes share the tile, so the margins are those of the two sides averaged.
    const double cx = p.eye_centre[0], cy = p.eye_centre[1];
    const double upper_margin = 0.5 * (shape.eye.upper(cx + x) + shape.eye.upper(cx - x)) - cy;
    const double lower_margin = 0.5 * (shape.eye.lower(cx + x) + shape.eye.lower(cx - x)) - cy;
    const double shade = p.lid_shadow * glm::smoothstep(upper_margin - 3.0, upper_margin + 0.5, y) +
                         0.35 * p.lid_shadow * glm::smoothstep(lower_margin + 1.5, lower_margin - 0.5, y);
    // The corners are deeper in the socket.
    const double socket = 0.2 * glm::smoothstep(0.55 * R, 0.9 * R, std::abs(x));
    return scaled(c, (1.0 - std::min(shade, 0.8)) * (1.0 - socket));
}

}  // namespace emoface::expression::detail
