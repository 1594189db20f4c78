// CudaGeometry: FaceGeometry's kernel bodies on the GPU. Three launches per
// frame on its own stream: the rig over the full mesh into a device scratch
// of positions, one thread per face (normal) and per part triangle (frame),
// then one thread per part vertex (a warp for a fan's pole) for its normal,
// wrinkle UV and tangent frame, gathered from those, written where the caller says (the mapped GL
// vertex buffers). The frame's parameters travel as the first launch's
// argument: no copy, no wait.
#include <cuda_runtime.h>

#include <vector>

#include "emoface/common/error.h"
#include "emoface/render/face_geometry.h"

namespace emoface::render {
namespace {

constexpr int kMaxParts = 8;

void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess)
        fail<InternalError>("render: CUDA geometry: {}: {} ({})", what, cudaGetErrorName(e), cudaGetErrorString(e));
}

struct PartOutputs {
    float* shape[kMaxParts];
    float* frame[kMaxParts];
};

__global__ void rig_kernel_launch(expression::RigView r, expression::RigFrame f, float* pos) {
    // The frame's tables are read at each vertex's own feature points: from
    // the launch's constant bank such scattered reads go one address at a
    // time per warp, from shared memory in parallel. So each block copies
    // the frame there first.
    __shared__ expression::RigFrame frame;
    static_assert(sizeof(expression::RigFrame) % sizeof(int) == 0, "copied as words");
    const int* src = reinterpret_cast<const int*>(&f);
    int* dst = reinterpret_cast<int*>(&frame);
    for (int i = threadIdx.x; i < int(sizeof(expression::RigFrame) / sizeof(int)); i += blockDim.x) dst[i] = src[i];
    __syncthreads();
    const int v = blockIdx.x * blockDim.x + threadIdx.x;
    if (v >= r.vertex_count) return;
    const expression::rig_kernel::P3 p = expression::rig_kernel::position(r, frame, v);
    pos[3 * v] = p.x;
    pos[3 * v + 1] = p.y;
    pos[3 * v + 2] = p.z;
}

__global__ void face_kernel_launch(geometry_kernel::GeometryView g, const float* pos, int faces, int part_triangles,
                                   geometry_kernel::V3* face_normals, geometry_kernel::FaceFrame* triangle_frames) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i < faces) face_normals[i] = geometry_kernel::face_pass(g, pos, i);
    else if (i < faces + part_triangles) triangle_frames[i - faces] = geometry_kernel::part_triangle_pass(g, pos, i - faces);
}

// The warp's 32 shares of a gather added (butterfly: every lane ends with
// the same sum, as a + b == b + a in floating point).
__device__ geometry_kernel::V3 warp_sum(geometry_kernel::V3 v) {
    for (int m = 16; m > 0; m >>= 1) {
        v.x += __shfl_xor_sync(0xffffffffu, v.x, m);
        v.y += __shfl_xor_sync(0xffffffffu, v.y, m);
        v.z += __shfl_xor_sync(0xffffffffu, v.z, m);
    }
    return v;
}

__device__ geometry_kernel::TangentSum warp_sum(geometry_kernel::TangentSum s) {
    s.t = warp_sum(s.t);
    s.b = warp_sum(s.b);
    for (int m = 16; m > 0; m >>= 1) s.w += __shfl_xor_sync(0xffffffffu, s.w, m);
    return s;
}

// The per-part-vertex pass. Its first `split_blocks` blocks give each of the
// `split` vertices with the longest gathers (at least kSplitGather: the
// fans' poles) a warp, each lane a 32nd of the gathers; they come first so
// that they start first. The blocks after have a thread per part vertex and
// skip those.
constexpr int kSplitGather = 24;
constexpr int kBlock = 256;

__global__ void part_kernel_launch(geometry_kernel::GeometryView g, const float* pos,
                                   const geometry_kernel::V3* face_normals,
                                   const geometry_kernel::FaceFrame* triangle_frames, PartOutputs out,
                                   const int* split, int split_count, int split_blocks) {
    if (int(blockIdx.x) < split_blocks) {
        const int w = (blockIdx.x * blockDim.x + threadIdx.x) / 32, lane = threadIdx.x % 32;
        if (w >= split_count) return;  // the whole warp
        const int pv = split[w];
        const int part = g.part_of[pv];
        const int local = pv - g.part_first[part];
        float* frame = g.part_frames[part] && out.frame[part] ? out.frame[part] + 6 * local : nullptr;
        const geometry_kernel::V3 n =
            geometry_kernel::unit_normal(warp_sum(geometry_kernel::part_normal_gather(g, face_normals, pv, lane, 32)));
        geometry_kernel::TangentSum t{};
        if (frame) t = warp_sum(geometry_kernel::part_tangent_gather(g, triangle_frames, pv, n, lane, 32));
        if (lane == 0) geometry_kernel::part_vertex_write(g, pos, pv, n, t, out.shape[part] + 6 * local, frame);
        return;
    }
    const int pv = (blockIdx.x - split_blocks) * blockDim.x + threadIdx.x;
    if (pv >= g.part_vertices || geometry_kernel::part_gather_size(g, pv) >= kSplitGather) return;
    const int part = g.part_of[pv];
    const int local = pv - g.part_first[part];
    float* frame = g.part_frames[part] && out.frame[part] ? out.frame[part] + 6 * local : nullptr;
    geometry_kernel::part_vertex_pass(g, pos, face_normals, triangle_frames, pv, out.shape[part] + 6 * local, frame);
}

// A host array copied to the device, freed with the owner.
struct DeviceArrays {
    std::vector<void*> blocks;
    template <class T>
    const T* copy(const T* host, std::size_t count) {
        if (!host || count == 0) return nullptr;
        void* d = nullptr;
        check(cudaMalloc(&d, count * sizeof(T)), "cudaMalloc");
        blocks.push_back(d);
        check(cudaMemcpy(d, host, count * sizeof(T), cudaMemcpyHostToDevice), "cudaMemcpy");
        return static_cast<const T*>(d);
    }
    ~DeviceArrays() {
        for (void* b : blocks) cudaFree(b);
    }
};

}  // namespace

bool cuda_geometry_available() {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess) {
        cudaGetLastError();
        return false;
    }
    return count > 0;
}

struct CudaGeometry::Impl {
    DeviceArrays arrays;
    expression::RigView rig;
    geometry_kernel::GeometryView geometry;
    int parts = 0;
    std::vector<unsigned char> part_frames;
    float* positions = nullptr;
    geometry_kernel::V3* face_normals = nullptr;
    geometry_kernel::FaceFrame* triangle_frames = nullptr;
    int faces = 0, part_triangles = 0;
    const int* split = nullptr;  // part vertices whose gathers a warp shares
    int split_count = 0;
    cudaStream_t stream = nullptr;
    cudaEvent_t event = nullptr;  // orders the stream with another
    ~Impl() {
        if (event) cudaEventDestroy(event);
        if (positions) cudaFree(positions);
        if (face_normals) cudaFree(face_normals);
        if (triangle_frames) cudaFree(triangle_frames);
        if (stream) cudaStreamDestroy(stream);
    }
};

CudaGeometry::CudaGeometry(const FaceGeometry& fg) : impl_(std::make_unique<Impl>()) {
    if (!cuda_geometry_available()) fail<EnvironmentError>("render: CUDA geometry: no CUDA device");
    if (fg.part_count() > kMaxParts)
        fail<InputError>("render: CUDA geometry: expected at most {} parts, found {}", kMaxParts, fg.part_count());
    Impl& m = *impl_;
    DeviceArrays& a = m.arrays;
    const expression::RigView h = fg.rig().view();
    const auto n = std::size_t(h.vertex_count);
    m.rig = h;
    m.rig.neutral = a.copy(h.neutral, 3 * n);
    m.rig.influence_start = a.copy(h.influence_start, n + 1);
    m.rig.influences = a.copy(h.influences, std::size_t(h.influence_start[n]));
    m.rig.lid_start = a.copy(h.lid_start, n + 1);
    m.rig.lid_weights = a.copy(h.lid_weights, std::size_t(h.lid_start[n]));
    m.rig.slide_start = a.copy(h.slide_start, n + 1);
    m.rig.slides = a.copy(h.slides, std::size_t(h.slide_start[n]));
    m.rig.lash_anchor = a.copy(h.lash_anchor, n);
    m.rig.lash_eye = a.copy(h.lash_eye, n);
    m.rig.jaw_weight = a.copy(h.jaw_weight, n);
    m.rig.eye_of = a.copy(h.eye_of, n);
    m.rig.eye_polar = a.copy(h.eye_polar, n);
    m.rig.eye_azimuth = a.copy(h.eye_azimuth, n);
    m.rig.head_weight = a.copy(h.head_weight, n);

    const geometry_kernel::GeometryView g = fg.view();
    const auto full = std::size_t(g.full_vertices), pv = std::size_t(g.part_vertices);
    const auto tris = std::size_t(g.vertex_face_start[full]);  // 3 x faces
    m.parts = fg.part_count();
    m.geometry = g;
    m.geometry.triangles = a.copy(g.triangles, tris);
    m.geometry.vertex_face_start = a.copy(g.vertex_face_start, full + 1);
    m.geometry.vertex_faces = a.copy(g.vertex_faces, tris);
    m.geometry.part_full = a.copy(g.part_full, pv);
    m.geometry.part_of = a.copy(g.part_of, pv);
    m.geometry.part_first = a.copy(g.part_first, std::size_t(m.parts) + 1);
    m.geometry.part_triangles = a.copy(g.part_triangles, std::size_t(g.corner_start[pv]));
    m.geometry.corner_start = a.copy(g.corner_start, pv + 1);
    m.geometry.corners = a.copy(g.corners, std::size_t(g.corner_start[pv]));
    m.geometry.part_frames = a.copy(g.part_frames, std::size_t(m.parts));
    m.geometry.fixed_uvs = a.copy(g.fixed_uvs, g.fixed_uvs ? 2 * pv : 0);
    m.part_frames.assign(g.part_frames, g.part_frames + m.parts);
    std::vector<int> split;
    for (int v = 0; v < g.part_vertices; ++v)
        if (geometry_kernel::part_gather_size(g, v) >= kSplitGather) split.push_back(v);
    m.split_count = int(split.size());
    m.split = a.copy(split.data(), split.size());
    check(cudaMalloc(reinterpret_cast<void**>(&m.positions), 3 * n * sizeof(float)), "cudaMalloc positions");
    m.faces = int(tris / 3);
    m.part_triangles = g.corner_start[pv] / 3;
    check(cudaMalloc(reinterpret_cast<void**>(&m.face_normals), std::size_t(m.faces + 1) * sizeof(geometry_kernel::V3)),
          "cudaMalloc face normals");
    check(cudaMalloc(reinterpret_cast<void**>(&m.triangle_frames),
                     std::size_t(m.part_triangles + 1) * sizeof(geometry_kernel::FaceFrame)),
          "cudaMalloc triangle frames");
    check(cudaStreamCreateWithFlags(&m.stream, cudaStreamNonBlocking), "cudaStreamCreate");
    check(cudaEventCreateWithFlags(&m.event, cudaEventDisableTiming), "cudaEventCreate");
}

void* CudaGeometry::stream() const { return impl_->stream; }

int CudaGeometry::split_vertices() const { return impl_->split_count; }

void CudaGeometry::wait_for(void* other) {
    check(cudaEventRecord(impl_->event, static_cast<cudaStream_t>(other)), "cudaEventRecord");
    check(cudaStreamWaitEvent(impl_->stream, impl_->event, 0), "cudaStreamWaitEvent");
}

void CudaGeometry::join_into(void* other) {
    check(cudaEventRecord(impl_->event, impl_->stream), "cudaEventRecord");
    check(cudaStreamWaitEvent(static_cast<cudaStream_t>(other), impl_->event, 0), "cudaStreamWaitEvent");
}

void CudaGeometry::finish() { check(cudaStreamSynchronize(impl_->stream), "cudaStreamSynchronize"); }

CudaGeometry::~CudaGeometry() = default;

void CudaGeometry::run(const expression::RigFrame& frame, const std::vector<float*>& shape,
                       const std::vector<float*>& frame_out) {
    Impl& m = *impl_;
    if (int(shape.size()) != m.parts || int(frame_out.size()) != m.parts)
        fail("render: CudaGeometry::run(): expected {} shape and frame pointers, found {} and {}", m.parts,
             shape.size(), frame_out.size());
    PartOutputs out{};
    for (int p = 0; p < m.parts; ++p) {
        if (!shape[std::size_t(p)]) fail("render: CudaGeometry::run(): part {} has no shape buffer", p);
        if (m.part_frames[std::size_t(p)] && !frame_out[std::size_t(p)])
            fail("render: CudaGeometry::run(): part {} has frames but no frame buffer", p);
        out.shape[p] = shape[std::size_t(p)];
        out.frame[p] = frame_out[std::size_t(p)];
    }
    const cudaStream_t s = m.stream;
    const int n = m.rig.vertex_count, pv = m.geometry.part_vertices;
    rig_kernel_launch<<<(n + kBlock - 1) / kBlock, kBlock, 0, s>>>(m.rig, frame, m.positions);
    if (pv > 0) {
        const int items = m.faces + m.part_triangles;
        face_kernel_launch<<<(items + kBlock - 1) / kBlock, kBlock, 0, s>>>(m.geometry, m.positions, m.faces,
                                                                           m.part_triangles, m.face_normals,
                                                                           m.triangle_frames);
        const int split_blocks = (m.split_count * 32 + kBlock - 1) / kBlock;
        part_kernel_launch<<<split_blocks + (pv + kBlock - 1) / kBlock, kBlock, 0, s>>>(
            m.geometry, m.positions, m.face_normals, m.triangle_frames, out, m.split, m.split_count, split_blocks);
    }
    check(cudaGetLastError(), "launching the geometry kernels");
}

}  // namespace emoface::render
