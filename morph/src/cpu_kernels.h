#pragma once
// The CPU backend's row loops around the shared kernel body (kernel.h). This
// file is compiled twice (cpu_kernels_base.cpp, cpu_kernels_avx2.cpp) with
// different instruction sets; the backend picks one at run time.
#include <cstddef>
#include <cstdint>
#include <cstring>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "backend.h"
#include "emoface/morph/kernel.h"

namespace emoface::morph::detail {

// One frame's work for the row loops.
struct CpuJob {
    const FramePlan* plan = nullptr;
    int width = 0, height = 0;
    kernel::ImageView keys[kernel::kMaxKeys] = {};  // the plan's sources, by slot
    // Image output (Host) or positions output (pixel coordinates, floats).
    unsigned char* out = nullptr;
    std::size_t out_pitch = 0;
    float* positions = nullptr;
    bool is_float = false;
    // Fast mode: the sums of all lines (kernel::sum_floats(sources) floats, by
    // slot) at grid points (i·cell + 0.5, j·cell + 0.5), grid_w x grid_h of
    // them; a source's sums only where its bound needs them.
    float* grid = nullptr;
    int grid_w = 0, grid_h = 0;
};

struct CpuKernels {
    // Exact warp of rows [y0, y1).
    void (*exact_rows)(const CpuJob& job, int y0, int y1);
    // Fast mode, pass 1: grid rows [g0, g1) of sums.
    void (*grid_rows)(const CpuJob& job, int g0, int g1);
    // Fast mode, pass 2: cell rows [t0, t1) from the grid and the near lines.
    void (*apply_rows)(const CpuJob& job, int t0, int t1);
};

namespace cpu_base {
const CpuKernels& kernels();
}
namespace cpu_avx2 {
const CpuKernels& kernels();
}

}  // namespace emoface::morph::detail

#if defined(EMOFACE_CPU_KERNELS_IMPL)
// ---- the implementation, included once per instruction set -----------------
namespace emoface::morph::detail::EMOFACE_CPU_KERNELS_IMPL {

using kernel::Accum;
using kernel::Batch;
using kernel::Law;

// Points per run: enough to amortise reading a line record, small enough that
// the sums of 8 sources stay in L1 (17 x 64 floats).
constexpr int kRun = 64;

#if defined(__SSE2__)
// The per-pixel end on x86: the same bilinear sample and blend as
// kernel::blend_batch (same clamping, same lerp order, texels outside a
// key's crop read as its rest value), with the four channels of a texel in
// one SSE register instead of four scalars.
using Colour = __m128;
EMOFACE_INLINE __m128 texel_ps(const kernel::ImageView& img, int x, int y) {
    if (!kernel::in_crop(img, x, y)) return _mm_setr_ps(img.rest.r, img.rest.g, img.rest.b, img.rest.a);
    const unsigned char* row = img.base + static_cast<std::size_t>(y - img.crop_y) * img.pitch;
    x -= img.crop_x;
    if (img.is_float) return _mm_loadu_ps(reinterpret_cast<const float*>(row) + 4 * x);
    int bytes;
    std::memcpy(&bytes, row + 4 * x, 4);
    const __m128i zero = _mm_setzero_si128();
    const __m128i v = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(bytes), zero), zero);
    return _mm_cvtepi32_ps(v);
}

EMOFACE_INLINE __m128 sample_ps(const kernel::ImageView& img, float px, float py) {
    const float fx = kernel::clampf(px - 0.5f, 0.0f, static_cast<float>(img.width - 1));
    const float fy = kernel::clampf(py - 0.5f, 0.0f, static_cast<float>(img.height - 1));
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const int x1 = x0 + 1 < img.width ? x0 + 1 : x0;
    const int y1 = y0 + 1 < img.height ? y0 + 1 : y0;
    const __m128 tx = _mm_set1_ps(fx - static_cast<float>(x0)), ty = _mm_set1_ps(fy - static_cast<float>(y0));
    const __m128 a = texel_ps(img, x0, y0), b = texel_ps(img, x1, y0);
    const __m128 c = texel_ps(img, x0, y1), d = texel_ps(img, x1, y1);
    const __m128 top = _mm_add_ps(a, _mm_mul_ps(tx, _mm_sub_ps(b, a)));
    const __m128 bottom = _mm_add_ps(c, _mm_mul_ps(tx, _mm_sub_ps(d, c)));
    return _mm_add_ps(top, _mm_mul_ps(ty, _mm_sub_ps(bottom, top)));
}
EMOFACE_INLINE void clear(Colour& c) { c = _mm_setzero_ps(); }
EMOFACE_INLINE void add_sample(Colour& c, const kernel::ImageView& img, float w, float px, float py) {
    c = _mm_add_ps(c, _mm_mul_ps(_mm_set1_ps(w), sample_ps(img, px, py)));
}
EMOFACE_INLINE kernel::Rgba to_rgba(const Colour& c) {
    alignas(16) float v[4];
    _mm_store_ps(v, c);
    return {v[0], v[1], v[2], v[3]};
}
#else
using Colour = kernel::Rgba;
EMOFACE_INLINE void clear(Colour& c) { c = {0.0f, 0.0f, 0.0f, 0.0f}; }
EMOFACE_INLINE void add_sample(Colour& c, const kernel::ImageView& img, float w, float px, float py) {
    kernel::add_weighted(c, kernel::sample_bilinear(img, px, py), w);
}
EMOFACE_INLINE kernel::Rgba to_rgba(const Colour& c) { return c; }
#endif

EMOFACE_INLINE void store_pixel(const CpuJob& job, int x, int y, const kernel::Rgba& c) {
    unsigned char* row = job.out + static_cast<std::size_t>(y) * job.out_pitch;
    if (job.is_float) {
        float* p = reinterpret_cast<float*>(row) + 4 * x;
        p[0] = c.r;
        p[1] = c.g;
        p[2] = c.b;
        p[3] = c.a;
    } else {
        const std::uint32_t v = kernel::pack_rgba8(c);
        std::memcpy(row + 4 * x, &v, 4);
    }
}

// The colours of up to kRun points of one row, summed over the batches of
// the sources evaluated there (whose weights sum to weight_sum).
struct RunColours {
    Colour c[kRun];
    float weight_sum;
    void clear(int n) {
        for (int j = 0; j < n; ++j) EMOFACE_CPU_KERNELS_IMPL::clear(c[j]);
        weight_sum = 0.0f;
    }
};

// A batch's point results: positions, or the batch's sources sampled and
// added to the points' colours.
template <int K, int PX>
EMOFACE_INLINE void batch_points(const CpuJob& job, const Accum<K, PX>& acc, const Batch<K>& batch, int x0, int y,
                                 int n, RunColours& col) {
    const FramePlan& plan = *job.plan;
    for (int j = 0; j < n; ++j) {
        float dx[K], dy[K];
        kernel::displacement(acc, j, plan.extent, dx, dy);
        const float px = static_cast<float>(x0 + j) + 0.5f, py = static_cast<float>(y) + 0.5f;
        // (k runs to the compile-time K, so dx and dy stay in registers)
        if (job.positions != nullptr) {
            float* p = job.positions + (static_cast<std::size_t>(y) * job.width + x0 + j) * (2 * plan.sources);
            for (int k = 0; k < K; ++k) {
                if (k >= batch.n) break;
                p[2 * batch.slot[k]] = px + dx[k];
                p[2 * batch.slot[k] + 1] = py + dy[k];
            }
            continue;
        }
        for (int k = 0; k < K; ++k) {
            if (k >= batch.n) break;
            const int i = batch.slot[k];
            add_sample(col.c[j], job.keys[i], plan.weight[i], px + dx[k], py + dy[k]);
        }
    }
    if (job.positions == nullptr)
        for (int k = 0; k < batch.n; ++k) col.weight_sum += plan.weight[batch.slot[k]];
}

// The points' colours over rest, renormalised (normal maps) and stored.
EMOFACE_INLINE void finish_points(const CpuJob& job, const RunColours& col, int x0, int y, int n) {
    if (job.positions != nullptr) return;
    const FramePlan& plan = *job.plan;
    for (int j = 0; j < n; ++j)
        store_pixel(job, x0 + j, y,
                    kernel::finish_blend(to_rgba(col.c[j]), col.weight_sum, plan.rest, plan.normal_map, job.is_float));
}

// Sums all lines for kRun points spaced `spacing` pixels apart on pixel row
// coordinate `y_px` (a centre), starting at pixel coordinate x_px.
template <int K, Law L>
inline void sum_lines(const FramePlan& plan, float x_px, float y_px, float spacing, const Batch<K>& batch,
                      Accum<K, kRun>& acc) {
    acc.clear();
    const float x0 = x_px * plan.inv_extent, y = y_px * plan.inv_extent, step = spacing * plan.inv_extent;
    for (int l = 0; l < plan.lines; ++l)
        kernel::accumulate_line<K, kRun, L>(plan.records + static_cast<std::size_t>(l) * plan.record_floats, x0, y,
                                            step, plan.b, batch, acc);
}

template <int K, Law L>
void exact_rows_t(const CpuJob& job, int y0, int y1) {
    const FramePlan& plan = *job.plan;
    Accum<K, kRun> acc;
    RunColours col;
    Batch<K> batch;
    for (int y = y0; y < y1; ++y) {
        for (int x0 = 0; x0 < job.width; x0 += kRun) {
            const int n = job.width - x0 < kRun ? job.width - x0 : kRun;
            std::uint32_t mask = kernel::sources_meeting(plan.bound, plan.sources, x0, y, x0 + n, y + 1);
            col.clear(n);
            while (kernel::take_batch(mask, batch)) {
                sum_lines<K, L>(plan, static_cast<float>(x0) + 0.5f, static_cast<float>(y) + 0.5f, 1.0f, batch, acc);
                batch_points(job, acc, batch, x0, y, n, col);
            }
            finish_points(job, col, x0, y, n);
        }
    }
}

// Fast mode, pass 1: the sums of all lines at grid points (i·cell + 0.5,
// j·cell + 0.5), kernel::sum_floats(sources) floats each, for the sources
// whose bound meets a cell that reads the point.
template <int K, Law L>
void grid_rows_t(const CpuJob& job, int g0, int g1) {
    const FramePlan& plan = *job.plan;
    const int C = plan.fast_cell;
    const float cell = static_cast<float>(C);
    const int S = kernel::sum_floats(plan.sources);
    Accum<K, kRun> acc;
    Batch<K> batch;
    for (int gy = g0; gy < g1; ++gy) {
        for (int gx0 = 0; gx0 < job.grid_w; gx0 += kRun) {
            const int n = job.grid_w - gx0 < kRun ? job.grid_w - gx0 : kRun;
            // Grid point (gx, gy) is a corner of cells gx - 1 and gx, gy - 1 and gy.
            std::uint32_t mask =
                kernel::sources_meeting(plan.bound, plan.sources, (gx0 - 1) * C, (gy - 1) * C, (gx0 + n) * C, (gy + 1) * C);
            while (kernel::take_batch(mask, batch)) {
                sum_lines<K, L>(plan, static_cast<float>(gx0) * cell + 0.5f, static_cast<float>(gy) * cell + 0.5f,
                                cell, batch, acc);
                for (int j = 0; j < n; ++j)
                    kernel::store_frame_sums(acc, j, batch,
                                             job.grid + (static_cast<std::size_t>(gy) * job.grid_w + gx0 + j) * S);
            }
        }
    }
}

// Fast mode, pass 2, for cell rows [t0, t1): per cell, its near lines, the
// sources whose bound meets it and, per batch of them, their far corner
// sums; per run of R pixels of a cell row and batch, kernel::cell_run
// (kernel.h, "fast mode"). R = 8 (4 for 4-pixel cells) keeps the number of
// instantiations, and the build time, down.
template <int K, Law L, int R>
void fast_tiles_t(const CpuJob& job, int t0, int t1) {
    const FramePlan& plan = *job.plan;
    constexpr int kMaxS = kernel::sum_floats(kernel::kMaxKeys);
    const int S = kernel::sum_floats(plan.sources);
    const int C = plan.fast_cell;
    const float inv_c = 1.0f / static_cast<float>(C);
    const float inv = plan.inv_extent;
    const kernel::FastGrid grid{plan.records, plan.record_floats, plan.lines, job.grid, job.grid_w, S, C, inv_c, inv,
                                kernel::cell_reach(plan.fast_reach, C, inv), plan.b};
    const int tiles_w = (job.width + C - 1) / C;
    unsigned short list[kernel::kMaxNear];
    Accum<K, R> acc;
    RunColours col;
    Batch<K> batches[kernel::kMaxKeys + 1];  // (+1: the take that finds the mask empty)
    for (int ty = t0; ty < t1; ++ty) {
        for (int tx = 0; tx < tiles_w; ++tx) {
            std::uint32_t mask =
                kernel::sources_meeting(plan.bound, plan.sources, tx * C, ty * C, tx * C + C, ty * C + C);
            int n_batches = 0;
            while (kernel::take_batch(mask, batches[n_batches])) ++n_batches;
            const int count = n_batches > 0 ? kernel::cell_near_lines(grid, tx, ty, list) : 0;
            float corner[4][kMaxS];
            if (count <= kernel::kMaxNear)
                for (int b = 0; b < n_batches; ++b)
                    kernel::cell_corner_sums<K, L>(grid, list, count, tx, ty, batches[b], corner[0], kMaxS);
            for (int r = 0; r < C; ++r) {
                const int y = ty * C + r;
                if (y >= job.height) break;
                const float fy = static_cast<float>(r) * inv_c;
                for (int i0 = 0; i0 < C; i0 += R) {
                    const int x0 = tx * C + i0;
                    if (x0 >= job.width) break;
                    const int n = job.width - x0 < R ? job.width - x0 : R;
                    col.clear(n);
                    for (int b = 0; b < n_batches; ++b) {
                        float left[kernel::sum_floats(K)], right[kernel::sum_floats(K)];
                        if (count <= kernel::kMaxNear) {
                            kernel::cell_row_end(corner[0], corner[2], fy, batches[b], left);
                            kernel::cell_row_end(corner[1], corner[3], fy, batches[b], right);
                        }
                        kernel::cell_run<K, R, L>(grid, list, count, left, right, i0,
                                                  (static_cast<float>(x0) + 0.5f) * inv,
                                                  (static_cast<float>(y) + 0.5f) * inv, batches[b], acc);
                        batch_points(job, acc, batches[b], x0, y, n, col);
                    }
                    finish_points(job, col, x0, y, n);
                }
            }
        }
    }
}

template <int K, Law L>
void apply_rows_t(const CpuJob& job, int t0, int t1) {
    if (job.plan->fast_cell == 4)
        fast_tiles_t<K, L, 4>(job, t0, t1);
    else
        fast_tiles_t<K, L, 8>(job, t0, t1);
}

// The weight law is chosen per line (Law::Runtime): one instantiation per
// batch width.
inline void exact_rows(const CpuJob& job, int y0, int y1) {
    kernel::with_sources(job.plan->batch, [&](auto k) { exact_rows_t<decltype(k)::value, Law::Runtime>(job, y0, y1); });
}
inline void grid_rows(const CpuJob& job, int g0, int g1) {
    kernel::with_sources(job.plan->batch, [&](auto k) { grid_rows_t<decltype(k)::value, Law::Runtime>(job, g0, g1); });
}
inline void apply_rows(const CpuJob& job, int t0, int t1) {
    kernel::with_sources(job.plan->batch, [&](auto k) { apply_rows_t<decltype(k)::value, Law::Runtime>(job, t0, t1); });
}

const CpuKernels& kernels() {
    static const CpuKernels table{&exact_rows, &grid_rows, &apply_rows};
    return table;
}

}  // namespace emoface::morph::detail::EMOFACE_CPU_KERNELS_IMPL
#endif
