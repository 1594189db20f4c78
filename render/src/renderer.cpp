#include "emoface/render/renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <string>

#include <glm/gtc/matrix_inverse.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/trigonometric.hpp>

#include "emoface/render/platform.h"
#include "emoface/render/wrinkle_texture.h"
#include "gl_util.h"
#include "shaders.h"
#include "skin_maps.h"

namespace emoface::render {

using detail::check_gl;

Camera Camera::look_at(const glm::vec3& eye, const glm::vec3& center, const glm::vec3& up,
                       float fovy_degrees, float aspect, float near_plane, float far_plane) {
    Camera c;
    c.view = glm::lookAt(eye, center, up);
    c.projection = glm::perspective(glm::radians(fovy_degrees), aspect, near_plane, far_plane);
    c.position = eye;
    return c;
}

// 32 triangles a run: on the H100 (row A of frame_e2e, skin shading) runs of
// 16 to 128 drew within 1% of each other, single triangles 40% slower (lost
// vertex reuse), 256 3% slower.
void order_front_first(const expression::TriMesh& mesh, std::vector<std::uint32_t>& triangles) {
    const std::size_t n = triangles.size() / 3;
    const std::size_t runs = (n + kFrontFirstRun - 1) / kFrontFirstRun;
    std::vector<float> depth(runs, 0.0f);
    for (std::size_t t = 0; t < n; ++t)
        for (std::size_t c = 0; c < 3; ++c)
            depth[t / kFrontFirstRun] += mesh.point(mesh.vertex_handle(int(triangles[3 * t + c])))[2];
    std::vector<std::uint32_t> order(runs);
    for (std::size_t k = 0; k < runs; ++k) {
        order[k] = std::uint32_t(k);
        depth[k] /= float(3 * std::min(kFrontFirstRun, n - k * kFrontFirstRun));
    }
    std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) { return depth[a] > depth[b]; });
    std::vector<std::uint32_t> sorted;
    sorted.reserve(triangles.size());
    for (const std::uint32_t k : order) {
        const std::size_t begin = 3 * std::size_t(k) * kFrontFirstRun;
        const std::size_t end = std::min(3 * n, begin + 3 * kFrontFirstRun);
        sorted.insert(sorted.end(), triangles.begin() + std::ptrdiff_t(begin), triangles.begin() + std::ptrdiff_t(end));
    }
    triangles.swap(sorted);
}

Camera Camera::frontal(const glm::vec3& box_min, const glm::vec3& box_max, float aspect,
                       float fovy_degrees, float fill) {
    const glm::vec3 center = 0.5f * (box_min + box_max);
    const glm::vec3 extent = box_max - box_min;
    const float half_fov = glm::radians(fovy_degrees) * 0.5f;
    // Distance at which the box's height (or width, whichever is tighter for
    // this aspect) spans `fill` of the view.
    const float half_h = 0.5f * std::max(extent.y, extent.x / std::max(aspect, 1e-6f)) / fill;
    const float distance = half_h / std::tan(half_fov) + 0.5f * extent.z;
    const glm::vec3 eye = center + glm::vec3(0.0f, 0.0f, distance);
    const float depth = std::max(extent.z, 1e-3f);
    return look_at(eye, center, {0.0f, 1.0f, 0.0f}, fovy_degrees, aspect,
                   std::max(distance - depth * 2.0f, distance * 0.05f), distance + depth * 2.0f);
}

namespace {

// Per-vertex data that changes every frame, in two buffers: the shape, and
// the wrinkle map's frame (not needed when the shader derives it).
struct ShapeVertex {
    float position[3];
    float normal[3];
};
struct FrameVertex {
    float tangent[4];
    float wrinkle_uv[2];
};
static_assert(sizeof(ShapeVertex) == 6 * sizeof(float), "tightly packed");
static_assert(sizeof(FrameVertex) == 6 * sizeof(float), "tightly packed");

GLuint compile(GLenum stage, const char* source) {
    GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, &source, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetShaderInfoLog(s, sizeof log, nullptr, log);
        glDeleteShader(s);
        fail<InternalError>("render: the {} shader does not compile: {}",
                            stage == GL_VERTEX_SHADER ? "vertex" : "fragment", log);
    }
    return s;
}

GLuint link_program(const char* vs_source, const char* fs_source) {
    const GLuint vs = compile(GL_VERTEX_SHADER, vs_source);
    GLuint fs = 0;
    try {
        fs = compile(GL_FRAGMENT_SHADER, fs_source);
    } catch (...) {
        glDeleteShader(vs);
        throw;
    }
    const GLuint p = glCreateProgram();
    glAttachShader(p, vs);
    glAttachShader(p, fs);
    glLinkProgram(p);
    glDeleteShader(vs);
    glDeleteShader(fs);
    GLint ok = 0;
    glGetProgramiv(p, GL_LINK_STATUS, &ok);
    if (!ok) {
        char log[4096] = {};
        glGetProgramInfoLog(p, sizeof log, nullptr, log);
        glDeleteProgram(p);
        fail<InternalError>("render: the bump-mapping program does not link: {}", log);
    }
    return p;
}

// A 2D texture from `texels` (rows first row first, as GL reads them),
// clamped or repeating, bilinear, with mipmaps and anisotropic filtering
// (where the driver has it) when asked.
struct TextureUpload {
    GLint internal_format;
    GLenum format, type;
    int alignment;  // bytes per row multiple of the texel data
    bool mipmaps;
    GLint wrap;
    const char* what;  // for the GL error check
    float anisotropy = 1.0f;  // the most texels along a pixel's long axis; 1: trilinear
};
GLuint upload_texture(const TextureUpload& u, int width, int height, const void* texels) {
    GLuint t = 0;
    glGenTextures(1, &t);
    glBindTexture(GL_TEXTURE_2D, t);
    glPixelStorei(GL_UNPACK_ALIGNMENT, u.alignment);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTexImage2D(GL_TEXTURE_2D, 0, u.internal_format, width, height, 0, u.format, u.type, texels);
    if (u.mipmaps) glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, u.mipmaps ? GL_LINEAR_MIPMAP_LINEAR : GL_LINEAR);
    if (u.anisotropy > 1.0f && epoxy_has_gl_extension("GL_EXT_texture_filter_anisotropic"))
        glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY_EXT, u.anisotropy);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, u.wrap);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, u.wrap);
    glBindTexture(GL_TEXTURE_2D, 0);
    check_gl(u.what);
    return t;
}

// 2x already removes the shirt's stripe; the H100's draw is 2.872 ms with it,
// 2.897 with 4x and 3.34 with 8x on every mipmapped map (the bound is 2.9;
// docs/PERFORMANCE.md, session 8).
constexpr float kBaseMapAnisotropy = 2.0f;

GLuint upload_srgb_texture(const ImageRGBA8& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.pixels.size() != std::size_t(image.width) * image.height * 4)
        fail("render: base texture: {}x{} image with {} bytes, expected width*height*4",
             image.width, image.height, image.pixels.size());
    // Mesh texcoords follow OBJ/OpenGL (v = 0 at the image's bottom row) and
    // GL's first row is t = 0: upload the rows bottom first.
    const std::size_t row = image.row_bytes();
    std::vector<std::uint8_t> flipped(image.pixels.size());
    for (int y = 0; y < image.height; ++y)
        std::copy_n(image.pixels.data() + std::size_t(image.height - 1 - y) * row, row,
                    flipped.data() + std::size_t(y) * row);
    // Anisotropic: the atlas squeezes the bust's rows into few texture rows,
    // so a trilinear lookup there took a mip level as coarse as the rows' v
    // rate and smeared the neck's skin down the shirt's front as a stripe.
    return upload_texture({GL_SRGB8_ALPHA8, GL_RGBA, GL_UNSIGNED_BYTE, 1, true, GL_CLAMP_TO_EDGE,
                           "uploading a base texture", kBaseMapAnisotropy},
                          image.width, image.height, flipped.data());
}

// The base colour's relief and hair mask (skin_maps.h), mipmapped (the
// filtered slopes are those of the filtered height), rows bottom first like
// the base texture. Eight bits a channel, slopes as 0.5 + 0.5 slope / scale:
// half floats (8 bytes a texel) made this one fetch cost as much as the rest
// of the relief's shading on the H100 (docs/PERFORMANCE.md, session 7).
struct DetailMap {
    GLuint texture = 0;
    float slope_scale = 0.0f;  // the slope a channel's 1 stands for
};
// `key_visible` (per vertex of `uvs` and `triangles`; empty: 1) goes into
// the alpha: the key's baked shadows (Renderer::set_key_shadow), read with
// the relief at no further cost to the draw (a vertex attribute of its own
// cost the H100's draw 0.04 ms: docs/PERFORMANCE.md, session 10).
DetailMap upload_detail_map(const ImageRGBA8& image, float mean_levels, std::array<float, 2> hair_luminance,
                            const std::vector<float>& key_visible, const std::vector<glm::vec2>& uvs,
                            const std::vector<std::uint32_t>& triangles) {
    const std::vector<float> slopes = detail::albedo_detail_slopes(image, mean_levels, hair_luminance);
    // Grown 4 texels past the UV islands' edges: the gutters the look-ups
    // of the next mip levels blend in.
    constexpr int kGrowTexels = 4;
    const std::vector<float> alpha =
        key_visible.empty() ? std::vector<float>()
                            : detail::vertex_values_in_uv(uvs, triangles, key_visible, image.width, image.height,
                                                          kGrowTexels, 1.0f);
    float scale = 0.0f;
    for (std::size_t i = 0; i < slopes.size(); i += 3)
        scale = std::max({scale, std::abs(slopes[i]), std::abs(slopes[i + 1])});
    if (scale == 0.0f) scale = 1.0f;
    std::vector<std::uint8_t> texels(slopes.size() / 3 * 4);
    auto unorm = [](float x) { return std::uint8_t(std::lround(255.0f * std::clamp(x, 0.0f, 1.0f))); };
    for (std::size_t i = 0, j = 0; i < slopes.size(); i += 3, j += 4) {
        texels[j] = unorm(0.5f + 0.5f * slopes[i] / scale);
        texels[j + 1] = unorm(0.5f + 0.5f * slopes[i + 1] / scale);
        texels[j + 2] = unorm(slopes[i + 2]);
        texels[j + 3] = alpha.empty() ? 255 : unorm(alpha[i / 3]);
    }
    return {upload_texture({GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, 1, true, GL_CLAMP_TO_EDGE,
                            "uploading a base texture's relief"},
                           image.width, image.height, texels.data()),
            scale};
}

// The pre-integrated scattering table: clamped, bilinear, packed unsigned
// floats (32 bits a texel: the skin shader samples it twice a pixel, for
// the key, and a 64-bit texel filters at half rate).
constexpr int kScatterTableWidth = 128;   // N.L
constexpr int kScatterTableHeight = 64;   // curvature
GLuint upload_scatter_table(const SkinShading& skin) {
    const std::vector<float> table =
        detail::preintegrated_scatter_table(skin, kScatterTableWidth, kScatterTableHeight);
    return upload_texture({GL_R11F_G11F_B10F, GL_RGB, GL_FLOAT, 4, false, GL_CLAMP_TO_EDGE,
                           "uploading the scattering table"},
                          kScatterTableWidth, kScatterTableHeight, table.data());
}

// The pore map: repeating, mipmapped (filtered pores shorten the normal, which
// the shader turns into roughness).
GLuint upload_pore_map(const PoreMapSpec& spec) {
    const std::vector<std::uint8_t> texels = detail::pore_map(spec);
    return upload_texture({GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, 1, true, GL_REPEAT,
                           "uploading the pore map"},
                          spec.size, spec.size, texels.data());
}

// How far the key's baked shadows stand for its shadows in this draw: 1
// while the key shines from within fade[0] degrees of the direction they
// were baked for (`toward`, model space; zero: none baked), fading to 0 at
// fade[1], where the contact shadow from the ambient occlusion takes over.
float baked_key_weight(const DrawOptions& o, const glm::vec3& toward) {
    if (!(glm::length(toward) > 0.0f)) return 0.0f;
    const glm::vec3 p = glm::vec3(o.light.position);
    const glm::vec3 key = o.light.position.w == 0.0f ? p : p - glm::vec3(o.model[3]);
    if (!(glm::length(key) > 0.0f)) return 0.0f;
    const float c = glm::dot(glm::normalize(key), glm::normalize(glm::mat3(o.model) * toward));
    const float near = std::cos(glm::radians(o.skin.key_shadow_fade_deg[0]));
    const float far = std::cos(glm::radians(o.skin.key_shadow_fade_deg[1]));
    if (!(near > far)) return c >= near ? 1.0f : 0.0f;
    const float t = std::clamp((c - far) / (near - far), 0.0f, 1.0f);
    return t * t * (3.0f - 2.0f * t);
}

}  // namespace

struct Renderer::Impl {
    struct Mesh {
        Material material;
        GLuint base_texture = 0;
        // The skin's relief baked from the base texture, made on the first
        // skin draw and again when the mean it is taken against changes.
        GLuint detail_texture = 0;
        float detail_slope_scale = 0.0f;
        float detail_levels = 0.0f;
        std::array<float, 2> detail_hair{};  // the hair mask's luminance range it was made with
        GLuint vao = 0, shape_vbo = 0, frame_vbo = 0, static_vbo = 0, ebo = 0;
        GLuint occlusion_vbo = 0;  // attribute 5; none: the constant 1 (open)
        // The key's baked visibility per vertex (set_key_shadow), drawn
        // into the detail map's alpha; the key's direction it was baked for
        // (model space; zero: none).
        std::vector<float> key_visible;
        glm::vec3 key_shadow_toward{0.0f};
        GLsizei index_count = 0;
        std::size_t vertex_count = 0;
        std::vector<glm::vec2> base_uvs;
        TangentFrames frames;
        std::vector<ShapeVertex> shape_staging;
        std::vector<FrameVertex> frame_staging;
    };

    Platform& platform;
    GLuint program = 0;
    // Whether add_mesh() draws triangles nearest the frontal camera first
    // (order_front_first): on GPUs, whose depth test rejects fragments
    // before they are shaded; not on a software rasteriser (llvmpipe),
    // where the reordered draw was slower.
    bool front_first = true;
    struct {
        GLint model, normal_matrix, view_projection, base_map, has_base_map, base_color,
            wrinkle_map, use_wrinkle_map, wrinkle_signed, light_position, light_ambient,
            light_diffuse, light_specular, specular_color, shininess, camera_position, projective,
            box, skin_model, skin_surface, scatter_table, max_curvature, mm_per_unit,
            normal_softening, cavity_direct, pore_map, pore_tiles, pore_strength, detail_map, albedo_bump, f0, roughness,
            lobe_weight, gloss_exponent, sheen_intensity, occlusion, key_cone, key_shadow, min_curvature, wrap, hair, wet, wet_sheen, key_tint,
            fill_direction, fill_colour, rim_direction, rim_colour, sky, ground,
            exposure, tone_map;
    } loc{};
    std::vector<Mesh> meshes;
    // The skin model's tables, made on the first skin draw and again when
    // the parameters they come from change.
    GLuint scatter_table = 0, pore_texture = 0;
    SkinShading scatter_source, pore_source;

    explicit Impl(Platform& p) : platform(p) {}

    Mesh& mesh(MeshId id) {
        if (id < 0 || std::size_t(id) >= meshes.size())
            fail("render: Renderer: no mesh {} (there are {})", id, meshes.size());
        return meshes[std::size_t(id)];
    }

    void release(Mesh& m) {
        if (m.base_texture) glDeleteTextures(1, &m.base_texture);
        if (m.detail_texture) glDeleteTextures(1, &m.detail_texture);
        m.detail_texture = 0;
        const GLuint buffers[5] = {m.shape_vbo, m.frame_vbo, m.static_vbo, m.ebo, m.occlusion_vbo};
        glDeleteBuffers(5, buffers);
        if (m.vao) glDeleteVertexArrays(1, &m.vao);
        m.base_texture = m.vao = m.shape_vbo = m.frame_vbo = m.static_vbo = m.ebo = m.occlusion_vbo = 0;
    }

    // Binds the scattering table to unit 2 and the pore map to unit 3,
    // remaking either when its parameters changed (each made on its own
    // unit: an upload binds and unbinds the active unit's texture).
    void bind_skin_tables(const SkinShading& skin) {
        glActiveTexture(GL_TEXTURE2);
        const bool same_scatter = scatter_table && skin.profile == scatter_source.profile &&
                                  skin.max_curvature == scatter_source.max_curvature;
        if (!same_scatter) {
            const GLuint t = upload_scatter_table(skin);
            if (scatter_table) glDeleteTextures(1, &scatter_table);
            scatter_table = t;
            scatter_source = skin;
        }
        glActiveTexture(GL_TEXTURE3);
        if (!pore_texture || !(skin.pores == pore_source.pores)) {
            const GLuint t = upload_pore_map(skin.pores);
            if (pore_texture) glDeleteTextures(1, &pore_texture);
            pore_texture = t;
            pore_source = skin;
        }
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, scatter_table);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, pore_texture);
    }
};

Renderer::Renderer(Platform& platform) : impl_(std::make_unique<Impl>(platform)) {
    platform.make_current();
    impl_->program = link_program(detail::kBumpVertexShader, detail::kBumpFragmentShader);
    const auto* gl_renderer = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
    impl_->front_first = !(gl_renderer && (std::strstr(gl_renderer, "llvmpipe") || std::strstr(gl_renderer, "softpipe") ||
                                          std::strstr(gl_renderer, "SwiftShader")));
    const GLuint p = impl_->program;
    auto u = [p](const char* name) { return glGetUniformLocation(p, name); };
    auto& l = impl_->loc;
    l.model = u("u_model");
    l.normal_matrix = u("u_normal_matrix");
    l.view_projection = u("u_view_projection");
    l.base_map = u("u_base_map");
    l.has_base_map = u("u_has_base_map");
    l.base_color = u("u_base_color");
    l.wrinkle_map = u("u_wrinkle_map");
    l.use_wrinkle_map = u("u_use_wrinkle_map");
    l.wrinkle_signed = u("u_wrinkle_signed");
    l.light_position = u("u_light_position");
    l.light_ambient = u("u_light_ambient");
    l.light_diffuse = u("u_light_diffuse");
    l.light_specular = u("u_light_specular");
    l.specular_color = u("u_specular_color");
    l.shininess = u("u_shininess");
    l.camera_position = u("u_camera_position");
    l.projective = u("u_projective");
    l.box = u("u_box");
    l.skin_model = u("u_skin_model");
    l.skin_surface = u("u_skin_surface");
    l.scatter_table = u("u_scatter_table");
    l.max_curvature = u("u_max_curvature");
    l.mm_per_unit = u("u_mm_per_unit");
    l.normal_softening = u("u_normal_softening");
    l.cavity_direct = u("u_cavity_direct");
    l.pore_map = u("u_pore_map");
    l.pore_tiles = u("u_pore_tiles");
    l.pore_strength = u("u_pore_strength");
    l.albedo_bump = u("u_albedo_bump");
    l.detail_map = u("u_detail_map");
    l.f0 = u("u_f0");
    l.roughness = u("u_roughness");
    l.lobe_weight = u("u_lobe_weight");
    l.gloss_exponent = u("u_gloss_exponent");
    l.sheen_intensity = u("u_sheen_intensity");
    l.occlusion = u("u_occlusion");
    l.key_shadow = u("u_key_shadow");
    l.key_cone = u("u_key_cone");
    l.min_curvature = u("u_min_curvature");
    l.wrap = u("u_wrap");
    l.hair = u("u_hair");
    l.wet = u("u_wet");
    l.wet_sheen = u("u_wet_sheen");
    l.key_tint = u("u_key_tint");
    l.fill_direction = u("u_fill_direction");
    l.fill_colour = u("u_fill_colour");
    l.rim_direction = u("u_rim_direction");
    l.rim_colour = u("u_rim_colour");
    l.sky = u("u_sky");
    l.ground = u("u_ground");
    l.exposure = u("u_exposure");
    l.tone_map = u("u_tone_map");
    check_gl("Renderer: creating the program");
}

Renderer::~Renderer() {
    if (!impl_) return;
    impl_->platform.make_current();
    for (auto& m : impl_->meshes) impl_->release(m);
    if (impl_->scatter_table) glDeleteTextures(1, &impl_->scatter_table);
    if (impl_->pore_texture) glDeleteTextures(1, &impl_->pore_texture);
    if (impl_->program) glDeleteProgram(impl_->program);
}

std::size_t Renderer::mesh_count() const { return impl_->meshes.size(); }

std::array<unsigned, 2> Renderer::vertex_buffers(MeshId id) const {
    const Impl::Mesh& m = impl_->mesh(id);
    return {m.shape_vbo, m.frame_vbo};
}

Renderer::MeshId Renderer::add_mesh(const expression::TriMesh& mesh, const Material& material) {
    impl_->platform.make_current();
    if (mesh.n_vertices() == 0 || mesh.n_faces() == 0)
        fail("render: Renderer::add_mesh(): the mesh is empty ({} vertices, {} faces)",
             mesh.n_vertices(), mesh.n_faces());
    if (!mesh.has_vertex_normals())
        fail("render: Renderer::add_mesh(): the mesh has no vertex normals");

    Impl::Mesh m;
    m.vertex_count = mesh.n_vertices();
    std::vector<std::uint32_t> indices;
    indices.reserve(mesh.n_faces() * 3);
    for (const auto fh : mesh.faces()) {
        std::uint32_t tri[3];
        int k = 0;
        for (const auto vh : mesh.fv_range(fh)) {
            if (k < 3) tri[k] = std::uint32_t(vh.idx());
            ++k;
        }
        if (k != 3)
            fail("render: Renderer::add_mesh(): face {} has {} vertices, expected a triangle",
                 fh.idx(), k);
        indices.insert(indices.end(), tri, tri + 3);
    }
    if (impl_->front_first) order_front_first(mesh, indices);
    m.index_count = GLsizei(indices.size());
    m.base_uvs.assign(m.vertex_count, glm::vec2(0.0f));
    if (mesh.has_vertex_texcoords2D())
        for (const auto vh : mesh.vertices()) {
            const auto& t = mesh.texcoord2D(vh);
            m.base_uvs[std::size_t(vh.idx())] = {t[0], t[1]};
        }

    glGenVertexArrays(1, &m.vao);
    glGenBuffers(1, &m.shape_vbo);
    glGenBuffers(1, &m.frame_vbo);
    glGenBuffers(1, &m.static_vbo);
    glGenBuffers(1, &m.ebo);
    glBindVertexArray(m.vao);
    glBindBuffer(GL_ARRAY_BUFFER, m.shape_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.vertex_count * sizeof(ShapeVertex)), nullptr,
                 GL_DYNAMIC_DRAW);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, GLsizei(sizeof(ShapeVertex)),
                          reinterpret_cast<void*>(offsetof(ShapeVertex, position)));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, GLsizei(sizeof(ShapeVertex)),
                          reinterpret_cast<void*>(offsetof(ShapeVertex, normal)));
    glBindBuffer(GL_ARRAY_BUFFER, m.frame_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.vertex_count * sizeof(FrameVertex)), nullptr,
                 GL_DYNAMIC_DRAW);
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 4, GL_FLOAT, GL_FALSE, GLsizei(sizeof(FrameVertex)),
                          reinterpret_cast<void*>(offsetof(FrameVertex, tangent)));
    glEnableVertexAttribArray(3);
    glVertexAttribPointer(3, 2, GL_FLOAT, GL_FALSE, GLsizei(sizeof(FrameVertex)),
                          reinterpret_cast<void*>(offsetof(FrameVertex, wrinkle_uv)));
    glBindBuffer(GL_ARRAY_BUFFER, m.static_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(m.vertex_count * sizeof(glm::vec2)),
                 m.base_uvs.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(4);
    glVertexAttribPointer(4, 2, GL_FLOAT, GL_FALSE, sizeof(glm::vec2), nullptr);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(std::uint32_t)),
                 indices.data(), GL_STATIC_DRAW);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    try {
        check_gl("Renderer::add_mesh(): uploading the mesh");
    } catch (...) {
        impl_->release(m);
        throw;
    }
    impl_->meshes.push_back(std::move(m));
    const MeshId id = MeshId(impl_->meshes.size() - 1);
    set_material(id, material);
    update_mesh(id, mesh);
    return id;
}

void Renderer::set_material(MeshId id, const Material& material) {
    impl_->platform.make_current();
    Impl::Mesh& m = impl_->mesh(id);
    GLuint texture = 0;
    if (material.base_texture) texture = upload_srgb_texture(*material.base_texture);
    if (m.base_texture) glDeleteTextures(1, &m.base_texture);
    if (m.detail_texture) glDeleteTextures(1, &m.detail_texture);
    m.base_texture = texture;
    m.detail_texture = 0;
    m.material = material;
}

void Renderer::set_occlusion(MeshId id, const std::vector<float>& occlusion) {
    impl_->platform.make_current();
    Impl::Mesh& m = impl_->mesh(id);
    if (occlusion.size() != m.vertex_count)
        fail("render: Renderer::set_occlusion(): {} values for mesh {} of {} vertices, expected one each",
             occlusion.size(), id, m.vertex_count);
    if (!m.occlusion_vbo) glGenBuffers(1, &m.occlusion_vbo);
    glBindVertexArray(m.vao);
    glBindBuffer(GL_ARRAY_BUFFER, m.occlusion_vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(occlusion.size() * sizeof(float)), occlusion.data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(5);
    glVertexAttribPointer(5, 1, GL_FLOAT, GL_FALSE, sizeof(float), nullptr);
    glBindVertexArray(0);
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    check_gl("Renderer::set_occlusion(): uploading the occlusion");
}

void Renderer::set_key_shadow(MeshId id, const std::vector<float>& visibility, const glm::vec3& toward_key) {
    impl_->platform.make_current();
    Impl::Mesh& m = impl_->mesh(id);
    if (visibility.size() != m.vertex_count)
        fail("render: Renderer::set_key_shadow(): {} values for mesh {} of {} vertices, expected one each",
             visibility.size(), id, m.vertex_count);
    if (!(glm::length(toward_key) > 0.0f))
        fail("render: Renderer::set_key_shadow(): a zero direction to the key, expected a unit vector");
    m.key_visible = visibility;
    m.key_shadow_toward = glm::normalize(toward_key);
    // The detail map carries it: made again at the next skin draw.
    if (m.detail_texture) glDeleteTextures(1, &m.detail_texture);
    m.detail_texture = 0;
}

void Renderer::update_mesh(MeshId id, const expression::TriMesh& mesh,
                           const std::vector<glm::vec2>& wrinkle_uvs) {
    Impl::Mesh& m = impl_->mesh(id);
    const std::vector<glm::vec2>& uvs = wrinkle_uvs.empty() ? m.base_uvs : wrinkle_uvs;
    if (uvs.size() != mesh.n_vertices())
        fail("render: Renderer::update_mesh(): {} wrinkle UVs for {} vertices", uvs.size(),
             mesh.n_vertices());
    m.frames.compute(mesh, uvs);
    update_mesh(id, mesh, uvs, m.frames.tangents());
}

void Renderer::update_mesh(MeshId id, const expression::TriMesh& mesh,
                           const std::vector<glm::vec2>& wrinkle_uvs,
                           const std::vector<glm::vec4>& tangents) {
    impl_->platform.make_current();
    Impl::Mesh& m = impl_->mesh(id);
    const std::size_t n = mesh.n_vertices();
    if (n != m.vertex_count)
        fail("render: Renderer::update_mesh(): mesh {} had {} vertices, now {}", id,
             m.vertex_count, n);
    const std::vector<glm::vec2>& uvs = wrinkle_uvs.empty() ? m.base_uvs : wrinkle_uvs;
    if (uvs.size() != n || tangents.size() != n)
        fail("render: Renderer::update_mesh(): {} wrinkle UVs and {} tangents for {} vertices",
             uvs.size(), tangents.size(), n);
    if (!mesh.has_vertex_normals())
        fail("render: Renderer::update_mesh(): the mesh has no vertex normals");
    m.frame_staging.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        FrameVertex& d = m.frame_staging[i];
        d.tangent[0] = tangents[i].x; d.tangent[1] = tangents[i].y;
        d.tangent[2] = tangents[i].z; d.tangent[3] = tangents[i].w;
        d.wrinkle_uv[0] = uvs[i].x; d.wrinkle_uv[1] = uvs[i].y;
    }
    glBindBuffer(GL_ARRAY_BUFFER, m.frame_vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(n * sizeof(FrameVertex)),
                    m.frame_staging.data());
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    update_shape(id, mesh);
}

void Renderer::update_shape(MeshId id, const expression::TriMesh& mesh) {
    impl_->platform.make_current();
    Impl::Mesh& m = impl_->mesh(id);
    const std::size_t n = mesh.n_vertices();
    if (n != m.vertex_count)
        fail("render: Renderer::update_shape(): mesh {} had {} vertices, now {}", id,
             m.vertex_count, n);
    if (!mesh.has_vertex_normals())
        fail("render: Renderer::update_shape(): the mesh has no vertex normals");
    const auto* points = mesh.points();
    const auto* normals = mesh.vertex_normals();
    m.shape_staging.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        ShapeVertex& d = m.shape_staging[i];
        d.position[0] = points[i][0]; d.position[1] = points[i][1]; d.position[2] = points[i][2];
        d.normal[0] = normals[i][0]; d.normal[1] = normals[i][1]; d.normal[2] = normals[i][2];
    }
    glBindBuffer(GL_ARRAY_BUFFER, m.shape_vbo);
    glBufferSubData(GL_ARRAY_BUFFER, 0, GLsizeiptr(n * sizeof(ShapeVertex)),
                    m.shape_staging.data());
    glBindBuffer(GL_ARRAY_BUFFER, 0);
    // Per-frame calls leave GL errors to Platform::end_frame()'s check:
    // glGetError waits for a threaded driver to catch up.
}

void Renderer::draw(const DrawOptions& o, const WrinkleTexture* wrinkle_map) {
    Impl& im = *impl_;
    im.platform.make_current();
    if (wrinkle_map && wrinkle_map->mapped())
        fail("render: Renderer::draw(): the wrinkle map is still mapped for CUDA");
    std::array<int, 4> vp = o.viewport;
    if (vp[2] <= 0 || vp[3] <= 0) vp = {0, 0, im.platform.width(), im.platform.height()};
    glViewport(vp[0], vp[1], vp[2], vp[3]);
    if (o.clear) {
        glEnable(GL_SCISSOR_TEST);
        glScissor(vp[0], vp[1], vp[2], vp[3]);
        glClearColor(o.background.r, o.background.g, o.background.b, 1.0f);
        glClearDepth(1.0);
        glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
        glDisable(GL_SCISSOR_TEST);
    }
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);  // eyelids and lips are seen from both sides
    glDisable(GL_BLEND);
    glEnable(GL_MULTISAMPLE);

    glUseProgram(im.program);
    const glm::mat4 view_projection = o.camera.projection * o.camera.view;
    const glm::mat3 normal_matrix = glm::inverseTranspose(glm::mat3(o.model));
    glUniformMatrix4fv(im.loc.model, 1, GL_FALSE, glm::value_ptr(o.model));
    glUniformMatrix3fv(im.loc.normal_matrix, 1, GL_FALSE, glm::value_ptr(normal_matrix));
    glUniformMatrix4fv(im.loc.view_projection, 1, GL_FALSE, glm::value_ptr(view_projection));
    glUniform4fv(im.loc.light_position, 1, glm::value_ptr(o.light.position));
    glUniform3fv(im.loc.light_ambient, 1, glm::value_ptr(o.light.ambient));
    glUniform3fv(im.loc.light_diffuse, 1, glm::value_ptr(o.light.diffuse));
    glUniform3fv(im.loc.light_specular, 1, glm::value_ptr(o.light.specular));
    glUniform3fv(im.loc.camera_position, 1, glm::value_ptr(o.camera.position));
    glUniform1i(im.loc.projective, o.projective_wrinkles ? 1 : 0);
    glUniform4fv(im.loc.box, 1, o.projective_box.data());
    if (o.projective_wrinkles &&
        !(o.projective_box[2] > o.projective_box[0] && o.projective_box[3] > o.projective_box[1]))
        fail("render: Renderer::draw(): empty projective box ({}, {})-({}, {})",
             o.projective_box[0], o.projective_box[1], o.projective_box[2], o.projective_box[3]);
    glUniform1i(im.loc.base_map, 0);
    glUniform1i(im.loc.wrinkle_map, 1);
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, wrinkle_map ? wrinkle_map->gl_texture() : 0);
    glUniform1i(im.loc.wrinkle_signed,
                wrinkle_map && wrinkle_map->encoding() == NormalEncoding::Signed);
    const bool skin_model = o.shading == Shading::Skin;
    const float albedo_bump = o.skin.albedo_bump_mm / o.skin.mm_per_unit;
    glUniform1i(im.loc.skin_model, skin_model ? 1 : 0);
    if (skin_model) {
        const SkinShading& k = o.skin;
        im.bind_skin_tables(k);
        glUniform1i(im.loc.scatter_table, 2);
        glUniform1i(im.loc.pore_map, 3);
        glUniform1f(im.loc.max_curvature, k.max_curvature);
        glUniform1f(im.loc.mm_per_unit, k.mm_per_unit);
        glUniform2fv(im.loc.normal_softening, 1, glm::value_ptr(k.normal_softening));
        glUniform1f(im.loc.cavity_direct, k.cavity_direct);
        glUniform1f(im.loc.pore_tiles, k.pore_tiles);
        glUniform1f(im.loc.pore_strength, k.pore_strength);
        glUniform1i(im.loc.detail_map, 4);
        glActiveTexture(GL_TEXTURE4);
        for (auto& m : im.meshes) {
            const bool wanted = k.albedo_bump_mm > 0.0f && m.material.base_texture && m.material.uses_wrinkle_map;
            if (!wanted || (m.detail_texture && m.detail_levels == k.albedo_bump_bias &&
                            m.detail_hair == k.hair_luminance))
                continue;
            // The triangles that paint the key's shadows into the base UVs:
            // read back from the index buffer, once per map.
            std::vector<std::uint32_t> triangles;
            if (!m.key_visible.empty()) {
                triangles.resize(std::size_t(m.index_count));
                glBindBuffer(GL_COPY_READ_BUFFER, m.ebo);
                glGetBufferSubData(GL_COPY_READ_BUFFER, 0, GLsizeiptr(triangles.size() * sizeof(std::uint32_t)),
                                   triangles.data());
                glBindBuffer(GL_COPY_READ_BUFFER, 0);
            }
            const DetailMap d = upload_detail_map(*m.material.base_texture, k.albedo_bump_bias, k.hair_luminance,
                                                  m.key_visible, m.base_uvs, triangles);
            if (m.detail_texture) glDeleteTextures(1, &m.detail_texture);
            m.detail_texture = d.texture;
            m.detail_slope_scale = d.slope_scale;
            m.detail_levels = k.albedo_bump_bias;
            m.detail_hair = k.hair_luminance;
        }
        glUniform1f(im.loc.f0, k.f0);
        glUniform2f(im.loc.roughness, k.roughness[0], k.roughness[1]);
        glUniform1f(im.loc.lobe_weight, k.lobe_weight);
        glUniform1f(im.loc.gloss_exponent, k.gloss_exponent);
        glUniform2f(im.loc.sheen_intensity, k.matte_sheen, k.full_sheen_gloss);
        glUniform3f(im.loc.occlusion, k.occlusion_key, k.occlusion_fill, k.occlusion_specular);
        glUniform2f(im.loc.key_cone, k.occlusion_key_lean, k.occlusion_key_cone_max);
        glUniform1f(im.loc.min_curvature, k.min_curvature / k.max_curvature);
        glUniform1f(im.loc.wrap, k.softness);
        glUniform3f(im.loc.hair, k.hair_wrap, k.hair_roughness, k.hair_sheen);
        glUniform4f(im.loc.wet, k.wet_f0, k.wet_broad_roughness, k.wet_broad_weight, k.wet_tight_scale);
        glUniform1f(im.loc.wet_sheen, k.wet_sheen);
        glUniform3fv(im.loc.key_tint, 1, glm::value_ptr(k.key_tint));
        glUniform3fv(im.loc.fill_direction, 1, glm::value_ptr(glm::normalize(k.fill.direction)));
        glUniform3fv(im.loc.fill_colour, 1, glm::value_ptr(k.fill.colour));
        glUniform3fv(im.loc.rim_direction, 1, glm::value_ptr(glm::normalize(k.rim.direction)));
        glUniform3fv(im.loc.rim_colour, 1, glm::value_ptr(k.rim.colour));
        glUniform3fv(im.loc.sky, 1, glm::value_ptr(k.sky));
        glUniform3fv(im.loc.ground, 1, glm::value_ptr(k.ground));
        glUniform1f(im.loc.exposure, k.exposure);
        glUniform1i(im.loc.tone_map, k.tone_mapping == ToneMapping::Aces ? 1 : 0);
    }

    for (const auto& m : im.meshes) {
        const bool bump = o.wrinkles && wrinkle_map && m.material.uses_wrinkle_map;
        glUniform1i(im.loc.use_wrinkle_map, bump ? 1 : 0);
        glUniform1i(im.loc.skin_surface, m.material.uses_wrinkle_map ? 1 : 0);
        glUniform1i(im.loc.has_base_map, m.base_texture ? 1 : 0);
        glUniform3fv(im.loc.base_color, 1, glm::value_ptr(m.material.base_color));
        glUniform3fv(im.loc.specular_color, 1, glm::value_ptr(m.material.specular_color));
        glUniform1f(im.loc.shininess, m.material.shininess);
        if (skin_model) {
            glActiveTexture(GL_TEXTURE4);
            glBindTexture(GL_TEXTURE_2D, m.detail_texture);
            glUniform1f(im.loc.albedo_bump, m.detail_texture ? albedo_bump * m.detail_slope_scale : 0.0f);
        }
        glActiveTexture(GL_TEXTURE0);
        glBindTexture(GL_TEXTURE_2D, m.base_texture);
        if (!m.occlusion_vbo) glVertexAttrib1f(5, 1.0f);
        if (skin_model) {
            // Drawn from the detail map's alpha: without the map, none.
            const bool read = m.detail_texture && albedo_bump > 0.0f && m.material.uses_wrinkle_map;
            const glm::vec3 toward = read ? m.key_shadow_toward : glm::vec3(0.0f);
            glUniform2f(im.loc.key_shadow, baked_key_weight(o, toward), o.skin.key_shadow);
        }
        glBindVertexArray(m.vao);
        glDrawElements(GL_TRIANGLES, m.index_count, GL_UNSIGNED_INT, nullptr);
    }
    glBindVertexArray(0);
    if (skin_model) {
        glActiveTexture(GL_TEXTURE4);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE3);
        glBindTexture(GL_TEXTURE_2D, 0);
        glActiveTexture(GL_TEXTURE2);
        glBindTexture(GL_TEXTURE_2D, 0);
    }
    glActiveTexture(GL_TEXTURE1);
    glBindTexture(GL_TEXTURE_2D, 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, 0);
    glUseProgram(0);
}

}  // namespace emoface::render
