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
    // Frontal position on the eyeball at rest (mm from its centre; +x
    // towards the outer corner, the tile being in each eye's own frame).
    const double x = R * std::sin(polar) * std::cos(azimuth), y = R * std::sin(polar) * std::sin(azimuth);
    const double cx = p.eye_centre[0], cy = p.eye_centre[1];

    // Sclera: the painted colour, warmer and pinker towards the corners,
    // where it is exposed and its vessels show, a faint cloudy unevenness
    // (a flat white reads as glass), a grey-blue shade round the limbus,
    // darker round the back.
    Rgb sclera = from255(p.sclera);
    const double mottle = 0.025 * std::sin(3.0 * azimuth + 5.0 * polar) + 0.02 * std::sin(7.0 * azimuth - 3.0 * polar + 1.0) +
                          0.015 * std::sin(13.0 * azimuth + 11.0 * polar + 2.0);
    sclera = tinted(sclera, {1.0 + mottle, 1.0 + 0.6 * mottle, 1.0 + 0.2 * mottle});
    const double corner = glm::smoothstep(ai + 0.05, 1.2, polar) * std::pow(std::cos(azimuth), 2);
    sclera = blend(sclera, tinted(sclera, {0.97, 0.80, 0.76}), std::min(1.0, 2.0 * p.sclera_corner_tint * corner));
    const double limbal_shade = 1.0 - glm::smoothstep(ai, ai + 0.22, polar);
    sclera = blend(sclera, tinted(sclera, {0.80, 0.84, 0.88}), 0.45 * limbal_shade);
    // Past about 100 degrees from the front pole the eyeball never shows
    // between the lids, whichever way it turns: no vessels there (they are
    // most of the eye tile's cost).
    const double shown = 1.0 - glm::smoothstep(1.6, 1.8, polar);
    if (shown > 0.0)
        sclera = blend(sclera, tinted(sclera, {0.86, 0.36, 0.34}), p.sclera_vessels * shown * vessels(polar, azimuth, R, ai));
    sclera = scaled(sclera, 1.0 - 0.25 * glm::smoothstep(0.3 * kPi, 0.8 * kPi, polar));

    // The caruncle and the plica semilunaris at the inner corner: the pink,
    // moist mound where the lids meet nasally, and the fold of conjunctiva
    // beside it (a white that runs into the corner reads as a doll's eye).
    if (x < 0.0 && polar < 1.8) {
        const double ax_corner = shape.eye.x_in;  // the inner corner (|x| of the face)
        const double nasal = cx - ax_corner;      // mm from the eyeball's axis to the corner
        const double slit = shape.eye.slit(cx + x) - cy;
        const double dy = (y - slit) / 2.2;
        const double across = std::exp(-dy * dy);
        const double mound = glm::smoothstep(nasal - 5.5, nasal - 3.0, -x) * across;
        const double lobules = 0.9 + 0.1 * std::sin(9.0 * y + 4.0 * x) * std::sin(7.0 * x - 3.0 * y);
        sclera = blend(sclera, scaled(Rgb{0.80, 0.47, 0.44}, lobules), 0.85 * mound);
        const double fold = (-x) - (nasal - 6.5);
        const double plica = std::exp(-(fold / 0.6) * (fold / 0.6)) * across;
        sclera = blend(sclera, tinted(sclera, {0.95, 0.74, 0.72}), 0.6 * plica);
    }

    Rgb c = sclera;
    constexpr double kLimbusSoftness = 0.09;  // radians (about 1.1 mm) over which the iris fades into the sclera
    if (polar < ai + kLimbusSoftness) {
        // Iris: radial fibres over darker gaps that wave a little as they
        // run out, a jagged collarette a third of the way out with the
        // warmer pupillary zone inside it whose colour frays outwards along
        // the fibres (a hazel eye: amber round the pupil over a grey-green
        // stroma), crypts beside it, faint contraction furrows round the
        // outer part, the dark pupillary ruff, and a broad limbal ring where
        // the iris meets the sclera. The fibres vary the brightness by under
        // half: at full contrast with a flat grey-blue colour the iris read
        // as a bright blue glass disc (blind review, session 6), and its
        // light outer part merged with the sclera, so the iris read small.
        const double t = std::clamp((polar - ap) / (ai - ap), 0.0, 1.0);
        const double bend = azimuth + 0.12 * t + 0.03 * std::sin(9.0 * t + 3.0 * azimuth);
        const double strands = 0.5 + 0.5 * std::sin(83.0 * bend + 2.5 * std::sin(11.0 * bend));
        const double fibres = 0.45 * std::pow(strands, 3.0) + 0.25 * (0.5 + 0.5 * std::sin(151.0 * bend + 4.0 * t)) +
                              0.3 * (0.5 + 0.5 * std::sin(37.0 * bend - 2.0 * t + 1.0));
        const double collarette = 0.36 + 0.05 * std::sin(7.0 * azimuth + 0.5) + 0.03 * std::sin(17.0 * azimuth + 2.0);
        Rgb iris = from255(p.iris);
        // The pupillary zone's colour runs out along the brighter fibres
        // past the collarette, in flames, not as a painted disc.
        const double reach = collarette + 0.15 * strands * (0.6 + 0.4 * std::sin(5.0 * azimuth + 1.0));
        iris = blend(iris, from255(p.iris_inner), 0.7 * (1.0 - glm::smoothstep(collarette - 0.12, reach + 0.05, t)));
        iris = scaled(iris, 0.78 + 0.42 * fibres);
        // The collarette's ridge catches light.
        const double ridge = std::exp(-std::pow((t - collarette) / 0.035, 2.0));
        iris = blend(iris, tinted(from255(p.iris_inner), {1.15, 1.1, 1.05}), 0.2 * ridge);
        const double crypt = glm::smoothstep(0.55, 0.95, std::sin(19.0 * azimuth + 1.3) * std::sin(23.0 * (t - collarette) + 0.4));
        iris = scaled(iris, 1.0 - 0.35 * crypt * glm::smoothstep(collarette, collarette + 0.08, t) *
                                 (1.0 - glm::smoothstep(0.7, 0.8, t)));
        const double furrows = std::pow(0.5 + 0.5 * std::sin(kPi * 2.0 * (t - 0.62) / 0.09 + 0.4 * std::sin(5.0 * azimuth)), 6.0);
        iris = scaled(iris, 1.0 - 0.18 * furrows * glm::smoothstep(0.6, 0.7, t) * (1.0 - glm::smoothstep(0.88, 0.92, t)));
        // The limbal ring: the stroma darkens over the outer third into a
        // grey-brown band, darkest at the rim (it frames the iris against
        // the white; a light rim made the iris read small), ramping in over
        // a third of the iris and fading into the sclera over
        // kLimbusSoftness: over a quarter, to 0.32, it read at 512 px as a
        // drawn black outline, a doll's eye (blind review, session 9).
        const double rim = glm::smoothstep(0.62, 1.0, t);
        iris = blend(iris, tinted(iris, {0.38, 0.37, 0.36}), rim);
        iris = blend(Rgb{0.10, 0.06, 0.045}, iris, glm::smoothstep(0.02, 0.08, t));  // pupillary ruff
        const Rgb pupil{0.012, 0.011, 0.013};
        iris = blend(pupil, iris, glm::smoothstep(0.0, 0.025, t));
        c = polar > ai ? blend(iris, sclera, glm::smoothstep(0.0, 1.0, (polar - ai) / kLimbusSoftness)) : iris;
    }

    // The upper lid's shadow on the eyeball where it rests on it, soft
    // (the lid stands off the eye by its thickness, and the lashes and the
    // lid's edge both shade it; the key light is above), and a fainter one
    // under the lower lid. The tile is fixed to the eyeball, so the shade
    // cannot follow a raised lid (AU5: fear, surprise); it ramps up to the
    // rest margin and holds above it, where the lid and brow overhang the
    // eyeball in every pose. Faded out above the margin it drew a grey band
    // at the rest margin's height; gone above it, the bared white glowed as
    // a bright band between lid and iris: a googly, pasted-in eye.
    const double upper_margin = shape.eye.upper(cx + x) - cy;
    const double lower_margin = shape.eye.lower(cx + x) - cy;
    // Two parts: the contact shade right under the margin (the lid's edge
    // and the lashes' roots) and a broad soft penumbra over the iris' top
    // and the white beside it (the lid and lashes stand off the eye, the
    // key is a soft box above). One ramp over 3.5 mm, mostly within a
    // millimetre, left the white bright up to a pixel under the lid at
    // 512 px: the eye read as stuck on, not sunk under the lid (blind
    // review, session 10).
    const double contact = glm::smoothstep(upper_margin - 2.0, upper_margin + 0.3, y);
    const double penumbra = glm::smoothstep(upper_margin - 5.0, upper_margin + 0.3, y);
    // It rises to 0.8 of lid_shadow and holds there, over the white that
    // only a raised lid bares (surprise, fear): at the full shade that
    // white over the iris read as a grey band, and eased back above the
    // rest margin it drew a darker stripe along that margin.
    const double shade = p.lid_shadow * std::min(0.55 * contact + 0.45 * penumbra, 0.8) +
                         0.35 * p.lid_shadow * glm::smoothstep(lower_margin + 1.5, lower_margin - 0.5, y);
    // The corners are deeper in the socket.
    const double socket = 0.3 * glm::smoothstep(0.45 * R, 0.9 * R, std::abs(x));
    return scaled(c, (1.0 - std::min(shade, 0.8)) * (1.0 - socket));
}

}  // namespace emoface::expression::detail
