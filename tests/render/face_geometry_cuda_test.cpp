// CudaGeometry (the rig, normals, wrinkle UVs and tangent frames on the GPU)
// against its CPU twin FaceGeometry::compute, on the default face in frames
// that move every stage of the rig; and a FaceScene on a CUDA machine takes
// the GPU geometry by default and still answers surface_point() as the CPU
// geometry's posed mesh does. Skips without a CUDA device.
#include <gtest/gtest.h>

#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "emoface/render/face_assets.h"
#include "emoface/render/face_scene.h"
#include "emoface/render/image_diff.h"
#include "face_geometry_cases.h"

namespace emoface::render {
namespace {

using namespace testing;

TEST(CudaGeometry, MatchesTheCpuTwin) {
    if (!cuda_geometry_available()) GTEST_SKIP() << "no CUDA device: the GPU geometry is not tested here";
    const std::vector<GeometryPart> parts = testing::parts();
    FaceGeometry geometry(rig(), face().mesh, parts, box());
    CudaGeometry gpu(geometry);
    std::vector<float*> shape_d, frame_d;
    for (const GeometryPart& p : parts) {
        float* s = nullptr;
        float* f = nullptr;
        ASSERT_EQ(cudaMalloc(&s, p.full_index.size() * 6 * sizeof(float)), cudaSuccess);
        if (p.frames) ASSERT_EQ(cudaMalloc(&f, p.full_index.size() * 6 * sizeof(float)), cudaSuccess);
        shape_d.push_back(s);
        frame_d.push_back(f);
    }
    std::vector<std::vector<float>> shape, frame;
    for (const NamedFaps& named : frames()) {
        const expression::RigFrame f = rig().frame(named.faps);
        gpu.run(f, shape_d, frame_d);
        gpu.finish();
        geometry.compute(f, shape, frame);
        for (std::size_t p = 0; p < parts.size(); ++p) {
            std::vector<float> s(shape[p].size()), t(frame[p].size());
            ASSERT_EQ(cudaMemcpy(s.data(), shape_d[p], s.size() * sizeof(float), cudaMemcpyDeviceToHost), cudaSuccess);
            if (!t.empty())
                ASSERT_EQ(cudaMemcpy(t.data(), frame_d[p], t.size() * sizeof(float), cudaMemcpyDeviceToHost),
                          cudaSuccess);
            float worst_shape = 0, worst_frame = 0;
            int frames_over = 0;
            for (std::size_t i = 0; i < s.size(); ++i) worst_shape = std::max(worst_shape, std::fabs(s[i] - shape[p][i]));
            for (std::size_t v = 0; v < t.size(); v += 6) {
                float e = 0;
                for (int c = 0; c < 6; ++c) e = std::max(e, std::fabs(t[v + std::size_t(c)] - frame[p][v + std::size_t(c)]));
                worst_frame = std::max(worst_frame, e);
                frames_over += !(e <= 1e-3f);
            }
            // The same bodies; the GPU contracts multiply-adds into FMAs, which
            // may turn a tangent whose corners nearly cancel (rarely).
            EXPECT_LE(worst_shape, 1e-4f) << named.name << ", part " << p;
            EXPECT_LE(frames_over, int(t.size() / 6 / 10000) + 2) << named.name << ", part " << p
                                                                  << ": worst frame difference " << worst_frame;
        }
    }
    for (float* s : shape_d) cudaFree(s);
    for (float* f : frame_d) cudaFree(f);
}

TEST(FaceSceneGeometry, GpuByDefaultWithTheSurfaceOfTheCpuGeometry) {
    if (!cuda_geometry_available()) GTEST_SKIP() << "no CUDA device: the GPU geometry is not tested here";
    FaceAssetsOptions ao;
    ao.face.resolution_scale = 0.5;
    ao.face.texture_size = 256;
    ao.wrinkle_map_size = 256;
    const auto assets = load_default_face_assets(EMOFACE_DATA_DIR, ao);
    PlatformOptions po;
    po.width = po.height = 64;
    po.cuda_device = 0;
    HeadlessPlatform platform(po);
    FaceSceneOptions gpu_options;  // geometry: Auto
    gpu_options.backend = morph::Backend::Cuda;
    const auto gpu = make_face_scene(platform, *assets, gpu_options);
    if (!gpu->uses_interop()) GTEST_SKIP() << "the GL context is not on the CUDA device: no interop";
    EXPECT_TRUE(gpu->uses_gpu_geometry()) << "a CUDA morph through interop takes the GPU geometry by default";
    FaceSceneOptions cpu_options;
    cpu_options.backend = morph::Backend::Cpu;
    const auto cpu = make_face_scene(platform, *assets, cpu_options);
    EXPECT_FALSE(cpu->uses_gpu_geometry()) << "the CPU morph keeps the geometry on the CPU";

    std::vector<float> weights(std::size_t(gpu->key_count()), 0.0f);
    weights[0] = 1.0f;
    for (const NamedFaps& named : frames()) {
        gpu->update(named.faps, weights);
        cpu->update(named.faps, weights);
        int checked = 0;
        float worst_position = 0, worst_normal = 0, moved = 0;
        for (const auto& fp : assets->face.feature_points) {
            if (!fp.present || fp.vertex < 0) continue;
            const FaceScene::SurfacePoint g = gpu->surface_point(fp.vertex), c = cpu->surface_point(fp.vertex);
            worst_position = std::max(worst_position, glm::length(g.position - c.position));
            worst_normal = std::max(worst_normal, glm::length(g.normal - c.normal));
            // The GPU scene's host mesh stays neutral: the posed point is not read from it.
            const auto n = gpu->mesh().point(gpu->mesh().vertex_handle(unsigned(fp.vertex)));
            moved = std::max(moved, glm::length(g.position - glm::vec3(n[0], n[1], n[2])));
            ++checked;
        }
        EXPECT_GT(checked, 40) << named.name;
        // The same rig body in float; OpenMesh's normals from the same points.
        EXPECT_LE(worst_position, 1e-4f) << named.name;
        EXPECT_LE(worst_normal, 1e-3f) << named.name;
        if (named.name != "neutral") EXPECT_GT(moved, 1e-3f) << named.name << ": the feature points did not move";
    }
}

// A CUDA scene and a CPU scene of one small face on one headless platform,
// drawn alike (thesis shading, so the pictures compare on the wrinkles and
// the geometry alone). skip says why not, where there is no CUDA-GL interop.
struct ScenePair {
    explicit ScenePair(int frames_in_flight) {
        if (!cuda_geometry_available()) {
            skip = "no CUDA device: the GPU geometry is not tested here";
            return;
        }
        FaceAssetsOptions ao;
        ao.face.resolution_scale = 0.5;
        ao.face.texture_size = 256;
        ao.wrinkle_map_size = 256;
        assets = load_default_face_assets(EMOFACE_DATA_DIR, ao);
        PlatformOptions po;
        po.width = po.height = 160;
        po.cuda_device = 0;
        platform = std::make_unique<HeadlessPlatform>(po);
        FaceSceneOptions gpu_options;
        gpu_options.backend = morph::Backend::Cuda;
        gpu_options.frames_in_flight = frames_in_flight;
        gpu = make_face_scene(*platform, *assets, gpu_options);
        if (!gpu->uses_interop()) {
            skip = "the GL context is not on the CUDA device: no interop";
            return;
        }
        FaceSceneOptions cpu_options;
        cpu_options.backend = morph::Backend::Cpu;
        cpu_options.frames_in_flight = frames_in_flight;  // no CUDA: the scene runs unpipelined
        cpu = make_face_scene(*platform, *assets, cpu_options);
        draw.camera = cpu->frontal_camera(1.0f);
        draw.light = cpu->portrait_light();
        draw.shading = Shading::Thesis;
        // Every key at once, so the morph writes wrinkles everywhere it can.
        weights.assign(std::size_t(gpu->key_count()), 1.0f / float(gpu->key_count()));
    }
    ImageRGBA8 render(FaceScene& scene) {
        platform->begin_frame();
        scene.draw(draw);
        platform->end_frame();
        return platform->read_rgba();
    }
    std::string skip;
    std::unique_ptr<FaceAssets> assets;
    std::unique_ptr<HeadlessPlatform> platform;
    std::unique_ptr<FaceScene> gpu, cpu;
    DrawOptions draw;
    std::vector<float> weights;
};

// update() on a CUDA scene maps the wrinkle texture and the vertex buffers
// in one call and runs the morph and the geometry on two streams in between;
// what it draws is what the CPU morph and geometry draw, frame after frame
// (a wrong order between the streams and the mapping would draw stale or
// half-written buffers).
TEST(FaceSceneGeometry, OneMappingDrawsWhatTheCpuDraws) {
    ScenePair s(1);
    if (!s.skip.empty()) GTEST_SKIP() << s.skip;
    ASSERT_TRUE(s.gpu->uses_gpu_geometry());
    ImageRGBA8 previous;
    for (const NamedFaps& named : frames()) {
        s.gpu->update(named.faps, s.weights);
        const ImageRGBA8 g = s.render(*s.gpu);
        s.cpu->update(named.faps, s.weights);
        const ImageRGBA8 c = s.render(*s.cpu);
        EXPECT_GE(diff_images(g, c).psnr(), 40.0) << named.name;
        if (!previous.pixels.empty() && named.name != "neutral")
            EXPECT_LT(diff_images(g, previous).psnr(), 60.0) << named.name << ": the frame did not change";
        previous = g;
    }
}

// frames_in_flight 2: update() leaves its frame in flight into the second
// texture and buffers and draw() draws the frame before it, which the CPU
// scene draws too, frame after frame (a wrong order between the CUDA work,
// the unmapping after the draw and the swap would draw the frame in flight,
// a stale one or half-written buffers); flush_pipeline() lands the last.
TEST(FaceSceneGeometry, PipelinedDrawsWhatTheCpuDrawsAFrameLater) {
    ScenePair s(2);
    if (!s.skip.empty()) GTEST_SKIP() << s.skip;
    ASSERT_EQ(s.gpu->frames_in_flight(), 2);
    ASSERT_EQ(s.cpu->frames_in_flight(), 1);
    // Frame 0 draws the scene's first state (neutral, the first key alone).
    ImageRGBA8 previous;
    int compared = 0;
    for (const NamedFaps& named : frames()) {
        s.gpu->update(named.faps, s.weights);
        const ImageRGBA8 g = s.render(*s.gpu);
        const ImageRGBA8 c = s.render(*s.cpu);  // the CPU scene still at the frame before
        EXPECT_GE(diff_images(g, c).psnr(), 40.0) << "the frame before " << named.name;
        if (!previous.pixels.empty() && compared > 1)
            EXPECT_LT(diff_images(g, previous).psnr(), 60.0) << "the frame before " << named.name << " did not change";
        previous = g;
        s.cpu->update(named.faps, s.weights);
        ++compared;
    }
    s.gpu->flush_pipeline();
    EXPECT_GE(diff_images(s.render(*s.gpu), s.render(*s.cpu)).psnr(), 40.0) << "the last frame, flushed";
    EXPECT_GT(compared, 2);
}

}  // namespace
}  // namespace emoface::render
