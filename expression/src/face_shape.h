#pragma once
// The default face's shape as functions of position: a smooth union of
// ellipsoids for the head volume (cast rays against it to place grid
// vertices), frontal relief (nose, lips, brow ridge, cheeks, ...) added along
// z, eyelids that lie on the eyeball sphere near the eye opening, and ears
// added along the side normal. Shared by the mesh generator and the texture
// painter, which colours from the same curves (lip borders, eyelid margins).
#include <array>
#include <cmath>
#include <cstdint>

#include <glm/common.hpp>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "face_params.h"

namespace emoface::expression::detail {

// glm::normalize, except that a zero vector stays zero (glm gives NaN).
inline glm::dvec3 normalised(const glm::dvec3& a) {
    const double l = glm::length(a);
    return l > 0 ? a * (1.0 / l) : a;
}

inline double clamp01(double t) { return t < 0 ? 0 : (t > 1 ? 1 : t); }
inline double mix(double a, double b, double t) { return a + (b - a) * t; }

// A hash of a lattice point to [0, 1].
inline double hash(int x, int y, int z) {
    std::uint32_t h = static_cast<std::uint32_t>(x) * 374761393u + static_cast<std::uint32_t>(y) * 668265263u +
                      static_cast<std::uint32_t>(z) * 2147483647u;
    h = (h ^ (h >> 13)) * 1274126177u;
    h ^= h >> 16;
    return (h & 0xffffff) / static_cast<double>(0xffffff);
}

// Value noise in [0, 1], smooth (C1) between integer lattice points: the
// painter's colour variation and the shape's irregular hairline and hair
// volume, which must agree where they meet.
inline double noise(double x, double y, double z = 0.0) {
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

// The eye opening of the left eye in frontal coordinates (the right eye is
// its mirror image: use |x|).
struct EyeOpening {
    double x_in = 0, y_in = 0, x_out = 0, y_out = 0;
    double upper_height = 0, lower_height = 0;
    double upper_peak = 0.5, lower_peak = 0.5;

    double s(double ax) const { return (ax - x_in) / (x_out - x_in); }
    double slit(double ax) const { return mix(y_in, y_out, clamp01(s(ax))); }
    double upper(double ax) const;
    double lower(double ax) const;
    bool inside_x(double ax) const { return ax > x_in && ax < x_out; }
};

class FaceShape {
public:
    explicit FaceShape(const FaceParams& params);

    const FaceParams& params() const { return p_; }

    // Head volume: negative inside.
    double field(glm::dvec3 p) const;
    glm::dvec3 field_normal(glm::dvec3 p) const;
    // Distance along a unit direction from an inside origin to the head volume's surface.
    double cast(glm::dvec3 origin, glm::dvec3 dir) const;

    // The final skin position for a point on the head volume's surface.
    glm::dvec3 displace(glm::dvec3 base) const;

    // The face's natural asymmetry (face.json "asymmetry"): a smooth offset
    // of a millimetre or so, zero round the eyes, that displace() adds last.
    // The painter takes it off a position before colouring it, so colour
    // and relief stay together; 0 everywhere when shape_mm is 0.
    glm::dvec3 asymmetry(glm::dvec3 p) const;

    // Frontal relief along z at (x, y), without the eyelid blend.
    double relief(double x, double y) const;

    // The eye opening (left eye; use |x|), set once the corner columns are known.
    EyeOpening eye;
    void set_eye_corners(double x_in, double x_out);

    // Mouth curves at x: the line where the lips meet, the vermilion borders.
    double mouth_line(double x) const;
    double upper_border(double x) const;
    double lower_border(double x) const;
    double mouth_half_width() const { return mouth_half_width_; }
    void set_mouth_half_width(double hw) { mouth_half_width_ = hw; }

    // z of the eyelid surface at (x, y): on the eyeball sphere grown by
    // clearance + thickness(distance from the margin).
    double lid_z(double x, double y, double margin_distance) const;
    // 0..1: how much the eyelid surface replaces the relief at (x, y), and the
    // distance from the eye opening.
    double lid_blend(double x, double y, double* margin_distance) const;

    // Outward displacement of the ear relief at a side point (y, z), left ear.
    double ear_relief(double y, double z) const;
    // The side point (y, z) at ear coordinates a (along the ear's tilted
    // long axis, -1 lobe .. 1 top) and s (across it, -1 the free back rim ..
    // 1 the front edge where the ear joins the head).
    glm::dvec2 ear_point(double a, double s) const;
    // The in-plane move (y, z) that draws a side point near the ear's
    // outline onto it, so the rim's edge follows the outline, not the grid.
    glm::dvec2 ear_rim_pull(double y, double z) const;

    // The hairline's height (y) at a point of the head, from face.json
    // "hair" (the front line over the forehead and temples, the sideburn,
    // over the ear, down to the nape), with the temples' recession and a
    // line that wanders by a millimetre or two, differently on each side.
    double hairline(glm::dvec3 q) const;
    // How far above the hairline a point of the head lies, in mm along the
    // head (negative below it): the height over hairline() divided by the
    // line's steepness, so the band is as wide where the line runs down the
    // temple as where it crosses the forehead; far above the line (over
    // 12 mm), the plain height less 12 mm, so the crown is never near it.
    double hair_height(glm::dvec3 q) const;
    // Where a point lies in the hair's flow from the crown's whorl: across
    // it (mm round the crown at a typical distance; the whorl's spiral
    // turns it with distance) and along it (mm from the crown).
    struct HairFlow {
        double azimuth, across, along;
    };
    HairFlow hair_flow(glm::dvec3 q) const;
    // The clump the hair gathers in at q: 1 on a tuft's crest, 0 in the
    // parting beside it (face.json head.hair_volume tuft_mm), the same for
    // the volume and the paint.
    double hair_tuft(glm::dvec3 q) const;
    // How far the hair stands off the scalp at a head-volume point with
    // outward normal n (0 below the hairline).
    double hair_thickness(glm::dvec3 base, glm::dvec3 n) const;

    // Where q lies against the T-shirt's collar (face.json shirt): how far
    // below its edge across the neckline's curve (mm; < 0 on the neck above
    // it), and how far round the neck from the front (mm along the neck's
    // surface, signed as x), the same for the cloth's thickness and its paint.
    struct ShirtPlace {
        double below, around;
    };
    ShirtPlace shirt_place(glm::dvec3 q) const;
    // How far the shirt stands off the skin at a head-volume point (0 on
    // the neck above the collar).
    double shirt_thickness(glm::dvec3 base) const;

    // Depth of the nostril dents at (x, y) as a fraction 0..1 (for painting).
    double nostril_amount(double x, double y) const;

private:
    double lip_relief(double x, double y) const;

    const FaceParams& p_;
    double neck_lean_tan_ = 0;
    double mouth_half_width_ = 0;
};

}  // namespace emoface::expression::detail
