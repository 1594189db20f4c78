// CudaGeometry (the rig, normals, wrinkle UVs and tangent frames on the GPU)
// against its CPU twin FaceGeometry::compute, on the default face in frames
// that move every stage of the rig. Skips without a CUDA device.
#include <gtest/gtest.h>

#include <cuda_runtime.h>

#include <algorithm>
#include <cmath>

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

}  // namespace
}  // namespace emoface::render
