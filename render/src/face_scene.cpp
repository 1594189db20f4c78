#include "emoface/render/face_scene.h"

#include <algorithm>
#include <chrono>
#include <limits>

#include <epoxy/gl.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "emoface/common/error.h"
#include "emoface/common/timing.h"
#include "emoface/render/face_occlusion.h"
#include "emoface/render/face_geometry.h"
#include "emoface/render/tangents.h"
#include "emoface/render/wrinkle_morph.h"

namespace emoface::render {

namespace {

enum Group { kSkin = 0, kEyes = 1, kMouth = 2, kGroups = 3 };

Group group_of(expression::VertexPart p) {
    switch (p) {
        case expression::VertexPart::Skin: return kSkin;
        case expression::VertexPart::EyeballLeft:
        case expression::VertexPart::EyeballRight: return kEyes;
        default: return kMouth;
    }
}

std::bitset<expression::kFeatureCount> present_points(const expression::Face& face) {
    std::bitset<expression::kFeatureCount> present;
    for (int i = 0; i < expression::kFeatureCount; ++i) present[i] = face.feature_points[i].present;
    return present;
}

expression::FeatureLayout layout_of(const fap::FeaturePointPositions& positions,
                                    const std::bitset<expression::kFeatureCount>& present,
                                    const expression::TextureBox& box) {
    std::array<glm::vec3, expression::kFeatureCount> p{};
    for (int i = 0; i < expression::kFeatureCount; ++i)
        p[i] = glm::vec3(float(positions[i][0]), float(positions[i][1]), float(positions[i][2]));
    return expression::projective_layout(p, present, box);
}

morph::Layout to_morph_layout(const std::vector<expression::Segment>& segments) {
    morph::Layout out;
    out.reserve(segments.size());
    for (const auto& s : segments) out.push_back({s.p.x, s.p.y, s.q.x, s.q.y});
    return out;
}

// GL buffers of the sizes given (bytes), for CUDA to write and GL to copy from.
std::vector<unsigned> gl_buffers_of(const std::vector<long long>& bytes) {
    std::vector<unsigned> out(bytes.size());
    if (out.empty()) return out;
    glGenBuffers(GLsizei(out.size()), out.data());
    for (std::size_t i = 0; i < out.size(); ++i) {
        glBindBuffer(GL_COPY_WRITE_BUFFER, out[i]);
        glBufferData(GL_COPY_WRITE_BUFFER, GLsizeiptr(bytes[i]), nullptr, GL_DYNAMIC_COPY);
    }
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    return out;
}

}  // namespace

const char* wrinkle_layout_name(WrinkleLayout layout) {
    return layout == WrinkleLayout::Anchored ? "anchored" : "projective";
}

std::optional<WrinkleLayout> parse_wrinkle_layout(std::string_view text) {
    if (text == "projective") return WrinkleLayout::Projective;
    if (text == "anchored") return WrinkleLayout::Anchored;
    return std::nullopt;
}

expression::TextureBox layout_box(const expression::Face& face) {
    const expression::TextureBox& box = face.texture_box;
    if (!(box.max.x > box.min.x) || !(box.max.y > box.min.y))
        fail<InputError>("render: face '{}' has an empty texture box ({}, {})-({}, {})", face.name,
                         box.min.x, box.min.y, box.max.x, box.max.y);
    return box;
}

expression::FeatureLayout posed_layout(const expression::Face& face,
                                       const expression::FaceRig& rig,
                                       const expression::FapValues& faps,
                                       WrinkleLayout layout) {
    if (layout == WrinkleLayout::Anchored) return expression::anchored_layout(face);
    return layout_of(rig.feature_points(faps), present_points(face), layout_box(face));
}

WrinkleKey make_wrinkle_key(const expression::Face& face, const expression::FaceRig& rig,
                            const expression::WrinkleLibrarySpec& spec, std::string name,
                            const expression::WrinkleSources& sources, const expression::FapValues& pose,
                            int size, WrinkleLayout layout) {
    WrinkleKey k;
    k.name = std::move(name);
    k.layout = posed_layout(face, rig, pose, layout);
    k.map = expression::generate_wrinkle_map(spec, sources, k.layout, size);
    k.region = expression::wrinkle_region(spec, sources, k.layout);
    return k;
}

FaceSceneOptions::FaceSceneOptions() {
    morph.normal_map = true;
    skin.shininess = 20.0f;
    skin.specular_color = glm::vec3(0.35f);
    eyes.uses_wrinkle_map = false;
    // The cornea is a smooth wet surface: a tight lobe gives the small bright
    // catch-light that makes an eye read as alive (a broad one only greys it).
    eyes.shininess = 1000.0f;
    eyes.specular_color = glm::vec3(1.0f);
    mouth.uses_wrinkle_map = false;
    mouth.shininess = 12.0f;
    mouth.specular_color = glm::vec3(0.1f);
}

struct FaceScene::Part {
    expression::TriMesh mesh;
    std::vector<int> full_index;  // part vertex -> full mesh vertex
    std::vector<glm::vec2> wrinkle_uvs;
    std::vector<glm::vec4> fixed_tangents;  // parts without wrinkles
    TangentFrames frames;
    Renderer::MeshId id = -1;
    bool wrinkles = false;
};

FaceScene::FaceScene(Platform& platform, const expression::Face& face,
                     const expression::FaceRig& rig, std::vector<WrinkleKey> keys,
                     std::vector<expression::FeatureLine> lines, const FaceSceneOptions& options)
    : platform_(platform), face_(face), rig_(rig), box_(layout_box(face)),
      layout_kind_(options.layout), lines_(std::move(lines)), params_(options.morph),
      frames_(options.frames) {
    params_.normal_map = true;
    // Where keys say nothing the skin is flat: AU keys add their slopes and
    // cavities to the neutral key's (weights may sum over 1). 128/255 is
    // what a flat pixel holds, so flat key pixels cancel exactly.
    params_.rest = {128.0f / 255.0f, 128.0f / 255.0f, 1.0f, 1.0f};
    if (layout_kind_ == WrinkleLayout::Anchored && frames_ == WrinkleFrames::Shader)
        fail("render: FaceScene: WrinkleFrames::Shader has the projective layout's closed form; "
             "expected WrinkleFrames::Mesh with the anchored layout");
    if (options.frames_in_flight != 1 && options.frames_in_flight != 2)
        fail<InputError>("render: FaceScene: expected 1 or 2 frames in flight, found {}", options.frames_in_flight);
    if (keys.empty()) fail<InputError>("render: FaceScene: no wrinkle keys");
    if (lines_.empty()) fail<InputError>("render: FaceScene: no feature lines");
    if (face.parts.size() != face.mesh.n_vertices())
        fail<InputError>("render: FaceScene: face '{}' has {} vertex parts for {} vertices",
                         face.name, face.parts.size(), face.mesh.n_vertices());
    // The anchored L* is the face's UV layout, the same every frame.
    if (layout_kind_ == WrinkleLayout::Anchored) {
        layout_ = expression::anchored_layout(face);
        target_ = to_morph_layout(expression::layout_segments(lines_, layout_));
    }
    const int size_w = keys[0].map.width, size_h = keys[0].map.height;

    // The morph: every key with its layout's lines.
    std::vector<morph::KeyMap> maps;
    for (const WrinkleKey& k : keys) {
        if (k.map.width != size_w || k.map.height != size_h)
            fail<InputError>("render: FaceScene: key '{}' is {}x{}, key '{}' {}x{}", k.name,
                             k.map.width, k.map.height, keys[0].name, size_w, size_h);
        morph::KeyMap map;
        map.pixels = k.map.rgba.data();
        map.layout = to_morph_layout(expression::layout_segments(lines_, k.layout));
        map.width = size_w;
        map.height = size_h;
        // A key without wrinkles at all is rest everywhere: one pixel of it.
        const expression::WrinkleRegion r =
            k.region.empty() ? expression::WrinkleRegion{glm::vec2(0.0f), glm::vec2(1.0f / float(size_w))} : k.region;
        map.region = {r.min.x, r.min.y, r.max.x, r.max.y};
        maps.push_back(std::move(map));
    }
    morpher_ = std::make_unique<morph::Morpher>(size_w, size_h, morph::PixelFormat::Rgba8,
                                                std::move(maps), options.backend);

    platform_.make_current();
    texture_ = std::make_unique<WrinkleTexture>(size_w, size_h, TexelFormat::RGBA8,
                                                NormalEncoding::Unsigned);
    wrinkle_morph_ = std::make_unique<WrinkleMorph>(*morpher_, *texture_);
    renderer_ = std::make_unique<Renderer>(platform_);

    // Split the mesh by part. A triangle touching an eyeball vertex belongs
    // to the eyes, else one touching the mouth interior to the mouth.
    mesh_ = face.mesh;
    if (!mesh_.has_vertex_normals()) mesh_.request_vertex_normals();
    if (!mesh_.has_face_normals()) mesh_.request_face_normals();
    mesh_.update_normals();
    parts_.resize(kGroups);
    std::vector<std::vector<int>> local(kGroups, std::vector<int>(mesh_.n_vertices(), -1));
    for (const auto fh : mesh_.faces()) {
        int v[3], k = 0;
        for (const auto vh : mesh_.fv_range(fh))
            if (k < 3) v[k++] = vh.idx();
        if (k != 3) continue;
        Group g = kSkin;
        for (int i = 0; i < 3; ++i) {
            const Group gi = group_of(face.parts[std::size_t(v[i])]);
            if (gi == kEyes || (gi == kMouth && g == kSkin)) g = gi;
        }
        Part& part = parts_[g];
        expression::TriMesh::VertexHandle h[3];
        for (int i = 0; i < 3; ++i) {
            int& l = local[g][std::size_t(v[i])];
            if (l < 0) {
                l = int(part.full_index.size());
                part.full_index.push_back(v[i]);
                part.mesh.add_vertex(mesh_.point(mesh_.vertex_handle(v[i])));
            }
            h[i] = part.mesh.vertex_handle(l);
        }
        part.mesh.add_face(h[0], h[1], h[2]);
    }
    const Material* materials[kGroups] = {&options.skin, &options.eyes, &options.mouth};
    for (int g = 0; g < kGroups; ++g) {
        Part& part = parts_[g];
        if (part.mesh.n_faces() == 0) continue;
        part.mesh.request_vertex_normals();
        part.mesh.request_vertex_texcoords2D();
        for (std::size_t i = 0; i < part.full_index.size(); ++i) {
            const auto full = mesh_.vertex_handle(part.full_index[i]);
            const auto vh = part.mesh.vertex_handle(int(i));
            part.mesh.set_normal(vh, mesh_.normal(full));
            if (mesh_.has_vertex_texcoords2D()) part.mesh.set_texcoord2D(vh, mesh_.texcoord2D(full));
        }
        Material m = *materials[g];
        if (!m.base_texture && !face.base_colour.empty()) {
            auto img = std::make_shared<ImageRGBA8>(face.base_colour.width, face.base_colour.height);
            img->pixels = face.base_colour.rgba;
            m.base_texture = std::move(img);
        }
        part.wrinkles = m.uses_wrinkle_map;
        part.wrinkle_uvs.assign(part.full_index.size(), glm::vec2(0.0f));
        // Anchored: the wrinkle map is sampled with the mesh's own UVs, v
        // turned to run down the image (texel row 0 = v 0 of the wrinkle
        // texture, as the morph writes it). A map painted on an OBJ's UV
        // layout thus lies as painted; the tangent frames built from these
        // UVs have +y down the image, the maps' green-down convention.
        if (layout_kind_ == WrinkleLayout::Anchored && mesh_.has_vertex_texcoords2D())
            for (std::size_t i = 0; i < part.full_index.size(); ++i) {
                const auto& t = mesh_.texcoord2D(mesh_.vertex_handle(part.full_index[i]));
                part.wrinkle_uvs[i] = glm::vec2(t[0], 1.0f - t[1]);
            }
        part.fixed_tangents.assign(part.full_index.size(), glm::vec4(1, 0, 0, 1));
        part.id = renderer_->add_mesh(part.mesh, m);
        // Parts the CPU gives no frames to: constant ones, uploaded once.
        if (!part.wrinkles || frames_ == WrinkleFrames::Shader)
            renderer_->update_mesh(part.id, part.mesh, part.wrinkle_uvs, part.fixed_tangents);
    }

    bake_light(mesh_, false);

    const bool gpu_geometry =
        options.geometry == GeometryDevice::Gpu ||
        (options.geometry == GeometryDevice::Auto && wrinkle_morph_->uses_interop() && cuda_geometry_available());
    if (gpu_geometry) {
        // The parts' vertex buffers, written by the GPU from now on.
        std::vector<GeometryPart> geometry_parts;
        std::vector<unsigned> buffers;
        for (Part& part : parts_) {
            if (part.id < 0) continue;
            GeometryPart gp;
            gp.full_index = part.full_index;
            for (const auto fh : part.mesh.faces())
                for (const auto vh : part.mesh.fv_range(fh)) gp.triangles.push_back(vh.idx());
            gp.frames = part.wrinkles && frames_ == WrinkleFrames::Mesh;
            if (gp.frames && layout_kind_ == WrinkleLayout::Anchored) gp.fixed_uvs = part.wrinkle_uvs;
            const auto b = renderer_->vertex_buffers(part.id);
            buffers.push_back(b[0]);
            if (gp.frames) buffers.push_back(b[1]);
            geometry_parts.push_back(std::move(gp));
        }
        geometry_ = std::make_unique<FaceGeometry>(rig_, mesh_, std::move(geometry_parts),
                                                   std::array<float, 4>{box_.min.x, box_.min.y, box_.max.x, box_.max.y});
        cuda_geometry_ = std::make_unique<CudaGeometry>(*geometry_);
        if (options.frames_in_flight == 2 && wrinkle_morph_->uses_interop()) {
            // Pipelined: a second wrinkle texture, and two sets of buffers for
            // the GPU geometry that draw() copies into the renderer's.
            renderer_buffers_ = buffers;
            for (unsigned b : buffers) {
                GLint64 bytes = 0;
                glBindBuffer(GL_COPY_READ_BUFFER, b);
                glGetBufferParameteri64v(GL_COPY_READ_BUFFER, GL_BUFFER_SIZE, &bytes);
                buffer_bytes_.push_back(bytes);
            }
            glBindBuffer(GL_COPY_READ_BUFFER, 0);
            staging_ = gl_buffers_of(buffer_bytes_);
            back_staging_ = gl_buffers_of(buffer_bytes_);
            geometry_buffers_ = std::make_unique<GlBufferInterop>(staging_);
            back_buffers_ = std::make_unique<GlBufferInterop>(back_staging_);
            back_texture_ = std::make_unique<WrinkleTexture>(size_w, size_h, TexelFormat::RGBA8,
                                                             NormalEncoding::Unsigned);
            back_texture_->register_cuda();
        } else {
            geometry_buffers_ = std::make_unique<GlBufferInterop>(buffers);
        }
    }

    // Start at the neutral pose with the first key alone.
    expression::FapValues neutral{};
    std::vector<float> weights(keys.size(), 0.0f);
    weights[0] = 1.0f;
    update(neutral, weights);
    flush_pipeline();
}

FaceScene::~FaceScene() {
    platform_.make_current();
    if (pending_) {
        try {
            back_texture_->unmap(morpher_->cuda_stream(), back_buffers_->resources());
        } catch (...) {  // a destructor must not throw
        }
    }
    geometry_buffers_.reset();
    back_buffers_.reset();
    for (std::vector<unsigned>* b : {&staging_, &back_staging_})
        if (!b->empty()) glDeleteBuffers(GLsizei(b->size()), b->data());
    back_texture_.reset();
    cuda_geometry_.reset();
    wrinkle_morph_.reset();
    texture_.reset();
    renderer_.reset();
}

bool FaceScene::uses_interop() const { return wrinkle_morph_->uses_interop(); }
int FaceScene::key_count() const { return morpher_->keys(); }

void FaceScene::update(const expression::FapValues& faps, const std::vector<float>& key_weights) {
    if (cuda_geometry_ && wrinkle_morph_->uses_interop()) return update_on_gpu(faps, key_weights);
    // The layout needs only the feature points (cheap), so the morph is
    // queued first: on the CUDA backend it then runs on the GPU while the
    // CPU deforms the mesh and uploads it (the draw waits for both).
    auto t = Clock::now();
    if (layout_kind_ == WrinkleLayout::Projective) {
        layout_ = layout_of(rig_.feature_points(faps), present_points(face_), box_);
        target_ = to_morph_layout(expression::layout_segments(lines_, layout_));
    }
    const double layout_ms = ms_since(t);
    update_wrinkles(key_weights);
    deform(faps, /*layout_from_mesh=*/false);
    times_.layout_ms = layout_ms;
}

void FaceScene::update_on_gpu(const expression::FapValues& faps, const std::vector<float>& key_weights) {
    // The morph and the geometry, each on its own stream, between one
    // mapping of the wrinkle texture and the vertex buffers together and one
    // unmapping, both on the morph's stream (the geometry's waits for the
    // mapping, the unmapping for the geometry): each mapping is a handoff
    // between GL and CUDA that costs the GPU more than the geometry's kernels.
    platform_.make_current();
    auto t = Clock::now();
    frame_ = rig_.frame(faps);  // the layout's feature points from it too: the rig's frame once
    if (layout_kind_ == WrinkleLayout::Projective) {
        layout_ = layout_of(rig_.feature_points(frame_), present_points(face_), box_);
        target_ = to_morph_layout(expression::layout_segments(lines_, layout_));
    }
    times_.layout_ms = ms_since(t);  // host time: the rig's parameters and the layout
    t = Clock::now();
    // Pipelined, into the back set (a frame still in flight that no draw()
    // took is handed over first: the newer one replaces it).
    flush_pipeline();
    WrinkleTexture& texture = back_texture_ ? *back_texture_ : *texture_;
    GlBufferInterop& interop = back_texture_ ? *back_buffers_ : *geometry_buffers_;
    void* morph_stream = morpher_->cuda_stream();
    const std::vector<void*>& buffers = interop.resources();
    const unsigned long long surface = texture.map_surface(morph_stream, buffers);
    try {
        cuda_geometry_->wait_for(morph_stream);
        run_gpu_geometry(interop.pointers());
        times_.rig_ms = ms_since(t);  // host time: map, launches
        t = Clock::now();
        morpher_->morph_to_surface(target_, key_weights, params_, surface);
        cuda_geometry_->join_into(morph_stream);
    } catch (...) {
        try {
            texture.unmap(morph_stream, buffers);
        } catch (...) {  // the first error is the one to report
        }
        throw;
    }
    times_.uv_ms = times_.tangents_ms = times_.upload_ms = 0.0;
    if (back_texture_) {
        // Unmapped by the next draw() after its own commands: the GL orders
        // what follows an unmapping after the CUDA work before it, and what
        // precedes it (that draw) is free to run beside that work.
        pending_ = true;
        times_.morph_ms = ms_since(t);  // host time: the morph's launches
        return;
    }
    texture.unmap(morph_stream, buffers);
    times_.morph_ms = ms_since(t);  // host time: the morph's launches, unmap
}

void FaceScene::flush_pipeline() {
    if (!pending_) return;
    platform_.make_current();
    pending_ = false;
    back_texture_->unmap(morpher_->cuda_stream(), back_buffers_->resources());
    std::swap(texture_, back_texture_);
    std::swap(geometry_buffers_, back_buffers_);
    std::swap(staging_, back_staging_);
    staging_copied_ = false;
}

void FaceScene::copy_staging_to_renderer() {
    for (std::size_t i = 0; i < staging_.size(); ++i) {
        glBindBuffer(GL_COPY_READ_BUFFER, staging_[i]);
        glBindBuffer(GL_COPY_WRITE_BUFFER, renderer_buffers_[i]);
        glCopyBufferSubData(GL_COPY_READ_BUFFER, GL_COPY_WRITE_BUFFER, 0, 0, GLsizeiptr(buffer_bytes_[i]));
    }
    glBindBuffer(GL_COPY_READ_BUFFER, 0);
    glBindBuffer(GL_COPY_WRITE_BUFFER, 0);
    staging_copied_ = true;
}

void FaceScene::run_gpu_geometry(const std::vector<float*>& buffers) {
    std::vector<float*> shape, frames;
    std::size_t next = 0;
    for (int p = 0; p < geometry_->part_count(); ++p) {
        shape.push_back(buffers[next++]);
        frames.push_back(geometry_->part(p).frames ? buffers[next++] : nullptr);
    }
    cuda_geometry_->run(frame_, shape, frames);
}

void FaceScene::update_wrinkles(const std::vector<float>& key_weights) {
    if (back_texture_)
        fail("render: FaceScene::update_wrinkles(): expected a scene with 1 frame in flight, found 2 "
             "(the pipelined frame is made by update() alone)");
    platform_.make_current();
    const auto t = Clock::now();
    wrinkle_morph_->update(target_, key_weights, params_);
    times_.morph_ms = ms_since(t);
}

void FaceScene::bake_light(const expression::TriMesh& shape, bool on_pose) {
    // Ambient occlusion (face_occlusion.h): the skin and the mouth interior
    // take it (the eyeballs turn away from the rest shape's occluders, so
    // they keep their own shading).
    const std::vector<float> occlusion = bake_face_occlusion(shape, face_);
    // The portrait key's cast shadows, for the skin. The key stands for a
    // soft box about 16 degrees in radius (a portrait's large box), seen
    // from 16 directions: its shadows' edges blur over a few mm at the
    // nose's and the brows' distance (at 10 degrees the nose's shadow edge
    // and the glabella's on the nasion read as drawn lines: blind review,
    // round 14). The renderer draws them while the key stays near this
    // direction (renderer.h, set_key_shadow).
    constexpr float kKeyRadiusDeg = 16.0f;
    constexpr int kKeySamples = 16;
    const glm::vec3 toward_key = glm::normalize(glm::vec3(portrait_light().position));
    const std::vector<float> key_visible =
        bake_face_light_visibility(shape, face_, toward_key, kKeyRadiusDeg, kKeySamples);
    for (int g = 0; g < kGroups; ++g) {
        const Part& part = parts_[std::size_t(g)];
        if (part.id < 0 || g == kEyes) continue;
        auto of_part = [&](const std::vector<float>& whole) {
            std::vector<float> values(part.full_index.size());
            for (std::size_t i = 0; i < values.size(); ++i) values[i] = whole[std::size_t(part.full_index[i])];
            return values;
        };
        std::vector<float> open = of_part(occlusion);
        if (g == kMouth && on_pose) {
            // The mouth interior has no relief map to carry the key's
            // shadows: they dim its occlusion instead (which shades it from
            // every light), by the key's share of its light. Only on the
            // pose: at rest the lips are closed over it, and what the key's
            // bake says of it there does not hold once the mouth opens.
            constexpr float kKeyShare = 0.7f;
            const std::vector<float> visible = of_part(key_visible);
            for (std::size_t i = 0; i < open.size(); ++i) open[i] *= 1.0f - kKeyShare * (1.0f - visible[i]);
        }
        renderer_->set_occlusion(part.id, open);
        renderer_->set_key_shadow(part.id, of_part(key_visible), toward_key);
    }
}

void FaceScene::bake_light_on_pose(const expression::FapValues& faps) {
    platform_.make_current();
    expression::TriMesh posed = face_.mesh;
    expression::FaceRig::write_to(rig_.deform(faps), posed);
    bake_light(posed, true);
}

void FaceScene::update_geometry(const expression::FapValues& faps) {
    if (back_texture_)
        fail("render: FaceScene::update_geometry(): expected a scene with 1 frame in flight, found 2 "
             "(the pipelined frame is made by update() alone)");
    deform(faps, /*layout_from_mesh=*/true);
}

void* FaceScene::geometry_stream() const { return cuda_geometry_ ? cuda_geometry_->stream() : nullptr; }

void FaceScene::deform_on_gpu(const expression::FapValues& faps, bool layout_from_mesh) {
    const auto t = Clock::now();
    frame_ = rig_.frame(faps);
    if (layout_from_mesh && layout_kind_ == WrinkleLayout::Projective) {
        layout_ = layout_of(rig_.feature_points(frame_), present_points(face_), box_);
        target_ = to_morph_layout(expression::layout_segments(lines_, layout_));
    }
    void* stream = cuda_geometry_->stream();
    run_gpu_geometry(geometry_buffers_->map(stream));
    geometry_buffers_->unmap(stream);
    times_.rig_ms = ms_since(t);  // host time: parameters, map, launches, unmap
    times_.uv_ms = times_.tangents_ms = times_.upload_ms = 0.0;
}

FaceScene::SurfacePoint FaceScene::surface_point(int vertex) const {
    if (vertex < 0 || vertex >= int(mesh_.n_vertices()))
        fail("render: FaceScene::surface_point(): expected a vertex below {}, found {}", mesh_.n_vertices(), vertex);
    const auto vh = mesh_.vertex_handle(unsigned(vertex));
    if (!cuda_geometry_) {
        const auto p = mesh_.point(vh);
        const auto n = mesh_.normal(vh);
        return {glm::vec3(p[0], p[1], p[2]), glm::vec3(n[0], n[1], n[2])};
    }
    // The GPU posed the vertex buffers only: the rig's body again here for
    // the vertex and its one-ring, the normal as the kernels make it (the
    // unit sum of the faces' unit normals).
    const expression::RigView rig = rig_.view();
    auto posed = [&](OpenMesh::VertexHandle v) {
        const auto p = expression::rig_kernel::position(rig, frame_, v.idx());
        return geometry_kernel::V3{p.x, p.y, p.z};
    };
    geometry_kernel::V3 sum{0, 0, 0};
    for (const auto fh : mesh_.vf_range(vh)) {
        geometry_kernel::V3 c[3];
        int i = 0;
        for (const auto v : mesh_.fv_range(fh)) c[i++] = posed(v);
        sum = sum + geometry_kernel::face_normal(c[0], c[1], c[2]);
    }
    const geometry_kernel::V3 p = posed(vh), n = geometry_kernel::unit_normal(sum);
    return {glm::vec3(p.x, p.y, p.z), glm::vec3(n.x, n.y, n.z)};
}

void FaceScene::deform(const expression::FapValues& faps, bool layout_from_mesh) {
    platform_.make_current();
    if (cuda_geometry_) return deform_on_gpu(faps, layout_from_mesh);
    auto t = Clock::now();
    rig_.deform(faps, deformed_);
    expression::FaceRig::write_to(deformed_, mesh_);
    times_.rig_ms = ms_since(t);

    const bool projective = layout_kind_ == WrinkleLayout::Projective;
    if (layout_from_mesh && projective) {
        t = Clock::now();
        layout_ = layout_of(deformed_.feature_points, present_points(face_), box_);
        target_ = to_morph_layout(expression::layout_segments(lines_, layout_));
        times_.layout_ms = ms_since(t);
    }

    times_.uv_ms = times_.tangents_ms = times_.upload_ms = 0.0;
    const auto* full_points = mesh_.points();
    const auto* full_normals = mesh_.vertex_normals();
    for (Part& part : parts_) {
        if (part.id < 0) continue;
        t = Clock::now();
        auto& points = part.mesh.property(part.mesh.points_pph()).data_vector();
        auto& normals = part.mesh.property(part.mesh.vertex_normals_pph()).data_vector();
        const bool cpu_frames = part.wrinkles && frames_ == WrinkleFrames::Mesh;
        for (std::size_t i = 0; i < part.full_index.size(); ++i) {
            const auto& p = full_points[part.full_index[i]];
            points[i] = p;
            normals[i] = full_normals[part.full_index[i]];
            if (cpu_frames && projective)
                part.wrinkle_uvs[i] = expression::project_to_texture(glm::vec3(p[0], p[1], p[2]), box_);
        }
        times_.uv_ms += ms_since(t);
        t = Clock::now();
        if (cpu_frames) part.frames.compute(part.mesh, part.wrinkle_uvs);
        times_.tangents_ms += ms_since(t);
        t = Clock::now();
        if (cpu_frames)
            renderer_->update_mesh(part.id, part.mesh, part.wrinkle_uvs, part.frames.tangents());
        else
            renderer_->update_shape(part.id, part.mesh);
        times_.upload_ms += ms_since(t);
    }
}

void FaceScene::finish() {
    platform_.make_current();
    glFinish();
}

void FaceScene::draw(const DrawOptions& options) {
    if (back_texture_) {
        platform_.make_current();
        if (!staging_copied_) copy_staging_to_renderer();
    }
    if (frames_ == WrinkleFrames::Shader) {
        DrawOptions o = options;
        o.projective_wrinkles = true;
        o.projective_box = {box_.min.x, box_.min.y, box_.max.x, box_.max.y};
        renderer_->draw(o, texture_.get());
    } else {
        renderer_->draw(options, texture_.get());
    }
    flush_pipeline();  // the frame in flight, after this draw's commands
}

Camera FaceScene::frontal_camera(float aspect, float fovy_degrees) const {
    // Frame the face (its texture box, where the wrinkles are) with some of
    // the head around it, not the neck.
    glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
    for (const auto vh : face_.mesh.vertices()) {
        const auto& p = face_.mesh.point(vh);
        lo = glm::min(lo, glm::vec3(p[0], p[1], p[2]));
        hi = glm::max(hi, glm::vec3(p[0], p[1], p[2]));
    }
    const glm::vec2 margin = 0.12f * (box_.max - box_.min);
    lo = glm::vec3(glm::max(glm::vec2(lo), box_.min - margin), lo.z);
    hi = glm::vec3(glm::min(glm::vec2(hi), box_.max + margin), hi.z);
    return Camera::frontal(lo, hi, aspect, fovy_degrees, 0.95f);
}

Light FaceScene::portrait_light() const {
    Light l;
    // A portrait key: 52 degrees to the viewer's left and 38 degrees above
    // the eyes (Rembrandt-like), so the far cheek, the eye sockets, the
    // nose's far side and the underside of the nose, lips and jaw turn
    // away from it and the face gets its shape; grazing enough on the
    // forehead and around the eyes that horizontal and vertical wrinkles
    // both shade. At 25 degrees the face was lit almost frontally and
    // read flat; at 40 and 35 the nose's cast shadow (its baked shadows)
    // fell under the nose, out of sight, and a blind observer still saw
    // 'flat frontal light, no cast shadows' (session 10, round 12).
    l.position = glm::vec4(glm::normalize(glm::vec3(-0.62f, 0.62f, 0.48f)), 0.0f);
    l.ambient = glm::vec3(0.16f);
    l.diffuse = glm::vec3(0.95f, 0.93f, 0.9f);
    l.specular = glm::vec3(0.3f);
    return l;
}

}  // namespace emoface::render
