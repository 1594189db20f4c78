#pragma once
// The bump-mapping renderer (thesis 4 and 5.5): GLSL 3.3 core, one draw per
// mesh. Per pixel: base colour from the mesh's own UVs (sRGB texture, decoded
// to linear); the normal from the wrinkle map (a second, per-frame UV set)
// brought to world space through the tangent frame (MikkTSpace: B = w N x T);
// then one of two shading models (DrawOptions::shading):
//   Shading::Thesis  Blinn-Phong as in thesis 5.5.1 (ambient + diffuse N.L +
//                    specular (N.H)^s, the specular term only where N.L > 0);
//   Shading::Skin    the skin model of skin_shading.h (scattering, two GGX
//                    lobes with Fresnel, pores, cavities, a light rig, ACES);
// output encoded to sRGB.
// The renderer draws into whatever framebuffer is bound: a Platform's, after
// begin_frame().
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "emoface/expression/mesh.h"
#include "emoface/render/image.h"
#include "emoface/render/skin_shading.h"
#include "emoface/render/tangents.h"

namespace emoface::render {

class Platform;
class WrinkleTexture;

// Colours are linear RGB. In skin shading the light is the rig's key light,
// of colour `diffuse` (for both reflections, as one physical light); the rig
// (SkinShading) replaces `ambient`, and `specular` is not used.
struct Light {
    // w = 0: a directional light, xyz the direction towards the light;
    // w = 1: a point light at xyz (world space). As in fixed-function GL.
    glm::vec4 position{0.0f, 0.0f, 1.0f, 0.0f};
    glm::vec3 ambient{0.12f};
    glm::vec3 diffuse{0.9f};
    glm::vec3 specular{0.25f};
};

struct Camera {
    glm::mat4 view{1.0f};
    glm::mat4 projection{1.0f};
    glm::vec3 position{0.0f, 0.0f, 1.0f};

    // A perspective camera at `eye` looking at `center` (vertical field of
    // view in degrees).
    static Camera look_at(const glm::vec3& eye, const glm::vec3& center, const glm::vec3& up,
                          float fovy_degrees, float aspect, float near_plane, float far_plane);
    // A camera in front of (+z side of) an axis-aligned box, looking down -z,
    // the box filling `fill` of the smaller side of the view.
    static Camera frontal(const glm::vec3& box_min, const glm::vec3& box_max, float aspect,
                          float fovy_degrees = 20.0f, float fill = 0.9f);
};

struct Material {
    // Linear RGB multiplied with the base texture (or used alone without one).
    glm::vec3 base_color{1.0f};
    // sRGB-encoded base colour image (rows top first) sampled with the mesh's
    // texcoords2D, which follow OBJ/OpenGL: v = 0 is the image's bottom row
    // (unlike the wrinkle UVs, whose v runs down the image; see
    // wrinkle_texture.h). null: base_color alone.
    std::shared_ptr<const ImageRGBA8> base_texture;
    // Whether this mesh is skin: bump-mapped with the wrinkle map and, in
    // skin shading, drawn with the skin model (eyeballs, mouth: no; those are
    // drawn as wet tissue, Lambert and one GGX lobe of the roughness that
    // matches `shininess`).
    bool uses_wrinkle_map = true;
    // Blinn-Phong (thesis shading) only.
    glm::vec3 specular_color{1.0f};
    float shininess = 24.0f;
};

enum class Shading {
    Thesis,  // thesis 5.5.1's Blinn-Phong (figure 6.4's reproduction)
    Skin,    // skin_shading.h
};

struct DrawOptions {
    Camera camera;
    Light light;
    Shading shading = Shading::Skin;
    // The skin model's parameters and the rest of its light rig
    // (data/render/skin.json); Shading::Skin only.
    SkinShading skin{};
    glm::mat4 model{1.0f};
    // false draws every mesh with its geometric normal (the side-by-side
    // comparison "without wrinkles").
    bool wrinkles = true;
    bool clear = true;
    glm::vec3 background{0.16f, 0.17f, 0.19f};  // sRGB-encoded clear colour
    // Viewport in pixels of the bound framebuffer; zero size = the whole
    // framebuffer of the platform given to the renderer.
    std::array<int, 4> viewport{0, 0, 0, 0};
    // Projective wrinkle layout done on the GPU: when set, bump-mapped meshes
    // take their wrinkle UVs from their model-space position projected into
    // this box (min.x, min.y, max.x, max.y; u to +x, v down from max.y) and
    // their tangent frames in closed form from the normal, instead of the
    // uploaded UVs and tangents (update_shape() then suffices per frame).
    bool projective_wrinkles = false;
    std::array<float, 4> projective_box{0.0f, 0.0f, 1.0f, 1.0f};
};

// How the wrinkle map's texels hold the tangent-space normal.
enum class NormalEncoding {
    Unsigned,  // n = 2 * texel - 1 (thesis 4.3; 8-bit maps)
    Signed,    // n = texel (float maps holding the vector itself)
};

// Reorders a mesh's triangles (`triangles`: 3 vertex indices each) nearest
// +z first, the frontal camera's side: drawn so, the depth test rejects what
// the face hides (the back of the head, the neck behind the chin, the inner
// lips) before it is shaded instead of after; the picture is the same in any
// order. Runs of kFrontFirstRun triangles in the given order move together,
// sorted by their mean depth (stable), so neighbours keep sharing their
// transformed vertices. Renderer::add_mesh() uses it on GPUs; not on a
// software rasteriser (llvmpipe), where the reordered draw was slower.
inline constexpr std::size_t kFrontFirstRun = 32;
void order_front_first(const expression::TriMesh& mesh, std::vector<std::uint32_t>& triangles);

class Renderer {
public:
    using MeshId = int;

    // Compiles the shaders in the platform's context (made current).
    explicit Renderer(Platform& platform);
    ~Renderer();
    Renderer(const Renderer&) = delete;
    Renderer& operator=(const Renderer&) = delete;

    // Uploads a mesh's topology and base UVs and its current shape (with the
    // base UVs as wrinkle UVs). Meshes are drawn in the order added; on a
    // GPU, a mesh's triangles in order_front_first()'s order.
    MeshId add_mesh(const expression::TriMesh& mesh, const Material& material);

    // The mesh's new shape (points, vertex normals) and wrinkle UVs (one per
    // vertex; empty = the base UVs); tangents are recomputed for the wrinkle
    // UVs. The vertex count must not change.
    void update_mesh(MeshId id, const expression::TriMesh& mesh,
                     const std::vector<glm::vec2>& wrinkle_uvs = {});
    // Same with tangents computed by the caller (one per vertex).
    void update_mesh(MeshId id, const expression::TriMesh& mesh,
                     const std::vector<glm::vec2>& wrinkle_uvs,
                     const std::vector<glm::vec4>& tangents);

    // Only the shape (points, vertex normals): for meshes drawn with
    // DrawOptions::projective_wrinkles, or whose UVs and tangents stay.
    void update_shape(MeshId id, const expression::TriMesh& mesh);

    void set_material(MeshId id, const Material& material);
    // The GL buffers of a mesh's per-frame vertex data, {shape, frame}: shape
    // 6 floats per vertex (position, normal), frame 6 (tangent xyzw, wrinkle
    // UV); for a writer on the GPU (face_geometry.h) instead of update_mesh().
    std::array<unsigned, 2> vertex_buffers(MeshId id) const;
    // Static ambient occlusion, one value per vertex in [0, 1] (1 = open;
    // ambient_occlusion.h); skin shading only. Without it a mesh is open.
    void set_occlusion(MeshId id, const std::vector<float>& occlusion);
    // The key light's cast shadows, baked on the rest shape: the share of
    // the key that reaches each vertex (face_occlusion.h), for a key shining
    // from `toward_key` (model space). Skin shading draws them while the
    // draw's key is near that direction (SkinShading::key_shadow_fade_deg);
    // otherwise, or without them, a contact shadow from the occlusion.
    void set_key_shadow(MeshId id, const std::vector<float>& visibility, const glm::vec3& toward_key);
    std::size_t mesh_count() const;

    // Draws every mesh. `wrinkle_map` null, or options.wrinkles false: flat
    // normals.
    void draw(const DrawOptions& options, const WrinkleTexture* wrinkle_map);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace emoface::render
