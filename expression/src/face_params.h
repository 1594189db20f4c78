#pragma once
// Parameters of the default face generator, read from data/face/face.json.
// docs/FACE.md explains each block; all lengths are millimetres in the face's
// frame (x = face's left, y = up, z = towards the viewer; y = 0 at eye level,
// the head's vertical axis at x = z = 0).
#include <array>
#include <map>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace emoface::expression::detail {

// An ellipsoid pitched by tilt_deg about the x axis (positive: its front end
// goes down), as the mandible runs from the chin up to the jaw angle. With an
// exponent above 2 it is a superellipsoid, |x/a|^e + |y/b|^e + |z/c|^e = 1:
// flatter faces and fuller shoulders, as the cranium's top, sides and back.
struct Ellipsoid {
    glm::dvec3 centre{0.0};
    glm::dvec3 radii{0.0};
    double tilt_deg = 0.0;
    double exponent = 2.0;
};

// A rod from `from` to `to` whose radius goes from radii[0] to radii[1]
// (a tapered capsule): the mandible's lower border from the jaw angle to
// the chin. `mirror`: also its mirror image across x = 0.
struct Capsule {
    glm::dvec3 from{0.0}, to{0.0};
    glm::dvec2 radii{0.0};
    bool mirror = false;
};

// One volume of the head's smooth union (an ellipsoid, or a capsule when
// `is_capsule`), joined to those before it with a fillet of size `blend` (mm).
struct HeadPart {
    std::string name;
    bool is_capsule = false;
    Ellipsoid shape;
    Capsule capsule;
    double blend = 0.0;
};

// A smooth bump added to the face's depth (z) over a frontal ellipse:
// height * (1 - rho^2)^3, rho the rotated, normalised distance from centre.
struct Bump {
    std::string name;
    glm::dvec2 centre{0.0};
    glm::dvec2 radius{0.0};
    double height = 0.0;
    double angle_deg = 0.0;
    bool mirror = false;
};

// A bump along a polyline: height and half-width interpolated along it,
// cross-section (1 - (d / width)^2)^3, d the distance to the polyline.
struct Ridge {
    std::string name;
    std::vector<glm::dvec2> points;
    std::vector<double> width;
    std::vector<double> height;
    double apex_round = 0.0;  // mm over which the crest is rounded (0: the profile's own point)
    bool mirror = false;
};

// One key of the ray sweep that lays the grid rows over the head: a row is a
// fan of rays over azimuth theta from an origin (0, origin_y, z) at elevation
// angle; z and angle go from their front value (theta = 0) to their back value
// (theta = 180 deg) with weight (1 + cos theta) / 2, so the rows can wrap
// under the chin at the front while staying level at the nape. Between keys
// the sweep is linear; rows are placed along it every `spacing` mm (of the
// front profile, or of the back one where that moves faster) up to the next key.
struct RowKey {
    double origin_y = 0.0;
    double origin_z_front = 0.0, origin_z_back = 0.0;
    double angle_front_deg = 0.0, angle_back_deg = 0.0;
    double spacing = 0.0;
};

struct FaceParams {
    std::string file;

    // resolution
    int front_columns = 0, back_columns = 0;
    double front_half_angle_deg = 0.0;
    std::vector<RowKey> upper_rows;  // from eye level (angle 0) up to the crown
    std::vector<RowKey> lower_rows;  // from eye level down to the neck's cut
    double row_spacing = 0.0;        // mm between rows where a key gives none
    // below the last lower row, rows that follow the body's profile down the
    // chest and out along the shoulders (face.json resolution.bust): how
    // many, how far (mm along the profile: in front, at the sides, behind),
    // and the first row's spacing as a share of the mean (the rest widen
    // evenly)
    int bust_rows = 0;
    glm::dvec3 bust_length_mm{0.0};
    double bust_first_share = 1.0;
    double bust_texture_rows = 0.0;  // texture height of the bust's rows, in rows above
    int eyeball_rings = 0, eyeball_segments = 0;
    int texture_size = 0;

    // head volume: the smooth union of the parts (cranium, cheekbones, face,
    // jaw, ...), then the neck, an elliptic cylinder whose axis leans forward
    // by neck_lean_deg (its top in front of its bottom), capped at neck_top_y
    // inside the head, then the shoulders (the trapezius' slope is the fillet)
    std::vector<HeadPart> head_parts;
    double neck_centre_z = 0.0;
    glm::dvec2 neck_radii{0.0};
    double neck_top_y = 0.0, neck_lean_deg = 0.0, neck_blend = 0.0;
    Ellipsoid shoulders;
    double shoulders_blend = 0.0;
    // the hair's volume off the scalp (mm) over the crown, on the sides and
    // at the nape, and over how many mm above the hairline it grows to that; lumps: +-
    // that fraction of it in tufts about lump_size mm across, so the
    // silhouette is not one smooth shell
    // tufts: the hair's clumps (mm across and along the strands' flow),
    // each standing up by +- tufts of the volume on its crest and sinking
    // into a parting between clumps
    struct HairVolume {
        double top = 0.0, sides = 0.0, nape = 0.0, fade = 1.0;
        double lumps = 0.0, lump_size = 1.0;
        glm::dvec2 tuft_size{1.0};
        double tufts = 0.0;
    } hair_volume;

    // eyes (left eye; the right one mirrors it)
    glm::dvec3 eye_centre{0.0};
    double eye_radius = 0.0, iris_radius = 0.0, pupil_radius = 0.0;
    // The cornea: a sphere of cornea_radius over the eyeball's, meeting it
    // cornea_reach off the eye's axis (mm).
    double cornea_radius = 0.0, cornea_reach = 0.0;
    glm::dvec2 inner_corner{0.0}, outer_corner{0.0};
    double upper_lid_height = 0.0, lower_lid_height = 0.0;
    double upper_lid_peak = 0.5, lower_lid_peak = 0.5;
    double lid_clearance = 0.0, lid_thickness = 0.0;
    double lid_blend_inner = 0.0, lid_blend_outer = 0.0;
    double lid_rise = 0.0;  // how the lid's skin leaves the eyeball: mm per mm^2 from the margin
    double lid_warp_reach = 0.0;
    // the eyeball's colour (eye_texture.cpp): 0..1 strengths
    double sclera_corner_tint = 0.0, sclera_vessels = 0.0, lid_shadow = 0.0;
    // eyelashes along each margin (default_face.cpp): how many, their length
    // and root width (mm), the angle they leave the lid at, away from the
    // eye's radial direction (degrees), and how much more they turn (curl)
    // by their tips
    struct LashRow {
        int count = 0;
        double length = 0.0, width = 0.0, lift_deg = 0.0, curl_deg = 0.0;
    };
    LashRow upper_lashes, lower_lashes;
    // the lash line painted into the lids' skin (face_texture.cpp): how far
    // up the upper lid it reaches from the margin (mm) and how much of the
    // lashes' colour it lays down, at the inner and the outer corner; how
    // much of the upper margin's strip it darkens; how much the lower lid's
    // sparse roots darken
    struct LashLine {
        glm::dvec2 width{0.0}, amount{0.0};
        double upper_margin = 0.0, lower = 0.0;
    } lash_line;
    // the upper lid's crease painted as a soft shade line (face_texture.cpp):
    // its height over the margin mid-lid (mm; lower towards the corners),
    // its width (mm) and how much it darkens the skin
    struct LidCrease {
        double height = 0.0, width = 1.0, amount = 0.0;
    } lid_crease;

    // mouth
    double mouth_y = 0.0, mouth_half_width = 0.0, mouth_corner_rise = 0.0;
    double upper_lip_height = 0.0, lower_lip_height = 0.0;
    double cupid_dip = 0.0, cupid_peak_x = 0.0;
    double upper_lip_protrusion = 0.0, lower_lip_protrusion = 0.0;
    double lip_crease_depth = 0.0, lip_crease_width = 0.0;
    // how far the skin below the lower lip tucks in under it, and that
    // tuck's distance below the vermilion border (mm)
    double lower_lip_tuck = 0.0, lower_lip_tuck_at = 0.0;
    double mouth_warp_reach = 0.0;
    double outer_corner_offset = 0.0;

    // mouth interior
    glm::dvec3 cavity_centre{0.0};
    glm::dvec3 cavity_radii{0.0};
    double teeth_half_width = 0.0, teeth_depth = 0.0;
    // crowns from the midline out: width along the arch, crown height (mm)
    std::vector<glm::dvec2> upper_crowns, lower_crowns;
    double teeth_gap = 0.0;
    glm::dvec3 tongue_centre{0.0};
    glm::dvec3 tongue_radii{0.0};

    // relief
    std::vector<Bump> bumps;
    std::vector<Ridge> ridges;
    std::vector<Bump> nostrils;  // dents painted dark

    // ears (left; mirrored): centre and half length / half breadth on the
    // side of the head (y, z), the long axis tilted back by ear_tilt_deg (its
    // top behind its bottom), the helix rim's height off the scalp
    glm::dvec2 ear_centre_yz{0.0};
    glm::dvec2 ear_radii_yz{0.0};
    double ear_tilt_deg = 0.0;
    double ear_height = 0.0;

    // the face's natural asymmetry: its largest shape offset (mm; 0 gives a
    // mirror-symmetric face) and how far the two halves' colour differs
    // (a fraction of the flush and tone)
    double asymmetry_mm = 0.0, asymmetry_albedo = 0.0;

    // pivots
    glm::dvec3 jaw_pivot{0.0};
    glm::dvec3 head_pivot{0.0};
    glm::dvec2 texture_box_min{0.0}, texture_box_max{0.0};

    // feature points placed by target: [x, y] = nearest front-facing skin
    // vertex in frontal projection; [x, y, z] = nearest skin vertex in 3D.
    std::map<std::string, std::vector<double>> feature_targets;

    // colours (sRGB 0..255)
    glm::dvec3 skin{0.0}, lips{0.0}, brows{0.0}, hair{0.0}, iris{0.0}, iris_inner{0.0}, sclera{0.0}, lashes{0.0};
    glm::dvec3 mouth{0.0}, teeth{0.0}, tongue{0.0};
    // brows (left): inner, peak, outer points and thickness at each
    std::array<glm::dvec2, 3> brow_points{};
    glm::dvec3 brow_thickness{0.0};
    // hairline: front height at x = 0, temple point (x, y), how far down the
    // hair reaches at the sides (sideburn) and back
    double hairline_y = 0.0;
    glm::dvec2 hairline_temple{0.0};
    double sideburn_z = 0.0, sideburn_bottom_y = 0.0, hair_back_bottom_y = 0.0;
    // the temples' recession: |x| of its deepest point, how far it rises
    // (mm) and its half-width; how far the line wanders (mm, +-)
    glm::dvec3 hair_recession{0.0};
    // mm of z over which the line runs down from the temple point to the
    // sideburn's top
    double temple_depth = 1.0;
    double hairline_wander = 0.0;
    // hair: the whorl the strands flow from, the width of the hairline's
    // fading band, the strands' size and the tips' lightening
    glm::dvec3 hair_crown{0.0};
    double hairline_band = 0.0, hair_strand_width = 0.0, hair_strand_length = 0.0, hair_tip_lightening = 0.0;
    // how far the strands turn round the crown per 100 mm from it (radians;
    // the whorl's spiral, so the front sweeps across the forehead)
    double hair_swirl = 0.0;
    // hair: how much darker a parting between tufts is than a tuft's crest
    // (the strands' roots show there, shadowed by the clumps beside it)
    double hair_tuft_shade = 0.0;
    // hair: stray locks over the forehead, each a few strands from one root
    // that fan out: how many locks, their length (mm, shortest .. longest),
    // strands per lock and a strand's width (mm)
    struct Forelock {
        int locks = 0, strands = 1;
        glm::dvec2 length{1.0};
        double width = 0.1;
    } hair_forelock;
    // brow hairs: spacing of their roots, length at the inner end and beyond,
    // width (mm), angle off the brow line (degrees) of the medial ones and of
    // the lateral ones above and below the line (which converge on it)
    double brow_hair_spacing = 0.0, brow_hair_width = 0.0;
    glm::dvec2 brow_hair_length{0.0};
    double brow_medial_angle = 0.0, brow_lateral_angle = 0.0;
    // How far a long hair's tip curves off its straight line (mm); the
    // range of the hairs' tones as factors of the brows' colour.
    double brow_hair_bend = 0.0;
    glm::dvec2 brow_hair_tone{1.0};

    // albedo variation of the skin (face.json "albedo"; mm, fractions)
    struct Flush {
        glm::dvec2 centre{0.0}, size{0.0};  // |x|, y; Gaussian widths
        double amount = 0.0;
    };
    // a regional cast: a Gaussian field (as Flush) that multiplies the
    // colour by tint, amount 1 at its centre
    struct Tone {
        glm::dvec2 centre{0.0}, size{0.0};
        glm::dvec3 tint{1.0};
        double amount = 0.0;
    };
    struct Albedo {
        double pigment_variation = 0.0, mottling = 0.0;
        // mid-frequency blood blotches: their size (mm) and strength (redness)
        double blotch_size = 1.0, blotch_strength = 0.0;
        std::vector<Flush> flush;
        std::vector<Tone> tones;
        double flush_breakup = 0.0, ear_flush = 0.0, ear_fold_shade = 0.0;
        double freckle_spacing = 0.0, freckle_size = 0.0, freckle_strength = 0.0;
        // Pores: pits centred on a jittered 3D lattice (spacing mm), of
        // radius up to size mm, darkening by up to strength; their strength
        // and size scale with a regional weight, base plus Gaussian fields
        // (a negative amount thins them, as on the lids). Grain: the skin's
        // finer lighter/darker variation, +- grain_strength at grain_size.
        struct Pores {
            double spacing = 1.0, size = 0.3, strength = 0.0, base = 1.0;
            std::vector<Flush> regions;
            double grain_size = 1.0, grain_strength = 0.0;
        } pores;
        // sparse small spots: jittered-grid spacing (mm), chance per cell,
        // size (mm, radius 0.5 .. 1.5 times it), strength 0..1
        struct Spots {
            double spacing = 1.0, chance = 0.0, size = 1.0, strength = 0.0;
        } blemishes, moles;
        glm::dvec3 beard_tint{1.0}, forehead_tint{1.0}, periorbital_tint{1.0};
        double beard_amount = 0.0, forehead_amount = 0.0, periorbital_amount = 0.0;
        double lip_border_mm = 0.0, lip_lines = 0.0;
        // 0 (one even gloss over the lips) .. 1: how far their sheen is broken up.
        double lip_sheen_breakup = 0.0;
        glm::dvec3 lid_margin{0.0};
        // Single fine hairs at the hairline (face_texture.cpp).
        struct FineHairs {
            glm::dvec2 spacing{1.0}, length{1.0};  // mm: across, along the flow; shortest, longest
            double width = 0.1;                     // mm at the root
            glm::dvec3 roots_tint{1.0};
            double roots_amount = 0.0;
        } fine_hairs;
    } albedo;
    // roughness scale per region (the base map's alpha; 1 = skin.json's)
    struct Gloss {
        double t_zone = 1.0, lips = 1.0, lid_margin = 1.0, tear_line = 1.0;
    } gloss;
    // the T-shirt painted over the shoulders and chest (face.json "shirt"):
    // its neckline's height (mm) in front, at the neck's sides and at the
    // back, how far round the neck (degrees of azimuth about the neck's
    // axis) the front's dip reaches, the crew collar's band and the shade
    // it casts on the neck
    struct Shirt {
        glm::dvec3 colour{0.0};  // sRGB 0..255
        double neckline_front = 0.0, neckline_side = 0.0, neckline_back = 0.0;
        double dip_half_angle_deg = 1.0;
        double collar_mm = 0.0, collar_shade = 1.0, rib_mm = 1.0, rib_contrast = 0.0, seam_shade = 0.0;
        double collar_roll = 0.0, edge_mm = 1.0;  // the collar's rolled top edge; the neck-to-collar edge's width
        glm::dvec2 thickness_mm{0.0};              // how far the collar and the body stand off the skin
        double weave_mm = 1.0, weave = 0.0;        // the jersey's wales: spacing, contrast
        double folds = 0.0, fold_count = 0.0, mottling = 0.0;
        double neck_shade_mm = 0.0, neck_shade = 0.0;
    } shirt;
};

FaceParams read_face_params(const std::string& params_dir);

}  // namespace emoface::expression::detail
