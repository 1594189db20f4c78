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
    gl_Position = u_view_projection * world;
}
)GLSL";

// Fragment stage: thesis 5.5.1's Blinn-Phong, in linear light, written out
// sRGB-encoded (the framebuffer is plain RGBA8, so the encoding is the same
// on every GL and the PNG holds what was computed).
const char* const kBumpFragmentShader = R"GLSL(#version 330 core
in vec3 v_position;
in vec3 v_normal;
in vec4 v_tangent;
in vec2 v_wrinkle_uv;
in vec2 v_base_uv;

uniform sampler2D u_base_map;     // sRGB texture: sampled as linear
uniform bool u_has_base_map;
uniform vec3 u_base_color;        // linear
uniform sampler2D u_wrinkle_map;
uniform bool u_use_wrinkle_map;
uniform bool u_wrinkle_signed;    // texel = n (float maps) or 0.5 + 0.5 n

uniform vec4 u_light_position;    // w = 0: direction towards the light
uniform vec3 u_light_ambient;
uniform vec3 u_light_diffuse;
uniform vec3 u_light_specular;
uniform vec3 u_specular_color;
uniform float u_shininess;
uniform vec3 u_camera_position;

out vec4 frag_color;

vec3 srgb_encode(vec3 c) {
    c = clamp(c, 0.0, 1.0);
    vec3 lo = 12.92 * c;
    vec3 hi = 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055;
    return mix(lo, hi, step(vec3(0.0031308), c));
}

void main() {
    float facing = gl_FrontFacing ? 1.0 : -1.0;
    vec3 vn = facing * v_normal;
    vec3 n = normalize(vn);
    if (u_use_wrinkle_map) {
        vec3 t = texture(u_wrinkle_map, v_wrinkle_uv).rgb;
        if (!u_wrinkle_signed) t = t * 2.0 - 1.0;   // thesis 4.3: [0,1] -> [-1,1]
        // MikkTSpace's pixel-shader rule: unnormalised interpolated frame,
        // bitangent rebuilt from the handedness.
        vec3 vt = facing * v_tangent.xyz;
        vec3 vb = v_tangent.w * cross(vn, vt);
        vec3 bumped = t.x * vt + t.y * vb + t.z * vn;
        if (dot(bumped, bumped) > 1e-12) n = normalize(bumped);
    }
    vec3 l = u_light_position.w == 0.0 ? normalize(u_light_position.xyz)
                                       : normalize(u_light_position.xyz - v_position);
    vec3 base = u_base_color;
    if (u_has_base_map) base *= texture(u_base_map, v_base_uv).rgb;

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
