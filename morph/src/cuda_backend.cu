// The CUDA backend: the same kernel body (kernel.h) launched over the image.
//
// Setup (once): key maps (each cropped to its region) in pitched device
// memory with a texture object over each, one stream, and, when the line table is too large to pass as a kernel
// parameter, a device table. A frame passes the line table as a kernel
// parameter (up to 8 KB: N = 84 lines with 2 sources fit) or uploads it in
// by-value slices to the device table, then launches (no host
// synchronisation, so frames can be captured into a CUDA graph):
//   exact: warp_kernel over the pixels: lines staged in shared memory, u, v
//          and the weight once per pixel-line for each batch of the sources
//          whose bound meets the block (kernel.h, "Batches"), hand bilinear
//          sampling (bit-compatible with the CPU), blend, store.
//   fast:  warp_kernel over a grid every `fast_cell` pixels writing the
//          sums of all lines, tile_kernel listing each cell's near lines
//          (and its corner sums without them),
//          then apply_kernel over the pixels: far sums interpolated, near
//          lines exact (kernel.h, "fast mode"), texture-unit sampling
//          where the weights sum to at most 1 (else, and for keys cropped
//          to a region, by hand: rest outside the crop).
// A frame of K <= 8 sources without regions, the common case, runs kernels
// specialised for one batch (warp_kernel, apply_kernel: One), as fast as
// before batches existed.
// Nothing is allocated per frame; buffers for positions, host output and the
// fast grid are allocated at their first use.
#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <string>
#include <type_traits>
#include <vector>

#include "backend.h"
#include "emoface/common/error.h"
#include "emoface/morph/kernel.h"

namespace emoface::morph::detail {
namespace {

using kernel::Accum;
using kernel::Law;
using kernel::kMaxKeys;

void cuda_check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) fail<InternalError>("morph: CUDA: {} failed: {}", what, cudaGetErrorString(e));
}
#define EMOFACE_CUDA_CHECK(call) cuda_check((call), #call)

// Line records passed by value: 8 KB of kernel parameters (CUDA 12.1+ allows
// up to 32 KB; 8 KB keeps the launch cheap and holds N = 84 with K = 2).
constexpr int kParamTableFloat4 = 512;
struct LineTable {
    float4 rec[kParamTableFloat4];
};

enum class OutKind : int { Pixels, Surface, Displacement, Sums };

// Grid sums (all the frame's sources, by slot) are padded to whole float4s.
__host__ __device__ constexpr int sums_stride(int sources) { return (kernel::sum_floats(sources) + 3) / 4 * 4; }

// About 3 KB with kMaxKeys = 32 sources; with the 8 KB line table the
// launch passes about 11 KB of parameters (CUDA 12.1+ on Volta and newer
// takes up to 32 KB).
struct KernelArgs {
    const float4* lines;  // device table, or nullptr: the LineTable parameter
    int n_lines;
    int record_floats;
    int chunk_lines;  // lines staged in shared memory at a time
    int line_split;   // PX = 1 only: threadIdx.y splits the lines of one row, not rows
    float extent, inv_extent, b;
    int points_w, points_h;  // the lattice evaluated by warp_kernel
    int spacing;             // pixels between lattice points
    int width, height;
    int sources;                            // the frame's sources, by slot:
    kernel::ImageView key[kMaxKeys];        //   stored pixels (crop) and rest
    cudaTextureObject_t tex[kMaxKeys];      //   texture over the stored pixels
    float weight[kMaxKeys];
    kernel::Bound bound[kMaxKeys];          //   target pixels where evaluated
    kernel::Rgba rest;
    int hw_filter;  // whole keys through the texture unit (sample_batch)
    int is_float;
    int normal_map;
    OutKind out_kind;
    unsigned char* out;
    std::size_t out_pitch;
    int out_vector;  // out and out_pitch allow 16-byte stores
    cudaSurfaceObject_t surface;
    float2* disp;  // Displacement: [point][source] in pixels
    float* sums;   // Sums: [point][sums_stride(sources)]
    // Fast mode: grid sums, and per cell its near lines.
    const float* grid;
    int grid_w, cell, tiles_w, tiles_h;
    float inv_cell;
    float reach;  // iso units, from a cell's centre
    int* near_count;
    unsigned short* near_list;  // [cell][kernel::kMaxNear]
    float* tile_sums;           // [cell][4 corners][sums_stride(sources)], cells with near lines only
};
// The arguments alone within the classic 4 KB; with the line table within
// the 32764 bytes CUDA 12.1+ allows.
static_assert(sizeof(KernelArgs) <= 4096, "KernelArgs over 4 KB: keep per-source data small");
static_assert(sizeof(KernelArgs) + sizeof(LineTable) <= 32764, "kernel parameters over CUDA's limit");

// Copies one 8 KB slice of a line table that is too large to pass by value
// into the device table. The slice travels as a kernel parameter, so a frame
// needs no pinned staging buffer, no host synchronisation, and can be
// captured into a CUDA graph.
__global__ void __launch_bounds__(256) upload_kernel(const __grid_constant__ LineTable slice, float4* dst, int count) {
    for (int i = threadIdx.x; i < count; i += blockDim.x) dst[i] = slice.rec[i];
}

__device__ EMOFACE_INLINE void store_pixel(const KernelArgs& a, int x, int y, const kernel::Rgba& c) {
    if (a.out_kind == OutKind::Surface) {
        if (a.is_float)
            surf2Dwrite(make_float4(c.r, c.g, c.b, c.a), a.surface, x * 16, y);
        else
            surf2Dwrite(make_uchar4(kernel::to_byte(c.r), kernel::to_byte(c.g), kernel::to_byte(c.b),
                                    kernel::to_byte(c.a)),
                        a.surface, x * 4, y);
        return;
    }
    unsigned char* row = a.out + static_cast<std::size_t>(y) * a.out_pitch;
    if (a.is_float)
        reinterpret_cast<float4*>(row)[x] = make_float4(c.r, c.g, c.b, c.a);
    else
        reinterpret_cast<unsigned int*>(row)[x] = kernel::pack_rgba8(c);
}

// The fast grid and line table as the kernel body sees them.
__device__ EMOFACE_INLINE kernel::FastGrid fast_grid(const KernelArgs& a, const LineTable& table) {
    return {reinterpret_cast<const float*>(a.lines != nullptr ? a.lines : table.rec),
            a.record_floats,
            a.n_lines,
            a.grid,
            a.grid_w,
            sums_stride(a.sources),
            a.cell,
            a.inv_cell,
            a.inv_extent,
            a.reach,
            a.b};
}

// The sum of the batch's weights.
template <int K>
__device__ EMOFACE_INLINE float batch_weight(const KernelArgs& a, const kernel::Batch<K>& batch) {
    float w = 0.0f;
#pragma unroll
    for (int k = 0; k < K; ++k)
        if (k < batch.n) w += a.weight[batch.slot[k]];
    return w;
}

// One thread sums all lines for PX points of one lattice row. On small
// lattices (line_split > 1) the threadIdx.y threads of a block share one row
// instead: each sums every line_split-th line and the partial sums meet in
// shared memory, so a 256² image still fills the GPU. The block lists the
// sources whose bound meets its points and runs the lines once per batch
// of them (kernel.h, "Batches"); the batches' colours add up per point.
// One: the frame's K sources are one batch evaluated everywhere (no
// regions, K <= kMaxBatch), the common case: no source lists, each line
// record loaded into registers with 16-byte loads at a compile-time size,
// and each point blended and stored as soon as its sums are done (no
// colour kept across batches).
template <int K, int PX, Law L, bool One>
__global__ void __launch_bounds__(256) warp_kernel(const __grid_constant__ KernelArgs a,
                                                   const __grid_constant__ LineTable table) {
    constexpr int S = kernel::sum_floats(K);
    constexpr int kOneRec4 = kernel::record_floats(K) / 4;
    extern __shared__ float4 s_lines[];
    const float4* src = a.lines != nullptr ? a.lines : table.rec;
    const int rec4 = One ? kOneRec4 : a.record_floats / 4;
    const int tid = threadIdx.y * blockDim.x + threadIdx.x;
    const int threads = blockDim.x * blockDim.y;
    const bool split = a.line_split > 1;
    const int i0 = (blockIdx.x * blockDim.x + threadIdx.x) * PX;
    const int j = split ? blockIdx.y : blockIdx.y * blockDim.y + threadIdx.y;
    const int first_line = split ? threadIdx.y : 0;
    const int line_step = split ? blockDim.y : 1;
    const bool writes = !split || threadIdx.y == 0;
    const int sp = a.spacing;
    const float x0 = (static_cast<float>(i0 * sp) + 0.5f) * a.inv_extent;
    const float y = (static_cast<float>(j * sp) + 0.5f) * a.inv_extent;
    const float step = static_cast<float>(sp) * a.inv_extent;

    // The sums of all lines for the batch at this thread's points (split:
    // complete in the threadIdx.y == 0 threads).
    auto sum_lines = [&](const kernel::Batch<K>& batch, Accum<K, PX>& acc) {
        acc.clear();
        for (int base = 0; base < a.n_lines; base += a.chunk_lines) {
            const int count = min(a.chunk_lines, a.n_lines - base);
            __syncthreads();
            for (int t = tid; t < count * rec4; t += threads) s_lines[t] = src[base * rec4 + t];
            __syncthreads();
            for (int l = first_line; l < count; l += line_step) {
                if constexpr (One) {
                    float4 r4[kOneRec4];
#pragma unroll
                    for (int q = 0; q < kOneRec4; ++q) r4[q] = s_lines[l * kOneRec4 + q];
                    kernel::accumulate_line<K, PX, L>(reinterpret_cast<const float*>(r4), x0, y, step, a.b, batch,
                                                      acc);
                } else {
                    kernel::accumulate_line<K, PX, L>(reinterpret_cast<const float*>(s_lines + l * rec4), x0, y,
                                                      step, a.b, batch, acc);
                }
            }
        }
        if (split) {
            float* partial = reinterpret_cast<float*>(s_lines + a.chunk_lines * rec4);
            __syncthreads();
            float* mine = partial + (threadIdx.y * blockDim.x + threadIdx.x) * (S * PX);
#pragma unroll
            for (int p = 0; p < PX; ++p) kernel::store_sums(acc, p, mine + p * S);
            __syncthreads();
            if (threadIdx.y == 0)
                for (int g = 1; g < static_cast<int>(blockDim.y); ++g) {
                    const float* other = partial + (g * blockDim.x + threadIdx.x) * (S * PX);
#pragma unroll
                    for (int p = 0; p < PX; ++p) kernel::add_sums(other + p * S, p, acc);
                }
        }
    };
    // Point p's result for the batch: grid sums, displacements, or its
    // sources sampled and added to `colour`.
    auto batch_point = [&](const kernel::Batch<K>& batch, const Accum<K, PX>& acc, int p, int i,
                           kernel::Rgba& colour) {
        if (a.out_kind == OutKind::Sums) {
            kernel::store_frame_sums(acc, p, batch,
                                     a.sums + (static_cast<std::size_t>(j) * a.points_w + i) * sums_stride(a.sources));
            return;
        }
        float dx[K], dy[K];
        kernel::displacement(acc, p, a.extent, dx, dy);
        if (a.out_kind == OutKind::Displacement) {
            float2* d = a.disp + (static_cast<std::size_t>(j) * a.points_w + i) * a.sources;
#pragma unroll
            for (int k = 0; k < K; ++k)
                if (k < batch.n) d[batch.slot[k]] = make_float2(dx[k], dy[k]);
            return;
        }
        kernel::blend_batch<K>(a.key, a.weight, batch, static_cast<float>(i) + 0.5f, static_cast<float>(j) + 0.5f, dx,
                               dy, colour);
    };
    const bool colours = a.out_kind != OutKind::Sums && a.out_kind != OutKind::Displacement;

    if constexpr (One) {
        const kernel::Batch<K> batch = kernel::all_sources<K>();
        Accum<K, PX> acc;
        sum_lines(batch, acc);
        if (!writes || j >= a.points_h) return;
        const float weight_sum = batch_weight(a, batch);
#pragma unroll
        for (int p = 0; p < PX; ++p) {
            const int i = i0 + p;
            if (i >= a.points_w) break;
            kernel::Rgba colour{0.0f, 0.0f, 0.0f, 0.0f};
            batch_point(batch, acc, p, i, colour);
            if (colours)
                store_pixel(a, i, j,
                            kernel::finish_blend(colour, weight_sum, a.rest, a.normal_map != 0, a.is_float != 0));
        }
        return;
    }

    // The block's points in pixels, grown by one lattice step: a grid
    // point serves the cells on both sides of it.
    const int bi0 = blockIdx.x * blockDim.x * PX, bi1 = bi0 + blockDim.x * PX;
    const int bj0 = split ? blockIdx.y : blockIdx.y * blockDim.y, bj1 = split ? bj0 + 1 : bj0 + blockDim.y;
    std::uint32_t mask = kernel::sources_meeting(a.bound, a.sources, (bi0 - 1) * sp, (bj0 - 1) * sp,
                                                 (bi1 - 1) * sp + sp, (bj1 - 1) * sp + sp);
    kernel::Rgba colour[PX];
#pragma unroll
    for (int p = 0; p < PX; ++p) colour[p] = {0.0f, 0.0f, 0.0f, 0.0f};
    float weight_sum = 0.0f;
    kernel::Batch<K> batch;
    while (kernel::take_batch(mask, batch)) {  // the same batches for the whole block
        Accum<K, PX> acc;
        sum_lines(batch, acc);
        weight_sum += batch_weight(a, batch);
        if (!writes || j >= a.points_h) continue;
#pragma unroll
        for (int p = 0; p < PX; ++p) {
            const int i = i0 + p;
            if (i >= a.points_w) break;
            batch_point(batch, acc, p, i, colour[p]);
        }
    }
    if (!writes || j >= a.points_h || !colours) return;
#pragma unroll
    for (int p = 0; p < PX; ++p) {
        const int i = i0 + p;
        if (i >= a.points_w) break;
        store_pixel(a, i, j, kernel::finish_blend(colour[p], weight_sum, a.rest, a.normal_map != 0, a.is_float != 0));
    }
}

// The sources whose bound meets cell (tx, ty).
__device__ EMOFACE_INLINE std::uint32_t cell_sources(const KernelArgs& a, int tx, int ty) {
    return kernel::sources_meeting(a.bound, a.sources, tx * a.cell, ty * a.cell, tx * a.cell + a.cell,
                                   ty * a.cell + a.cell);
}

// Fast mode, pass 2: one thread per cell lists the lines near it and, if
// there are any (and not too many), writes the cell's four corner sums
// without them for the sources evaluated there, so pass 3 never recomputes
// them per pixel.
template <int K, Law L>
__global__ void __launch_bounds__(128) tile_kernel(const __grid_constant__ KernelArgs a,
                                                   const __grid_constant__ LineTable table) {
    const int t = blockIdx.x * blockDim.x + threadIdx.x;
    if (t >= a.tiles_w * a.tiles_h) return;
    const int tx = t % a.tiles_w, ty = t / a.tiles_w;
    std::uint32_t mask = cell_sources(a, tx, ty);
    const kernel::FastGrid g = fast_grid(a, table);
    unsigned short* list = a.near_list + static_cast<std::size_t>(t) * kernel::kMaxNear;
    const int count = mask != 0 ? kernel::cell_near_lines(g, tx, ty, list) : 0;
    a.near_count[t] = count;
    if (count == 0 || count > kernel::kMaxNear) return;
    const int S4 = sums_stride(a.sources);
    kernel::Batch<K> batch;
    while (kernel::take_batch(mask, batch))
        kernel::cell_corner_sums<K, L>(g, list, count, tx, ty, batch, a.tile_sums + static_cast<std::size_t>(t) * 4 * S4,
                                       S4);
}

// Adds the batch's sources at pixel (px, py) displaced by (dx, dy) to
// `sum`. A whole key goes through the texture unit where the frame's
// weights sum to at most 1 (hw_filter): its 8-bit interpolation weights
// then stay within the CPU parity tolerance, while keys adding up over
// rest (weights summing to several) multiply that error, and are sampled
// by hand like the CPU, as are cropped keys (rest outside the crop).
template <int K>
__device__ EMOFACE_INLINE void sample_batch(const KernelArgs& a, const kernel::Batch<K>& batch, float px, float py,
                                            const float (&dx)[K], const float (&dy)[K], kernel::Rgba& sum) {
    const float unit = a.is_float ? 1.0f : 255.0f;
#pragma unroll
    for (int k = 0; k < K; ++k) {
        if (k >= batch.n) break;
        const int i = batch.slot[k];
        const kernel::ImageView& key = a.key[i];
        if (a.hw_filter && key.crop_w == a.width && key.crop_h == a.height) {
            const float4 t = tex2D<float4>(a.tex[i], px + dx[k], py + dy[k]);
            kernel::add_weighted(sum, {t.x, t.y, t.z, t.w}, a.weight[i] * unit);
        } else {
            kernel::add_weighted(sum, kernel::sample_bilinear(key, px + dx[k], py + dy[k]), a.weight[i]);
        }
    }
}

// Fast mode, pass 3: four pixels of one row a thread, all in one cell
// (fast_cell is a multiple of 4); a warp covers 32 x 4 pixels, so its loads
// of grid corners and its texture fetches stay local. Per batch of the
// sources evaluated in the cell, its corner sums are interpolated (less the
// near lines' terms, where it has any), then the near lines are added
// exactly (kernel.h, "fast mode") and the keys sampled (sample_batch).
// One: as in warp_kernel, the frame's sources are one batch evaluated
// everywhere, and moreover all whole keys sampled by the texture unit
// (hw_filter): the corners are read with 16-byte loads, records are
// compile-time sized, and each pixel is finished as soon as its batch is
// (no colour kept across batches and no hand-sampling code, either of
// which spills under the 3-blocks-an-SM register budget).
template <int K, Law L, bool One>
__global__ void __launch_bounds__(256, 3) apply_kernel(const __grid_constant__ KernelArgs a,
                                                    const __grid_constant__ LineTable table) {
    const int x0 = (blockIdx.x * blockDim.x + threadIdx.x) * 4;
    const int y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x0 >= a.width || y >= a.height) return;
    kernel::FastGrid g = fast_grid(a, table);
    if constexpr (One) g.record_floats = kernel::record_floats(K);  // the frame's K sources
    const int tx = x0 / a.cell, ty = y / a.cell;
    const int tile = ty * a.tiles_w + tx;
    const int count = a.near_count[tile];
    const unsigned short* list = a.near_list + static_cast<std::size_t>(tile) * kernel::kMaxNear;
    const float inv = a.inv_extent;
    const float xi = (static_cast<float>(x0) + 0.5f) * inv, yi = (static_cast<float>(y) + 0.5f) * inv;
    const bool crowded = count > kernel::kMaxNear;  // every line, exactly

    // The cell's corner sums: from the grid, or from pass 2 where the cell
    // has near lines.
    const int S = sums_stride(a.sources);
    const float *c00, *c10, *c01, *c11;
    if (count == 0) {
        c00 = a.grid + (static_cast<std::size_t>(ty) * a.grid_w + tx) * S;
        c10 = c00 + S;
        c01 = c00 + static_cast<std::size_t>(a.grid_w) * S;
        c11 = c01 + S;
    } else {
        c00 = a.tile_sums + static_cast<std::size_t>(tile) * 4 * S;
        c10 = c00 + S;
        c01 = c00 + 2 * S;
        c11 = c00 + 3 * S;
    }
    const float fy = static_cast<float>(y - ty * a.cell) * a.inv_cell;

    // RGBA8 into a plain buffer goes out as one 16-byte store per thread;
    // anything else is stored pixel by pixel.
    const bool vector_store = a.out_vector && a.out_kind == OutKind::Pixels && !a.is_float && x0 + 3 < a.width;
    unsigned int packed[4];
    auto finish = [&](int p, const kernel::Rgba& colour, float weight_sum) {
        const kernel::Rgba c = kernel::finish_blend(colour, weight_sum, a.rest, a.normal_map != 0, a.is_float != 0);
        if (vector_store)
            packed[p] = kernel::pack_rgba8(c);
        else if (x0 + p < a.width)
            store_pixel(a, x0 + p, y, c);
    };
    // Pixel p's result for the batch, from the cell row's ends: its
    // displacements, or its sources sampled and added to `colour`.
    auto batch_pixel = [&](const kernel::Batch<K>& batch, const float* left, const float* right, int p,
                           kernel::Rgba& colour) {
        const int x = x0 + p;
        Accum<K, 1> acc;
        kernel::cell_run<K, 1, L>(g, list, count, left, right, x - tx * a.cell, xi + static_cast<float>(p) * inv, yi,
                                  batch, acc);
        float dx[K], dy[K];
        kernel::displacement(acc, 0, a.extent, dx, dy);
        if (a.out_kind == OutKind::Displacement) {
            if (x < a.width) {
                float2* d = a.disp + (static_cast<std::size_t>(y) * a.width + x) * a.sources;
#pragma unroll
                for (int k = 0; k < K; ++k)
                    if (k < batch.n) d[batch.slot[k]] = make_float2(dx[k], dy[k]);
            }
            return;
        }
        const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
        if constexpr (One) {
            const float unit = a.is_float ? 1.0f : 255.0f;
#pragma unroll
            for (int k = 0; k < K; ++k) {
                const float4 t = tex2D<float4>(a.tex[k], px + dx[k], py + dy[k]);
                kernel::add_weighted(colour, {t.x, t.y, t.z, t.w}, a.weight[k] * unit);
            }
        } else {
            sample_batch(a, batch, px, py, dx, dy, colour);
        }
    };

    if constexpr (One) {
        constexpr int S4 = sums_stride(K) / 4;
        const kernel::Batch<K> batch = kernel::all_sources<K>();
        // kernel::cell_row_end for every source, with 16-byte loads.
        float4 left[S4], right[S4];
        if (!crowded) {
            const float4 *q00 = reinterpret_cast<const float4*>(c00), *q01 = reinterpret_cast<const float4*>(c01);
            const float4 *q10 = reinterpret_cast<const float4*>(c10), *q11 = reinterpret_cast<const float4*>(c11);
#pragma unroll
            for (int q = 0; q < S4; ++q) {
                const float4 t0 = __ldg(q00 + q), b0 = __ldg(q01 + q), t1 = __ldg(q10 + q), b1 = __ldg(q11 + q);
                left[q] = make_float4(t0.x + fy * (b0.x - t0.x), t0.y + fy * (b0.y - t0.y),
                                      t0.z + fy * (b0.z - t0.z), t0.w + fy * (b0.w - t0.w));
                right[q] = make_float4(t1.x + fy * (b1.x - t1.x), t1.y + fy * (b1.y - t1.y),
                                       t1.z + fy * (b1.z - t1.z), t1.w + fy * (b1.w - t1.w));
            }
        }
        const float weight_sum = batch_weight(a, batch);
#pragma unroll
        for (int p = 0; p < 4; ++p) {
            kernel::Rgba colour{0.0f, 0.0f, 0.0f, 0.0f};
            batch_pixel(batch, reinterpret_cast<const float*>(left), reinterpret_cast<const float*>(right), p,
                        colour);
            if (a.out_kind != OutKind::Displacement) finish(p, colour, weight_sum);
        }
    } else {
        std::uint32_t mask = cell_sources(a, tx, ty);
        kernel::Rgba colour[4];
#pragma unroll
        for (int p = 0; p < 4; ++p) colour[p] = {0.0f, 0.0f, 0.0f, 0.0f};
        float weight_sum = 0.0f;
        kernel::Batch<K> batch;
        while (kernel::take_batch(mask, batch)) {
            // The cell's two columns interpolated to this row, for the batch.
            float left[kernel::sum_floats(K)], right[kernel::sum_floats(K)];
            if (!crowded) {
                kernel::cell_row_end(c00, c01, fy, batch, left);
                kernel::cell_row_end(c10, c11, fy, batch, right);
            }
            weight_sum += batch_weight(a, batch);
#pragma unroll
            for (int p = 0; p < 4; ++p) batch_pixel(batch, left, right, p, colour[p]);
        }
        if (a.out_kind == OutKind::Displacement) return;
#pragma unroll
        for (int p = 0; p < 4; ++p) finish(p, colour[p], weight_sum);
    }
    if (vector_store && a.out_kind != OutKind::Displacement) {
        unsigned char* row = a.out + static_cast<std::size_t>(y) * a.out_pitch;
        reinterpret_cast<uint4*>(row)[x0 / 4] = make_uint4(packed[0], packed[1], packed[2], packed[3]);
    }
}

// ---- run-time choices -> templates -----------------------------------------

// fn(K, L) with the frame's source count and weight law as compile-time
// constants (std::integral_constant).
template <class Fn>
void with_sources_and_law(const FramePlan& plan, Fn&& fn) {
    kernel::with_sources(plan.batch, [&](auto k) {
        if (plan.law == Law::InverseSquare)
            fn(k, std::integral_constant<Law, Law::InverseSquare>{});
        else
            fn(k, std::integral_constant<Law, Law::Power>{});
    });
}

template <int N>
using Int = std::integral_constant<int, N>;

// The frame's sources are one batch evaluated everywhere (warp_kernel,
// apply_kernel: One).
bool one_batch(const FramePlan& plan, int width, int height) {
    if (plan.sources > kernel::kMaxBatch) return false;
    for (int i = 0; i < plan.sources; ++i) {
        const kernel::Bound& b = plan.bound[i];
        if (b.x0 > 0 || b.y0 > 0 || b.x1 < width || b.y1 < height) return false;
    }
    return true;
}

// fn(std::bool_constant<one>{}).
template <class Fn>
void with_one(bool one, Fn&& fn) {
    if (one)
        fn(std::true_type{});
    else
        fn(std::false_type{});
}

// ---- the backend -------------------------------------------------------------

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

template <class T>
void device_free(T*& p) {
    if (p != nullptr) cudaFree(p);
    p = nullptr;
}

class CudaBackend final : public BackendImpl {
public:
    CudaBackend(int width, int height, PixelFormat format, const std::vector<KeyMap>& keys)
        : width_(width), height_(height), is_float_(format == PixelFormat::RgbaF32),
          pixel_bytes_(is_float_ ? 16 : 4) {
        try {
            setup(keys);
        } catch (...) {
            release();
            throw;
        }
    }
    ~CudaBackend() override { release(); }

    SetupTimes setup_times() const override { return times_; }
    void* stream() const override { return stream_; }
    void synchronize() override { EMOFACE_CUDA_CHECK(cudaStreamSynchronize(stream_)); }

    void run(const FramePlan& plan, const OutputTarget& target) override {
        EMOFACE_CUDA_CHECK(cudaSetDevice(device_));
        KernelArgs a{};
        a.n_lines = plan.lines;
        a.record_floats = plan.record_floats;
        a.extent = plan.extent;
        a.inv_extent = plan.inv_extent;
        a.b = plan.b;
        a.width = width_;
        a.height = height_;
        a.is_float = is_float_ ? 1 : 0;
        a.normal_map = plan.normal_map ? 1 : 0;
        a.sources = plan.sources;
        a.rest = plan.rest;
        float weight_total = 0.0f;
        for (int i = 0; i < plan.sources; ++i) weight_total += plan.weight[i];
        a.hw_filter = weight_total <= 1.0f + kernel::kConvexSlack ? 1 : 0;
        for (int i = 0; i < plan.sources; ++i) {
            const int k = plan.source_index[i];
            const Crop& c = crops_[k];
            a.key[i] = {keys_[k], key_pitch_[k], width_, height_, is_float_, c.x, c.y, c.w, c.h, plan.rest};
            a.tex[i] = textures_[k];
            a.weight[i] = plan.weight[i];
            a.bound[i] = plan.bound[i];
        }

        // The line table: by value when it fits, else uploaded to the device
        // table in by-value slices (upload_kernel).
        const std::size_t table_floats = static_cast<std::size_t>(plan.lines) * plan.record_floats;
        if (table_floats <= 4 * kParamTableFloat4) {
            std::memcpy(table_.rec, plan.records, table_floats * sizeof(float));
            a.lines = nullptr;
        } else {
            const std::size_t table4 = table_floats / 4;
            for (std::size_t at = 0; at < table4; at += kParamTableFloat4) {
                const int count = static_cast<int>(std::min<std::size_t>(kParamTableFloat4, table4 - at));
                std::memcpy(slice_.rec, plan.records + 4 * at, static_cast<std::size_t>(count) * sizeof(float4));
                upload_kernel<<<1, 256, 0, stream_>>>(slice_, lines_ + at, count);
                EMOFACE_CUDA_CHECK(cudaGetLastError());
            }
            a.lines = lines_;
        }

        // Where the pixels go.
        const bool positions = target.kind == OutputTarget::Kind::Positions;
        const bool to_host = target.kind == OutputTarget::Kind::Host;
        if (positions) {
            ensure(disp_, disp_bytes_, static_cast<std::size_t>(width_) * height_ * plan.sources * sizeof(float2));
            a.out_kind = OutKind::Displacement;
            a.disp = disp_;
        } else if (target.kind == OutputTarget::Kind::Surface) {
            a.out_kind = OutKind::Surface;
            a.surface = static_cast<cudaSurfaceObject_t>(target.surface);
        } else {
            a.out_kind = OutKind::Pixels;
            if (to_host) {
                ensure(out_, out_bytes_, static_cast<std::size_t>(width_) * height_ * pixel_bytes_);
                a.out = out_;
                a.out_pitch = static_cast<std::size_t>(width_) * pixel_bytes_;
            } else {
                a.out = static_cast<unsigned char*>(target.ptr);
                a.out_pitch = target.pitch;
            }
            a.out_vector = (reinterpret_cast<std::uintptr_t>(a.out) % 16 == 0 && a.out_pitch % 16 == 0) ? 1 : 0;
        }

        const dim3 warp_block(32, 4);
        if (plan.accuracy == Accuracy::Exact) {
            a.points_w = width_;
            a.points_h = height_;
            a.spacing = 1;
            launch_points(plan, a, warp_block);
        } else {
            const int cell = plan.fast_cell;
            a.cell = cell;
            a.inv_cell = 1.0f / static_cast<float>(cell);
            a.grid_w = (width_ - 1) / cell + 2;
            const int grid_h = (height_ - 1) / cell + 2;
            a.tiles_w = (width_ + cell - 1) / cell;
            a.tiles_h = (height_ + cell - 1) / cell;
            a.reach = kernel::cell_reach(plan.fast_reach, cell, plan.inv_extent);
            const std::size_t tiles = static_cast<std::size_t>(a.tiles_w) * a.tiles_h;
            ensure(grid_, grid_bytes_,
                   static_cast<std::size_t>(a.grid_w) * grid_h * sums_stride(plan.sources) * sizeof(float));
            ensure(near_count_, near_count_bytes_, tiles * sizeof(int));
            ensure(near_list_, near_list_bytes_, tiles * kernel::kMaxNear * sizeof(unsigned short));
            ensure(tile_sums_, tile_sums_bytes_, tiles * 4 * sums_stride(plan.sources) * sizeof(float));
            a.near_count = near_count_;
            a.near_list = near_list_;
            a.tile_sums = tile_sums_;
            KernelArgs g = a;
            g.points_w = a.grid_w;
            g.points_h = grid_h;
            g.spacing = cell;
            g.out_kind = OutKind::Sums;
            g.sums = grid_;
            launch_points(plan, g, warp_block);
            a.grid = grid_;
            const dim3 block(8, 32);  // a warp: 8 threads x 4 pixels wide, 4 rows
            const dim3 blocks((width_ + 4 * 8 - 1) / (4 * 8), (height_ + 31) / 32);
            with_sources_and_law(plan, [&](auto k, auto law) {
                constexpr int K = decltype(k)::value;
                constexpr Law L = decltype(law)::value;
                tile_kernel<K, L><<<static_cast<unsigned>((tiles + 127) / 128), 128, 0, stream_>>>(a, table_);
                EMOFACE_CUDA_CHECK(cudaGetLastError());
                bool textured = a.hw_filter != 0;
                for (int i = 0; i < plan.sources; ++i)
                    textured = textured && a.key[i].crop_w == width_ && a.key[i].crop_h == height_;
                with_one(textured && one_batch(plan, width_, height_), [&](auto one) {
                    apply_kernel<K, L, decltype(one)::value><<<blocks, block, 0, stream_>>>(a, table_);
                });
            });
            EMOFACE_CUDA_CHECK(cudaGetLastError());
        }

        if (to_host) {
            EMOFACE_CUDA_CHECK(cudaMemcpy2DAsync(target.ptr, target.pitch, out_,
                                                 static_cast<std::size_t>(width_) * pixel_bytes_,
                                                 static_cast<std::size_t>(width_) * pixel_bytes_, height_,
                                                 cudaMemcpyDeviceToHost, stream_));
            synchronize();
        } else if (positions) {
            auto* out = static_cast<float*>(target.ptr);
            const std::size_t floats = static_cast<std::size_t>(width_) * height_ * plan.sources * 2;
            EMOFACE_CUDA_CHECK(
                cudaMemcpyAsync(out, disp_, floats * sizeof(float), cudaMemcpyDeviceToHost, stream_));
            synchronize();
            for (int y = 0; y < height_; ++y)
                for (int x = 0; x < width_; ++x) {
                    float* p = out + (static_cast<std::size_t>(y) * width_ + x) * plan.sources * 2;
                    for (int k = 0; k < plan.sources; ++k) {
                        p[2 * k] += static_cast<float>(x) + 0.5f;
                        p[2 * k + 1] += static_cast<float>(y) + 0.5f;
                    }
                }
        }
    }

private:
    // Shared memory per block for staged lines (and split partial sums):
    // under the 48 KB default, and small enough for several blocks per SM.
    static constexpr std::size_t kSharedBytes = 40 * 1024;

    void launch_points(const FramePlan& plan, const KernelArgs& args, dim3 block) {
        // Several points a thread amortise the line loads (8 where the sums
        // of up to 3 sources leave registers to spare, else 4); on small
        // lattices that would leave the GPU too few threads, so take one
        // point a thread and split the lines of a row over block.y threads.
        KernelArgs a = args;
        const long long points = static_cast<long long>(a.points_w) * a.points_h;
        const bool few_sources = plan.batch <= 3;
        bool split = split_groups_ > 1 && points < (1 << 20);
        int px = split ? (few_sources ? 2 : 1) : (points >= (1 << 21) && few_sources ? 8 : 4);
        if (px_override_ > 0) {
            px = px_override_;
            if (px == 2 && !few_sources) px = 1;
            split = split && px <= 2;
        }
        if (split) block.y = split_groups_;
        a.line_split = split ? static_cast<int>(block.y) : 1;
        dim3 blocks((a.points_w + px * block.x - 1) / (px * block.x), (a.points_h + block.y - 1) / block.y);
        // Shared memory: staged lines, plus the partial sums when splitting;
        // within the 48 KB a block gets without opting in.
        const std::size_t reduce =
            split ? static_cast<std::size_t>(block.x) * block.y * px * kernel::sum_floats(plan.batch) * sizeof(float)
                  : 0;
        const std::size_t record_bytes = static_cast<std::size_t>(plan.record_floats) * sizeof(float);
        a.chunk_lines = static_cast<int>(std::max<std::size_t>(
            1, std::min<std::size_t>(plan.lines, (kSharedBytes - reduce) / record_bytes)));
        const std::size_t smem = a.chunk_lines * record_bytes + reduce;
        if (split) blocks.y = a.points_h;
        // 8 and 2 points a thread only for up to 3 sources (registers).
        const bool one = one_batch(plan, width_, height_);
        with_sources_and_law(plan, [&](auto k, auto law) {
            constexpr int K = decltype(k)::value;
            constexpr Law L = decltype(law)::value;
            auto launch = [&](auto points) {
                with_one(one, [&](auto o) {
                    warp_kernel<K, decltype(points)::value, L, decltype(o)::value>
                        <<<blocks, block, smem, stream_>>>(a, table_);
                });
            };
            if constexpr (K <= 3) {
                if (px == 8) return launch(Int<8>{});
                if (px == 2) return launch(Int<2>{});
            }
            px >= 4 ? launch(Int<4>{}) : launch(Int<1>{});
        });
        EMOFACE_CUDA_CHECK(cudaGetLastError());
    }

    template <class T>
    void ensure(T*& p, std::size_t& capacity, std::size_t bytes) {
        if (bytes <= capacity) return;
        EMOFACE_CUDA_CHECK(cudaStreamSynchronize(stream_));
        device_free(p);
        capacity = 0;
        EMOFACE_CUDA_CHECK(cudaMalloc(reinterpret_cast<void**>(&p), bytes));
        capacity = bytes;
    }

    void setup(const std::vector<KeyMap>& keys) {
        if (const char* v = std::getenv("EMOFACE_MORPH_SPLIT")) {
            const int g = std::atoi(v);
            if (g == 0 || g == 2 || g == 4 || g == 8) split_groups_ = g;
        }
        if (const char* px = std::getenv("EMOFACE_MORPH_PX")) {
            const int v = std::atoi(px);
            if (v == 1 || v == 2 || v == 4 || (v == 8 && keys.size() <= 3)) px_override_ = v;
        }
        EMOFACE_CUDA_CHECK(cudaGetDevice(&device_));
        EMOFACE_CUDA_CHECK(cudaFree(nullptr));  // context creation is not allocation
        auto t0 = Clock::now();
        EMOFACE_CUDA_CHECK(cudaStreamCreateWithFlags(&stream_, cudaStreamNonBlocking));
        const std::size_t row = static_cast<std::size_t>(width_) * pixel_bytes_;
        keys_.assign(keys.size(), nullptr);
        key_pitch_.assign(keys.size(), 0);
        textures_.assign(keys.size(), 0);
        for (std::size_t k = 0; k < keys.size(); ++k) {
            crops_.push_back(key_crop(keys[k].region, width_, height_));
            void* p = nullptr;
            EMOFACE_CUDA_CHECK(
                cudaMallocPitch(&p, &key_pitch_[k], static_cast<std::size_t>(crops_[k].w) * pixel_bytes_, crops_[k].h));
            keys_[k] = static_cast<unsigned char*>(p);
        }
        // The device line table, for tables that do not fit the parameter.
        const std::size_t table_floats =
            static_cast<std::size_t>(keys[0].layout.size()) * kernel::record_floats(static_cast<int>(keys.size()));
        if (table_floats > 4 * kParamTableFloat4)
            EMOFACE_CUDA_CHECK(cudaMalloc(reinterpret_cast<void**>(&lines_), table_floats * sizeof(float)));
        for (std::size_t k = 0; k < keys.size(); ++k) {
            cudaResourceDesc res{};
            res.resType = cudaResourceTypePitch2D;
            res.res.pitch2D.devPtr = keys_[k];
            res.res.pitch2D.desc =
                is_float_ ? cudaCreateChannelDesc<float4>() : cudaCreateChannelDesc<uchar4>();
            res.res.pitch2D.width = crops_[k].w;
            res.res.pitch2D.height = crops_[k].h;
            res.res.pitch2D.pitchInBytes = key_pitch_[k];
            cudaTextureDesc tex{};
            tex.addressMode[0] = cudaAddressModeClamp;
            tex.addressMode[1] = cudaAddressModeClamp;
            tex.filterMode = cudaFilterModeLinear;
            tex.readMode = is_float_ ? cudaReadModeElementType : cudaReadModeNormalizedFloat;
            tex.normalizedCoords = 0;
            EMOFACE_CUDA_CHECK(cudaCreateTextureObject(&textures_[k], &res, &tex, nullptr));
        }
        EMOFACE_CUDA_CHECK(cudaDeviceSynchronize());
        times_.allocate_ms = ms_since(t0);

        t0 = Clock::now();
        for (std::size_t k = 0; k < keys.size(); ++k) {
            const Crop& c = crops_[k];
            const auto* first = static_cast<const unsigned char*>(keys[k].pixels) +
                                (static_cast<std::size_t>(c.y) * width_ + c.x) * pixel_bytes_;
            EMOFACE_CUDA_CHECK(cudaMemcpy2DAsync(keys_[k], key_pitch_[k], first, row,
                                                 static_cast<std::size_t>(c.w) * pixel_bytes_, c.h,
                                                 cudaMemcpyHostToDevice, stream_));
        }
        EMOFACE_CUDA_CHECK(cudaStreamSynchronize(stream_));
        times_.upload_ms = ms_since(t0);
    }

    void release() noexcept {
        if (stream_ != nullptr) cudaStreamSynchronize(stream_);
        for (cudaTextureObject_t t : textures_)
            if (t != 0) cudaDestroyTextureObject(t);
        textures_.clear();
        for (unsigned char*& k : keys_) device_free(k);
        keys_.clear();
        device_free(lines_);
        device_free(grid_);
        device_free(near_count_);
        device_free(near_list_);
        device_free(tile_sums_);
        device_free(out_);
        device_free(disp_);
        if (stream_ != nullptr) cudaStreamDestroy(stream_);
        stream_ = nullptr;
    }

    int width_, height_;
    bool is_float_;
    std::size_t pixel_bytes_;
    int px_override_ = 0;       // EMOFACE_MORPH_PX=1|4|8, for the benchmark's sweeps
    int split_groups_ = 4;      // EMOFACE_MORPH_SPLIT=0|2|4|8: threads sharing a row's lines (benchmark)
    int device_ = 0;
    cudaStream_t stream_ = nullptr;
    std::vector<unsigned char*> keys_;  // crops_[k] of key k, key_pitch_[k] bytes a row
    std::vector<std::size_t> key_pitch_;
    std::vector<Crop> crops_;
    std::vector<cudaTextureObject_t> textures_;
    float4* lines_ = nullptr;
    float* grid_ = nullptr;
    std::size_t grid_bytes_ = 0;
    int* near_count_ = nullptr;
    std::size_t near_count_bytes_ = 0;
    unsigned short* near_list_ = nullptr;
    std::size_t near_list_bytes_ = 0;
    float* tile_sums_ = nullptr;
    std::size_t tile_sums_bytes_ = 0;
    unsigned char* out_ = nullptr;
    std::size_t out_bytes_ = 0;
    float2* disp_ = nullptr;
    std::size_t disp_bytes_ = 0;
    LineTable table_;  // host copies of by-value tables (8 KB each, not on the stack)
    LineTable slice_;
    SetupTimes times_;
};

}  // namespace

const CudaStatus& cuda_status() {
    static const CudaStatus status = [] {
        CudaStatus s;
        int count = 0;
        cudaError_t e = cudaGetDeviceCount(&count);
        if (e != cudaSuccess) {
            s.why = std::string("cudaGetDeviceCount: ") + cudaGetErrorString(e);
            cudaGetLastError();
            return s;
        }
        if (count == 0) {
            s.why = "no CUDA device found";
            return s;
        }
        s.gpu_found = true;
        int device = 0;
        cudaGetDevice(&device);
        cudaDeviceProp prop{};
        if ((e = cudaGetDeviceProperties(&prop, device)) != cudaSuccess) {
            s.why = std::string("cudaGetDeviceProperties: ") + cudaGetErrorString(e);
            return s;
        }
        s.description = std::string(prop.name) + " (sm_" + std::to_string(prop.major) + std::to_string(prop.minor) +
                        ", " + std::to_string(prop.multiProcessorCount) + " SMs)";
        // A device this binary has no code for (see CMAKE_CUDA_ARCHITECTURES).
        cudaFuncAttributes attr{};
        if ((e = cudaFuncGetAttributes(&attr, tile_kernel<1, Law::InverseSquare>)) != cudaSuccess) {
            s.why = s.description + " has no matching kernel image in this build (" + cudaGetErrorString(e) +
                    "); add its architecture to CMAKE_CUDA_ARCHITECTURES";
            cudaGetLastError();
            return s;
        }
        s.usable = true;
        return s;
    }();
    return status;
}

std::unique_ptr<BackendImpl> make_cuda_backend(int width, int height, PixelFormat format,
                                               const std::vector<KeyMap>& keys) {
    return std::make_unique<CudaBackend>(width, height, format, keys);
}

}  // namespace emoface::morph::detail
