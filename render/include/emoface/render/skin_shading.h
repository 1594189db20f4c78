#pragma once
// The parameters of the skin shading model (Renderer, Shading::Skin) and its
// default light rig. The values people tune live in data/render/skin.json,
// each with its source (docs FIDELITY.md section 5); the defaults below are
// that file's values (a test keeps them in step), so a program that loads
// nothing still draws the same skin.
//
// The model, per pixel:
//   diffuse   pre-integrated subsurface scattering (Penner & Borshukov 2011):
//             a lookup table of the d'Eon-Luebke diffusion profile integrated
//             over a ring of curvature 1/r, indexed by N.L and the surface's
//             curvature (from screen-space derivatives); per colour channel a
//             normal softened towards the geometric one (red scatters farthest);
//   specular  two GGX lobes (roughness a, b; weight of a) with Schlick Fresnel
//             from F0 (skin n = 1.4 gives 0.028); F0 scaled by the cavity
//             (wrinkle map alpha, pore pits) so cavities lose their sheen;
//   pores     a tiled, deterministic pore normal map generated at load
//             (mipmapped; the length of its filtered normal widens the lobes,
//             Toksvig, so pores too small to see still roughen the sheen);
//   regions   the base map's alpha scales both roughnesses (the painter's
//             regions: lips, the tear line, the T-zone glossier than the
//             cheeks; 1, the skin.json values, where a map has no alpha);
//   detail    the base colour's fine log-luminance contrast (above its local
//             mean) as a height, baked into slopes when first drawn: hair
//             strands, brow hairs and lip lines catch the light along their
//             direction;
//   light     the draw's key light, a fill and a rim light, a sky/ground
//             hemisphere with specular occlusion (Lagarde & de Rousiers 2014)
//             in the cavities; the sum is exposed, tone mapped (ACES fit,
//             Narkowicz 2015) and encoded to sRGB.
#include <array>
#include <string>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace emoface::render {

// One Gaussian of the sum-of-Gaussians diffusion profile
// R(d) = sum_i weight_i * exp(-d^2 / (2 v_i)) / (2 pi v_i), d in mm.
struct ScatterGaussian {
    float variance_mm2 = 0.0f;
    glm::vec3 weight{0.0f};
    bool operator==(const ScatterGaussian& o) const {
        return variance_mm2 == o.variance_mm2 && weight == o.weight;
    }
};

// A directional light of the rig: direction towards the light (world space,
// need not be unit length), linear RGB intensity (1 lights a white Lambert
// surface facing it to 1).
struct RigLight {
    glm::vec3 direction{0.0f, 0.0f, 1.0f};
    glm::vec3 colour{0.0f};
    bool operator==(const RigLight& o) const {
        return direction == o.direction && colour == o.colour;
    }
};

// The procedural pore map: a square tile of `size` texels holding a
// jittered grid of `cells` x `cells` pits (a cell of `cells`-th of the tile)
// over the skin's microrelief, crossing families of meandering furrows.
struct PoreMapSpec {
    int size = 256;
    int cells = 28;
    float pit_radius = 0.32f;   // of a cell
    float pit_depth = 1.0f;     // relative to the noise's amplitude (1)
    float noise_scale = 0.35f;  // amplitude of the fine noise beside the pits
    unsigned seed = 1u;
    bool operator==(const PoreMapSpec& o) const {
        return size == o.size && cells == o.cells && pit_radius == o.pit_radius &&
               pit_depth == o.pit_depth && noise_scale == o.noise_scale && seed == o.seed;
    }
};

enum class ToneMapping {
    Aces,  // ACES filmic fit (Narkowicz 2015): monotonic, 0 -> 0, highlights roll off
    None,  // linear, clamped to [0, 1] (measurements, tests)
};

struct SkinShading {
    // --- diffuse: pre-integrated scattering ---
    // d'Eon & Luebke 2007 (GPU Gems 3 ch. 14), six Gaussians.
    std::array<ScatterGaussian, 6> profile{{
        {0.0064f, {0.233f, 0.455f, 0.649f}},
        {0.0484f, {0.100f, 0.336f, 0.344f}},
        {0.187f, {0.118f, 0.198f, 0.000f}},
        {0.567f, {0.113f, 0.007f, 0.007f}},
        {1.99f, {0.358f, 0.004f, 0.000f}},
        {7.41f, {0.078f, 0.000f, 0.000f}},
    }};
    // Curvature range of the lookup table (1/mm); flatter is Lambert.
    float max_curvature = 0.5f;
    // The flattest skin is looked up as this curved (1/mm): red light
    // scatters several mm, so even a broad forehead's terminator is soft
    // and reddish rather than a plastic Lambert edge.
    float min_curvature = 0.1f;
    // Millimetres per scene unit (the default face is modelled in mm).
    float mm_per_unit = 1.0f;
    // How far the diffuse normal leans from the bumped normal to the
    // geometric one (Penner's softened normals: red scatters farthest), for
    // red and for green and blue (one lookup of the table for both).
    glm::vec2 normal_softening{0.3f, 0.1f};
    // How much the wrinkle cavity darkens direct diffuse light (ambient light
    // is darkened fully).
    float cavity_direct = 0.9f;

    // --- specular: two GGX lobes with Fresnel ---
    float f0 = 0.028f;
    std::array<float, 2> roughness{0.45f, 0.7f};
    float lobe_weight = 0.85f;  // of roughness[0]; the other lobe gets the rest
    // Regions (the base map's alpha g, 1 on cheeks and the lower face):
    // roughness x g^gloss_exponent, and the lights' sheen scaled from
    // matte_sheen at g = 1 up to 1 at g <= full_sheen_gloss (the T-zone,
    // lips, lid margins).
    float gloss_exponent = 2.0f;
    float matte_sheen = 0.55f;
    float full_sheen_gloss = 0.8f;

    // --- baked ambient occlusion (ambient_occlusion.h): how far it dims ---
    float occlusion_key = 0.4f;        // the key's light where it grazes (a key off its baked shadows' direction)
    float occlusion_fill = 0.8f;       // the fill's, the rim's and the sky's diffuse light
    float occlusion_specular = 1.0f;   // the sky's, the fill's and the rim's sheen
    float occlusion_key_lean = 0.5f;   // how far an occluded point's open cone leans down (occluders above)
    float occlusion_key_cone_max = 0.5f;  // the narrowest open cone's cos (the rest shape's occlusion is stale where the face moves)
    // The key's baked cast shadows (Renderer::set_key_shadow): how deep
    // (1: no key light in them), and the angles off the direction they were
    // baked for at which they start and finish fading out.
    float key_shadow = 1.0f;
    std::array<float, 2> key_shadow_fade_deg{5.0f, 20.0f};

    // --- pores ---
    PoreMapSpec pores{};
    float pore_tiles = 48.0f;    // pore tiles per unit of the base UVs
    float pore_strength = 0.8f;  // scale of the pore normals' tilt

    // --- detail from the albedo ---
    float albedo_bump_mm = 0.8f;   // height per unit of log-luminance contrast
    float albedo_bump_bias = 2.0f;  // the mean's extent, in mip levels (skin_maps.h)

    // --- hair: where the base colour's local mean is dark (skin_maps.h) ---
    // Hair does not scatter light like skin (no red terminator) and its
    // sheen is broad and dim, not skin's.
    std::array<float, 2> hair_luminance{0.06f, 0.13f};  // linear mean luminance: all hair .. all skin
    float hair_wrap = 0.05f;       // N.L wrap of the rig lights on hair (skin: softness)
    float hair_roughness = 0.75f;  // one GGX roughness for both lobes
    float hair_sheen = 0.3f;       // the lights' sheen on hair, of skin's full sheen

    // --- wet parts (the eyes, the mouth's inside): a tight lobe of the
    // material's shininess plus a weak broad one (a moist film) ---
    float wet_f0 = 0.025f;
    float wet_broad_roughness = 0.45f;
    float wet_broad_weight = 0.1f;
    float wet_tight_scale = 1.2f;  // the tight lobe's roughness, of the shininess's (Walter et al. 2007)
    float wet_sheen = 4.0f;        // the lights' reflections on wet parts: the soft boxes' radiance over a point light's

    // --- light rig (the key light is the draw's Light, tinted) ---
    glm::vec3 key_tint{1.06f, 0.98f, 0.88f};
    float softness = 0.1f;  // wrap of every rig light's N.L (soft boxes), energy kept
    RigLight fill{{0.5f, 0.1f, 0.86f}, {0.11f, 0.125f, 0.155f}};
    RigLight rim{{0.5f, 0.6f, -0.65f}, {0.2f, 0.19f, 0.17f}};
    glm::vec3 sky{0.1f, 0.11f, 0.13f};      // ambient from above (+y)
    glm::vec3 ground{0.08f, 0.06f, 0.05f};  // ambient from below (warm bounce)
    float exposure = 0.9f;
    ToneMapping tone_mapping = ToneMapping::Aces;

    bool operator==(const SkinShading& o) const {
        return profile == o.profile && max_curvature == o.max_curvature &&
               mm_per_unit == o.mm_per_unit && normal_softening == o.normal_softening &&
               min_curvature == o.min_curvature &&
               cavity_direct == o.cavity_direct && f0 == o.f0 && roughness == o.roughness &&
               lobe_weight == o.lobe_weight && gloss_exponent == o.gloss_exponent &&
               matte_sheen == o.matte_sheen && full_sheen_gloss == o.full_sheen_gloss &&
               occlusion_key == o.occlusion_key && occlusion_fill == o.occlusion_fill &&
               occlusion_specular == o.occlusion_specular &&
               occlusion_key_lean == o.occlusion_key_lean && occlusion_key_cone_max == o.occlusion_key_cone_max && key_tint == o.key_tint &&
               softness == o.softness && pores == o.pores && pore_tiles == o.pore_tiles &&
               pore_strength == o.pore_strength && albedo_bump_mm == o.albedo_bump_mm &&
               albedo_bump_bias == o.albedo_bump_bias && hair_luminance == o.hair_luminance &&
               hair_wrap == o.hair_wrap && hair_roughness == o.hair_roughness && hair_sheen == o.hair_sheen &&
               wet_f0 == o.wet_f0 && wet_broad_roughness == o.wet_broad_roughness &&
               wet_broad_weight == o.wet_broad_weight && wet_tight_scale == o.wet_tight_scale && wet_sheen == o.wet_sheen && fill == o.fill && rim == o.rim &&
               sky == o.sky && ground == o.ground && exposure == o.exposure &&
               tone_mapping == o.tone_mapping;
    }
    bool operator!=(const SkinShading& o) const { return !(*this == o); }
};

// Reads data/render/skin.json (every key required; keys starting with _
// are comments). Throws emoface::InputError naming the file and the key.
SkinShading load_skin_shading(const std::string& path);

}  // namespace emoface::render
