#pragma once
// A frame's drawn geometry from its FAPs, in three passes of kernel bodies:
// the rig (expression/rig_kernel.h) gives every vertex's position; each face
// its normal and each part triangle its frame; then each vertex of each
// drawn part (skin, eyes, mouth: FaceScene's meshes) gets its vertex normal
// (the full mesh's faces around it, as OpenMesh's), and in the parts with
// wrinkles its wrinkle UV and tangent frame (render/geometry_kernel.h),
// written in the renderer's vertex layout:
//   shape: 6 floats per vertex (position, normal)
//   frame: 6 floats per vertex (tangent xyzw, wrinkle UV)
// FaceGeometry holds the topology and runs the bodies on the CPU (all
// cores): the twin of CudaGeometry, which runs the same bodies on the GPU
// into device memory (CUDA-GL interop: the GL vertex buffers themselves), so
// that per frame only the RigFrame crosses from the host.
#include <array>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>

#include "emoface/expression/mesh.h"
#include "emoface/expression/rig.h"
#include "emoface/render/geometry_kernel.h"

namespace emoface::render {

struct GeometryPart {
    std::vector<int> full_index;  // part vertex -> full mesh vertex
    std::vector<int> triangles;   // 3 part vertices per triangle
    bool frames = false;          // wrinkle UVs and tangent frames are made per frame
    // The wrinkle UVs when they do not move (the anchored layout), one per
    // part vertex; empty: projected into the texture box each frame.
    std::vector<glm::vec2> fixed_uvs;
};

class FaceGeometry {
public:
    // `mesh`: the face's full mesh (its faces are the normals' neighbourhoods);
    // `box`: the texture box the projective UVs are taken in.
    FaceGeometry(const expression::FaceRig& rig, const expression::TriMesh& mesh, std::vector<GeometryPart> parts,
                 const std::array<float, 4>& box);

    int part_count() const { return int(parts_.size()); }
    int part_size(int part) const { return int(parts_[std::size_t(part)].full_index.size()); }
    const GeometryPart& part(int p) const { return parts_[std::size_t(p)]; }
    const expression::FaceRig& rig() const { return rig_; }
    geometry_kernel::GeometryView view() const;  // host pointers, valid while this lives

    // The CPU twin: positions of the full mesh, then each part's shape and
    // (parts with frames) frame arrays, on all cores. `shape[p]` and
    // `frame[p]` are resized as needed (frame[p] stays empty for parts
    // without frames).
    void compute(const expression::RigFrame& frame, std::vector<std::vector<float>>& shape,
                 std::vector<std::vector<float>>& frame_out);

private:
    const expression::FaceRig& rig_;
    std::vector<GeometryPart> parts_;
    std::vector<int> triangles_, vertex_face_start_, vertex_faces_;
    std::vector<int> part_full_, part_of_, part_first_, part_triangles_, corner_start_, corners_;
    std::vector<unsigned char> part_frames_;
    std::vector<float> fixed_uvs_;
    std::array<float, 4> box_;
    // Scratch: 3 floats per full vertex, a normal per face, a frame per part triangle.
    std::vector<float> positions_;
    std::vector<geometry_kernel::V3> face_normals_;
    std::vector<geometry_kernel::FaceFrame> triangle_frames_;
};

// Whether this build and machine can run CudaGeometry.
bool cuda_geometry_available();

// FaceGeometry's bodies on the GPU. The face's arrays go to the device once;
// run() launches the rig over the full mesh and the per-part body on the
// object's own CUDA stream and returns without waiting.
class CudaGeometry {
public:
    explicit CudaGeometry(const FaceGeometry& geometry);  // throws EnvironmentError without CUDA
    ~CudaGeometry();
    CudaGeometry(const CudaGeometry&) = delete;
    CudaGeometry& operator=(const CudaGeometry&) = delete;

    // shape[p], frame[p]: device pointers (a mapped GL buffer, or memory of
    // the caller's); frame[p] may be null for parts without frames.
    void run(const expression::RigFrame& frame, const std::vector<float*>& shape, const std::vector<float*>& frame_out);
    void* stream() const;  // a cudaStream_t
    void finish();         // waits for the stream
    // Orders this object's stream and another (a cudaStream_t): work queued
    // here after wait_for() waits for what `other` has queued so far; work
    // queued on `other` after join_into() waits for what is queued here.
    void wait_for(void* other);
    void join_into(void* other);
    // How many part vertices have gathers long enough (a fan's pole) that a
    // warp shares each: the pass would otherwise last as long as their one thread.
    int split_vertices() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

// GL buffers registered with CUDA once, mapped per frame (CUDA-GL interop).
class GlBufferInterop {
public:
    explicit GlBufferInterop(const std::vector<unsigned>& gl_buffers);  // throws without CUDA
    ~GlBufferInterop();
    GlBufferInterop(const GlBufferInterop&) = delete;
    GlBufferInterop& operator=(const GlBufferInterop&) = delete;
    // All buffers mapped in one call; their device pointers, in order.
    std::vector<float*> map(void* stream);
    void unmap(void* stream);
    // The registered buffers (cudaGraphicsResource_t), for a mapping together
    // with other resources (WrinkleTexture::map_surface(stream, others)), and
    // their device pointers while so mapped.
    const std::vector<void*>& resources() const { return resources_; }
    std::vector<float*> pointers() const;

private:
    std::vector<void*> resources_;
    bool mapped_ = false;
};

}  // namespace emoface::render
