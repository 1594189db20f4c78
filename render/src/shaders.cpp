#include "shaders.h"

namespace emoface::render::detail {

// Vertex stage: world-space position, normal and tangent for the fragment
// stage. The thesis (5.5.1) moves the light into tangent space here; the
// frame is instead rebuilt per fragment (MikkTSpace), which gives the same
// lighting on flat triangles and stays right where the frame turns across one.
const char* const kBumpVertexShader = R"GLSL(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 2) in vec4 a_tangent;      // xyz tangent, w handedness
layout(location = 3) in vec2 a_wrinkle_uv;   // per-frame UVs of the wrinkle map
layout(location = 4) in vec2 a_base_uv;      // the mesh's own UVs
layout(location = 5) in float a_occlusion;   // baked ambient occlusion, 1 = open

uniform mat4 u_model;
uniform mat3 u_normal_matrix;
uniform mat4 u_view_projection;
// Projective wrinkle layout (DESIGN.md "Texture layouts"): the wrinkle UVs
// are the model-space position projected frontally into the texture box
// (min.x, min.y, max.x, max.y), v down; the tangent frame of that map is then
// known in closed form, so neither is computed on the CPU.
uniform bool u_projective;
uniform vec4 u_box;

out vec3 v_position;
out vec3 v_normal;
out vec4 v_tangent;
out vec2 v_wrinkle_uv;
out vec2 v_base_uv;
out float v_occlusion;

void main() {
    vec4 world = u_model * vec4(a_position, 1.0);
    v_position = world.xyz;
    v_normal = u_normal_matrix * a_normal;
    vec4 tangent = a_tangent;
    vec2 wrinkle_uv = a_wrinkle_uv;
    if (u_projective) {
        wrinkle_uv = vec2((a_position.x - u_box.x) / (u_box.z - u_box.x),
                          (u_box.w - a_position.y) / (u_box.w - u_box.y));
        // dp/du on the surface is perpendicular to y (v stays put) and to the
        // normal: along y x n, signed to point to +x; dp/dv points down, so
        // the frame is left-handed (w = -1) where the surface faces +z.
        float s = a_normal.z < 0.0 ? -1.0 : 1.0;
        vec3 t = s * vec3(a_normal.z, 0.0, -a_normal.x);
        tangent = dot(t, t) > 1e-12 ? vec4(normalize(t), -s) : vec4(1.0, 0.0, 0.0, -s);
    }
    v_tangent = vec4(mat3(u_model) * tangent.xyz, tangent.w);
    v_wrinkle_uv = wrinkle_uv;
    v_base_uv = a_base_uv;
    v_occlusion = a_occlusion;
    gl_Position = u_view_projection * world;
}
)GLSL";

// Fragment stage, two models (renderer.h, skin_shading.h):
//   thesis: 5.5.1's Blinn-Phong in linear light, written out sRGB-encoded
//           (the framebuffer is plain RGBA8, so the encoding is the same on
//           every GL and the PNG holds what was computed);
//   skin:   pre-integrated scattering, two GGX lobes with Fresnel, pores,
//           cavity and specular occlusion, a key/fill/rim/hemisphere rig
//           (the full model for the key light; fill and rim reduced to
//           wrapped Lambert and one GGX lobe),
//           exposure and tone mapping, then the same sRGB encoding.
// Light intensities follow the thesis's convention: a light of colour I
// lights a white Lambert surface facing it to I (I = E / pi), so a BRDF f
// contributes pi f (N.L) I.
const char* const kBumpFragmentShader = R"GLSL(#version 330 core
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_wrinkle_uv;
in vec2 v_base_uv;
in float v_occlusion;

uniform sampler2D u_base_map;     // sRGB texture: sampled as linear
uniform bool u_has_base_map;
uniform vec3 u_base_color;        // linear
uniform sampler2D u_wrinkle_map;  // rgb normal, a cavity (1 = none)
uniform bool u_use_wrinkle_map;
uniform bool u_wrinkle_signed;    // texel = n (float maps) or 0.5 + 0.5 n

uniform vec4 u_light_position;    // w = 0: direction towards the light
uniform vec3 u_light_ambient;
uniform vec3 u_light_diffuse;
uniform vec3 u_light_specular;
uniform vec3 u_specular_color;
uniform float u_shininess;
uniform vec3 u_camera_position;

// Skin model (u_skin_model false: thesis Blinn-Phong).
uniform bool u_skin_model;
uniform bool u_skin_surface;        // this mesh is skin (else a wet, glossy part)
uniform sampler2D u_scatter_table;  // N.L x curvature -> rgb diffuse
uniform float u_max_curvature;      // 1/mm at the table's top row
uniform float u_mm_per_unit;
uniform vec2 u_normal_softening;   // red; green and blue
uniform float u_cavity_direct;
uniform sampler2D u_pore_map;       // rgb normal, a cavity
uniform float u_pore_tiles;
uniform float u_pore_strength;
uniform sampler2D u_detail_map;     // rg: the base colour's relief, 0.5 + 0.5 slope per base UV; b: hair (skin_maps.h);
                                    // a: the share of the key the rest shape gets (its baked shadows)
uniform float u_albedo_bump;        // detail height (scene units) per unit of the relief, x the map's slope scale
uniform float u_f0;
uniform vec2 u_roughness;
uniform float u_lobe_weight;
uniform float u_gloss_exponent;     // roughness x gloss^this (gloss: the base map's alpha)
uniform vec2 u_sheen_intensity;     // direct sheen at gloss 1 (matte), gloss at which it is full
uniform vec3 u_occlusion;           // how far the baked occlusion dims: key, fill/rim/sky diffuse, specular
uniform vec2 u_key_cone;            // the key's contact shadow: the open cone's lean, its narrowest cos
uniform vec2 u_key_shadow;          // the baked cast shadow: how far it stands (1: the key is where it was baked), its depth
uniform float u_min_curvature;      // table coordinate: the flattest skin still scatters
uniform float u_wrap;               // the rig lights' softness (wrapped N.L, energy kept)
uniform vec3 u_hair;                // hair: wrap, roughness, the lights' sheen
uniform vec4 u_wet;                 // eyes, mouth: F0, broad lobe's roughness, its weight, tight lobe's scale
uniform float u_wet_sheen;          // eyes, mouth: the scale of the lights' reflections
uniform vec3 u_key_tint;
uniform vec3 u_fill_direction;     // unit vectors
uniform vec3 u_fill_colour;
uniform vec3 u_rim_direction;
uniform vec3 u_rim_colour;
uniform vec3 u_sky;
uniform vec3 u_ground;
uniform float u_exposure;
uniform bool u_tone_map;

out vec4 frag_color;

const float PI = 3.14159265;

vec3 srgb_encode(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    vec3 lo = 12.92 * c;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(lo, hi, step(vec3(0.0031308), c));
}

// ACES filmic fit (Narkowicz 2015): 0 -> 0, monotonic, rolls off to 1.
vec3 tone_map(vec3 x) {
    x = max(x, vec3(0.0));
    return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), 0.0, 1.0);
}

// Schlick's Fresnel.
float fresnel(float f0, float cos_theta) {
    float m = 1.0 - clamp(cos_theta, 0.0, 1.0);
    float m2 = m * m;
    return f0 + (1.0 - f0) * m2 * m2 * m;
}

// GGX D times the height-correlated Smith visibility G / (4 N.L N.V), the
// latter in Hammon's linear fit (2017): no square roots, within a few
// per cent of the exact term at the skin's roughness.
float ggx_dv(float a, float n_dot_h, float n_dot_l, float n_dot_v) {
    float a2 = a * a;
    float d = n_dot_h * n_dot_h * (a2 - 1.0) + 1.0;
    float dist = a2 / (PI * d * d);
    return dist * 0.5 / max(mix(2.0 * n_dot_l * n_dot_v, n_dot_l + n_dot_v, a), 1e-6);
}

// Split-sum environment BRDF, analytic fit (Karis 2014, "mobile").
float environment_brdf(float f0, float roughness, float n_dot_v) {
    const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
    const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
    vec4 r = roughness * c0 + c1;
    float a004 = min(r.x * r.x, exp2(-9.28 * n_dot_v)) * r.x + r.y;
    vec2 ab = vec2(-1.04, 1.04) * a004 + r.zw;
    return f0 * ab.x + ab.y;
}

// Lagarde & de Rousiers 2014: reflections fade inside an occluded cavity.
float specular_occlusion(float n_dot_v, float ao, float roughness) {
    return clamp(pow(n_dot_v + ao, exp2(-16.0 * roughness - 1.0)) - 1.0 + ao, 0.0, 1.0);
}

vec3 hemisphere(vec3 dir) {
    return mix(u_ground, u_sky, 0.5 + 0.5 * dir.y);
}

struct Surface {
    vec3 n;          // shading normal (bumped, pores)
    vec3 v;          // towards the eye
    float n_dot_v;
    vec3 n_r, n_g;   // softened diffuse normals (skin): red; green and blue
    vec3 diffuse_albedo;  // albedo x the diffuse share (1 - sheen)
    float direct_cavity;  // the cavity's dimming of direct diffuse light
    float curvature; // table row coordinate in [0, 1]
    float hair;      // 1 on hair: plain diffuse instead of skin's scattering
    float f0;
    vec2 alpha;      // GGX alpha of the two lobes
    float alpha_mean;  // one lobe standing for both (fill and rim)
    float lobe_weight;
    float cavity;    // 1 open skin, 0 a deep crevice
    float direct_sheen;   // the region's scale of the lights' sheen
    float key_cone;       // the key's contact shadow: cos of the open cone's half-angle
    float key_visible;    // the baked share of the key that reaches the rest shape
    float dim_shadow;     // ... of the fill's, the rim's and the sky's
    float dim_sheen;      // specular occlusion of the fill, the rim and the sky
};

// One light's contribution (colour `c`, direction `l` towards it). `full`
// (a constant at each call, so the compiler drops the other branch): the
// key light's model, red's and green-blue's softened normals looked up in
// the scattering table and the two GGX lobes. Otherwise the dim lights'
// (fill, rim) reduced model: wrapped Lambert at the green-blue softened
// normal (what the table's flattest row holds) and one lobe standing for
// both.
// `glossy` (a constant at each call): whether the light has a sheen; the
// rim's, from behind, fell on skin turned away from the camera and changed
// the 1920x1080 frame by PSNR 51.6 dB, for 0.044 ms of the H100's draw
// (docs/PERFORMANCE.md, session 8).
// The rig's lights are soft boxes, not points: N.L is wrapped by w,
// (N.L + w) / (1 + w), and the result divided by 1 + w so that the light
// a surface gets over all directions stays the same (the terminator moves
// past 90 degrees and softens; nothing is added).
vec3 shade_light(Surface s, vec3 l, vec3 c, const bool full, const bool glossy) {
    vec3 diffuse;
    // The key's shadows. Baked for the key where it stands by default
    // (face_occlusion.h: its cast shadows on the rest shape, the nose's on
    // the cheek and lip, the brows' in the sockets, the jaw's on the neck):
    // u_key_shadow.x is 1 there, fading to 0 as the key moves away from it
    // (the viewer's light), where a contact shadow from the baked ambient
    // occlusion ao stands in: a point open to a cone of half-angle t has
    // ao = sin^2 t (cosine weighted), so it sees the key only where the
    // cone's axis . L > cos t. On a face most occluders lie above (brows
    // over the eyes, the nose over the lip, the jaw over the neck), so the
    // axis leans down from the normal by u_key_cone.x (1 - ao)
    // (unnormalised: the lean's dot with L). Both are of the rest shape,
    // stale where the face moves (a raised lid bares skin that was inside
    // its fold): the cone is never narrower than u_key_cone.y, so skin
    // facing the key is lit. Soft over 0.3 (the key is a soft box);
    // u_occlusion.x of it applies.
    float visible = 1.0;
    if (full && u_skin_surface) {
        if (u_key_shadow.x < 1.0) {
            float toward = dot(s.n_g, l) - u_key_cone.x * s.key_cone * s.key_cone * l.y;
            visible = mix(1.0, smoothstep(s.key_cone - 0.3, s.key_cone, toward), u_occlusion.x);
        }
        visible = mix(visible, 1.0 - u_key_shadow.y * (1.0 - s.key_visible), u_key_shadow.x);
    }
    if (u_skin_surface) {
        float wrap_scale = 1.0 / (1.0 + u_wrap);
        if (full) {
            vec2 n_dot_l = (vec2(dot(s.n_r, l), dot(s.n_g, l)) + u_wrap) * wrap_scale;
            vec2 u = clamp(0.5 + 0.5 * n_dot_l, 0.0, 1.0);
            // Green and blue share a softened normal and so one lookup.
            vec3 green_blue = textureLod(u_scatter_table, vec2(u.y, s.curvature), 0.0).rgb;
            diffuse = vec3(textureLod(u_scatter_table, vec2(u.x, s.curvature), 0.0).r, green_blue.gb);
            diffuse *= wrap_scale * visible;
        } else {
            // The table's flattest row is Lambert to 0.015 (a dim light's
            // red terminator is not seen), so no lookup.
            diffuse = vec3(clamp((dot(s.n_g, l) + u_wrap) * wrap_scale, 0.0, 1.0) * (wrap_scale * s.dim_shadow));
        }
        // Hair scatters no light under its surface: wrapped Lambert. A
        // branch, since most of the face is skin (coherent over a warp).
        if (s.hair > 0.0) {
            float hair_wrap_scale = 1.0 / (1.0 + u_hair.x);
            float lambert = max(dot(s.n, l) + u_hair.x, 0.0) * hair_wrap_scale * hair_wrap_scale *
                            (full ? visible : s.dim_shadow);
            diffuse = mix(diffuse, vec3(lambert), s.hair);
        }
        diffuse *= s.direct_cavity;
    } else {
        diffuse = vec3(max(dot(s.n, l), 0.0));
    }
    // Light that the sheen reflects does not enter the skin.
    vec3 color = diffuse * s.diffuse_albedo;
    float n_dot_l = dot(s.n, l);
    if (glossy && n_dot_l > 0.0) {
        vec3 h = normalize(l + s.v);
        float n_dot_h = max(dot(s.n, h), 0.0);
        float lobes = full ? s.lobe_weight * ggx_dv(s.alpha.x, n_dot_h, n_dot_l, s.n_dot_v) +
                                 (1.0 - s.lobe_weight) * ggx_dv(s.alpha.y, n_dot_h, n_dot_l, s.n_dot_v)
                           : ggx_dv(s.alpha_mean, n_dot_h, n_dot_l, s.n_dot_v);
        float sheen = PI * lobes * fresnel(s.f0, dot(l, h)) * n_dot_l * s.direct_sheen;
        color += vec3(sheen * (full ? visible : s.dim_sheen));
    }
    return color * c;
}

// `gloss`: the base map's alpha, the region's roughness scale (lips, the
// tear line and the T-zone below 1; 1 where a map has no such regions).
// `slope`: the base colour's relief (its log-luminance above its local mean,
// baked at load), d height / d base UV in scene units: hair strands, brow
// hairs and lip lines stand out of the darker gaps between them.
// `hair`: 1 on the scalp's hair and the brows (the relief map's third
// channel), whose diffuse light is plain and whose sheen is one broad, dim
// lobe.
// `key_visible`: the share of the key that reaches the rest shape there (the
// detail map's alpha; 1 without it).
vec3 shade_skin(vec3 n_bumped, vec3 n_geo, vec3 base, float cavity, float gloss, vec2 slope, float hair,
                float key_visible) {
    Surface s;
    s.v = normalize(u_camera_position - v_position);
    s.cavity = cavity;
    s.direct_sheen = 1.0;
    s.hair = hair;
    s.f0 = u_f0;
    vec2 roughness;
    float occlusion = 1.0;
    if (u_skin_surface) {
        // Regions: matte cheeks and lower face (gloss 1) reflect the lights
        // dimly through a broad lobe; the oilier T-zone, the moist lips
        // and the wet lid margins (gloss below 1) sharper and fuller.
        float g = clamp(gloss, 0.3, 1.0);
        roughness = u_roughness * pow(g, u_gloss_exponent);
        s.direct_sheen = mix(mix(1.0, u_sheen_intensity.x, smoothstep(u_sheen_intensity.y, 1.0, g)), u_hair.z, hair);
        roughness = mix(roughness, vec2(u_hair.y), hair);
        occlusion = v_occlusion;
        s.lobe_weight = u_lobe_weight;
        // Pores, in the frame of the base UVs built from screen derivatives
        // (Schueler 2006); their filtered normal's shortening (Toksvig)
        // widens the lobes where pores are smaller than a pixel.
        vec2 uv = v_base_uv * u_pore_tiles;
        vec4 pore = texture(u_pore_map, uv);
        vec3 pn = pore.rgb * 2.0 - 1.0;
        float shortening = clamp(length(pn), 1e-3, 1.0);
        vec3 dp1 = dFdx(v_position), dp2 = dFdy(v_position);
        vec2 duv1 = dFdx(uv), duv2 = dFdy(uv);
        vec3 dp2perp = cross(dp2, n_bumped), dp1perp = cross(n_bumped, dp1);
        vec3 t = dp2perp * duv1.x + dp1perp * duv2.x;
        vec3 b = dp2perp * duv1.y + dp1perp * duv2.y;
        float scale = max(dot(t, t), dot(b, b));
        s.n = n_bumped;
        if (scale > 1e-20) {
            scale = inversesqrt(scale);
            vec3 tilted = n_bumped * pn.z + u_pore_strength * scale * (t * pn.x + b * pn.y);
            if (dot(tilted, tilted) > 1e-12) s.n = normalize(tilted);
        }
        // The albedo's relief as a bump (Mikkelsen 2010, surface gradient):
        // t and b are the frame of uv = base UV x tiles scaled by det, so
        // the height's gradient is (h_u t + h_v b) / (tiles det).
        float det = dot(dp1, dp2perp);
        vec3 gradient = sign(det) * (slope.x * t + slope.y * b);
        vec3 detailed = abs(det) * s.n - gradient;
        if (dot(detailed, detailed) > 1e-20) s.n = normalize(detailed);
        float variance = u_pore_strength * u_pore_strength * (1.0 - shortening) / shortening;
        roughness = sqrt(clamp(roughness * roughness + vec2(variance), 0.0, 1.0));
        s.cavity = cavity * pore.a;
        // Curvature of the geometric surface (Penner): |dN| / |dP| in 1/mm,
        // at least the flattest skin's (light scatters a few mm in red even
        // where the surface is flat at that scale: a red, soft terminator).
        // Rates over both screen axes as sums of squares (the Frobenius
        // norms of dN and dP: one square root; dp1, dp2 are the pores').
        vec3 dn1 = dFdx(n_geo), dn2 = dFdy(n_geo);
        float dn = dot(dn1, dn1) + dot(dn2, dn2);
        float dp = (dot(dp1, dp1) + dot(dp2, dp2)) * (u_mm_per_unit * u_mm_per_unit);
        s.curvature = clamp(sqrt(dn / max(dp, 1e-12)) / u_max_curvature, u_min_curvature, 1.0);
        // Each channel sees a normal softened towards the geometric one;
        // the same for every light, so made once here.
        s.n_r = normalize(mix(s.n, n_geo, u_normal_softening.x));
        s.n_g = normalize(mix(s.n, n_geo, u_normal_softening.y));
    } else {
        // Eyes, mouth: wet. A tight lobe, sharper than the roughness that
        // matches the Blinn-Phong exponent (Walter et al. 2007: alpha =
        // sqrt(2 / (s + 2))), and a weak broad one, under the tear film's
        // Fresnel.
        float alpha = sqrt(2.0 / (u_shininess + 2.0));
        roughness = vec2(sqrt(alpha) * u_wet.w, u_wet.y);
        s.lobe_weight = 1.0 - u_wet.z;
        s.f0 = u_wet.x;
        s.direct_sheen = u_wet_sheen;
        s.n = n_bumped;
        s.n_r = s.n_g = s.n;
        s.curvature = 0.0;
    }
    s.alpha = max(roughness * roughness, vec2(1e-3));
    // The cavity dims F0 (Jimenez et al. 2013): crevices lose their sheen.
    s.f0 *= s.cavity;
    s.n_dot_v = max(dot(s.n, s.v), 1e-4);
    float mean_roughness = mix(roughness.y, roughness.x, s.lobe_weight);
    s.alpha_mean = max(mean_roughness * mean_roughness, 1e-3);
    float sheen = environment_brdf(s.f0, mean_roughness, s.n_dot_v);
    float diffuse_share = 1.0 - sheen;
    s.diffuse_albedo = base * diffuse_share;
    s.direct_cavity = mix(1.0, s.cavity, u_cavity_direct);
    // The baked occlusion (eye sockets, nostrils, mouth corners, under the
    // jaw, the ears, the hairline) stands for the shadows the rig's broad
    // lights would cast there: fully for the sky, mostly for the fill and
    // the rim, and for the key where it grazes when the key is off the
    // direction its shadows were baked for (shade_light). With the wrinkle
    // and pore cavity it also fades the sheen (Lagarde & de Rousiers 2014).
    s.key_cone = min(sqrt(max(1.0 - occlusion, 0.0)), u_key_cone.y);
    s.key_visible = key_visible;
    s.dim_shadow = mix(1.0, occlusion, u_occlusion.y);
    float ambient_open = s.cavity * mix(1.0, occlusion, u_occlusion.z);
    s.dim_sheen = specular_occlusion(s.n_dot_v, ambient_open, mean_roughness);

    vec3 key = u_light_position.w == 0.0 ? normalize(u_light_position.xyz)
                                         : normalize(u_light_position.xyz - v_position);
    vec3 color = shade_light(s, key, u_light_diffuse * u_key_tint, true, true);
    color += shade_light(s, u_fill_direction, u_fill_colour, false, true);
    color += shade_light(s, u_rim_direction, u_rim_colour, false, false);

    // The sky/ground hemisphere: diffuse from the softest normal, specular
    // by the environment BRDF towards the reflection, both occluded.
    color += hemisphere(s.n_r) * s.diffuse_albedo * (s.cavity * s.dim_shadow);
    color += hemisphere(reflect(-s.v, s.n)) * sheen * s.dim_sheen;
    // The mouth interior's baked occlusion (face_occlusion.h) stands for the
    // lips and cheeks over an open mouth: they shade it from every light
    // (the eyes have none: 1).
    if (!u_skin_surface) color *= v_occlusion;
    return color;
}

void main() {
    float facing = gl_FrontFacing ? 1.0 : -1.0;
    vec3 vn = facing * v_normal;
    vec3 n = normalize(vn);
    vec3 n_geo = n;
    float cavity = 1.0;
    if (u_use_wrinkle_map) {
        vec4 texel = texture(u_wrinkle_map, v_wrinkle_uv);
        vec3 t = texel.rgb;
        if (!u_wrinkle_signed) t = t * 2.0 - 1.0;   // thesis 4.3: [0,1] -> [-1,1]
        cavity = clamp(texel.a, 0.0, 1.0);
        // MikkTSpace's pixel-shader rule: unnormalised interpolated frame,
        // bitangent rebuilt from the handedness.
        vec3 vt = facing * v_tangent.xyz;
        vec3 vb = v_tangent.w * cross(vn, vt);
        vec3 bumped = t.x * vt + t.y * vb + t.z * vn;
        if (dot(bumped, bumped) > 1e-12) n = normalize(bumped);
    }
    vec3 base = u_base_color;
    float gloss = 1.0;
    vec2 slope = vec2(0.0);
    float hair = 0.0;
    float key_visible = 1.0;
    if (u_has_base_map) {
        vec4 texel = texture(u_base_map, v_base_uv);
        base *= texel.rgb;
        if (u_skin_model) {
            gloss = texel.a;
            if (u_skin_surface && u_albedo_bump > 0.0) {
                vec4 detail = texture(u_detail_map, v_base_uv);
                slope = (u_albedo_bump / u_pore_tiles) * (detail.rg * 2.0 - 1.0);
                hair = detail.b;
                key_visible = detail.a;
            }
        }
    }

    if (u_skin_model) {
        vec3 color = u_exposure * shade_skin(n, n_geo, base, cavity, gloss, slope, hair, key_visible);
        frag_color = vec4(srgb_encode(u_tone_map ? tone_map(color) : color), 1.0);
        return;
    }

    vec3 l = u_light_position.w == 0.0 ? normalize(u_light_position.xyz)
                                       : normalize(u_light_position.xyz - v_position);
    float n_dot_l = max(0.0, dot(n, l));
    // The thesis adds the light's ambient colour as is; here it is modulated
    // by the base colour, so the unlit side keeps the skin's hue.
    vec3 color = u_light_ambient * base + u_light_diffuse * n_dot_l * base;
    if (n_dot_l > 0.0) {
        vec3 v = normalize(u_camera_position - v_position);
        vec3 h = normalize(l + v);
        float n_dot_h = max(0.0, dot(n, h));
        color += u_light_specular * u_specular_color * pow(n_dot_h, u_shininess);
    }
    frag_color = vec4(srgb_encode(color), 1.0);
}
)GLSL";

}  // namespace emoface::render::detail
