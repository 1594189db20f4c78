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
    kernel::ImageView keys[kernel::kMaxKeys] = {};  // the plan's sources, in order
    // Image output (Host) or positions output (pixel coordinates, floats).
    unsigned char* out = nullptr;
    std::size_t out_pitch = 0;
    float* positions = nullptr;
    // Fast mode: the sums of all lines (kernel::sum_floats(sources) floats) at
    // grid points (i·cell + 0.5, j·cell + 0.5), grid_w x grid_h of them.
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
using kernel::Law;

// Points per run: enough to amortise reading a line record, small enough that
// the sums of 8 sources stay in L1 (17 x 64 floats).
constexpr int kRun = 64;

#if defined(__SSE2__)
// The per-pixel end on x86: the same bilinear sample and blend as
// kernel::blend_sources (same clamping, same lerp order), with the four
// channels of a texel in one SSE register instead of four scalars.
EMOFACE_INLINE __m128 texel_ps(const kernel::ImageView& img, const unsigned char* row, int x) {
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
    const unsigned char* r0 = img.base + static_cast<std::size_t>(y0) * img.pitch;
    const unsigned char* r1 = img.base + static_cast<std::size_t>(y1) * img.pitch;
    const __m128 a = texel_ps(img, r0, x0), b = texel_ps(img, r0, x1);
    const __m128 c = texel_ps(img, r1, x0), d = texel_ps(img, r1, x1);
    const __m128 top = _mm_add_ps(a, _mm_mul_ps(tx, _mm_sub_ps(b, a)));
    const __m128 bottom = _mm_add_ps(c, _mm_mul_ps(tx, _mm_sub_ps(d, c)));
    return _mm_add_ps(top, _mm_mul_ps(ty, _mm_sub_ps(bottom, top)));
}
#endif

EMOFACE_INLINE void store_pixel(const CpuJob& job, int x, int y, const kernel::Rgba& c) {
    unsigned char* row = job.out + static_cast<std::size_t>(y) * job.out_pitch;
    if (job.keys[0].is_float) {
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

// Writes point results: positions, or the sampled and blended pixel.
template <int K>
EMOFACE_INLINE void finish_point(const CpuJob& job, int x, int y, const float (&dx)[K], const float (&dy)[K]) {
    const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
    if (job.positions != nullptr) {
        float* p = job.positions + (static_cast<std::size_t>(y) * job.width + x) * (2 * K);
        for (int k = 0; k < K; ++k) {
            p[2 * k] = px + dx[k];
            p[2 * k + 1] = py + dy[k];
        }
        return;
    }
#if defined(__SSE2__)
    __m128 sum = _mm_setzero_ps();
    for (int k = 0; k < K; ++k)
        sum = _mm_add_ps(sum, _mm_mul_ps(_mm_set1_ps(job.plan->weight[k]),
                                         sample_ps(job.keys[k], px + dx[k], py + dy[k])));
    alignas(16) float c[4];
    _mm_store_ps(c, sum);
    kernel::Rgba rgba{c[0], c[1], c[2], c[3]};
    if (job.plan->normal_map) rgba = kernel::renormalise(rgba, job.keys[0].is_float ? 1.0f : 255.0f);
    store_pixel(job, x, y, rgba);
#else
    store_pixel(job, x, y,
                kernel::blend_sources<K>(job.keys, job.plan->weight, px, py, dx, dy, job.plan->normal_map));
#endif
}

// Points x0 .. of row y (PX of them, fewer at the row's end) from their sums.
template <int K, int PX>
EMOFACE_INLINE void finish_run(const CpuJob& job, const Accum<K, PX>& acc, int x0, int y) {
    const int n = job.width - x0 < PX ? job.width - x0 : PX;
    for (int j = 0; j < n; ++j) {
        float dx[K], dy[K];
        kernel::displacement(acc, j, job.plan->extent, dx, dy);
        finish_point<K>(job, x0 + j, y, dx, dy);
    }
}

// Sums all lines for kRun points spaced `spacing` pixels apart on pixel row
// coordinate `y_px` (a centre), starting at pixel coordinate x_px.
template <int K, Law L>
inline void sum_lines(const FramePlan& plan, float x_px, float y_px, float spacing, Accum<K, kRun>& acc) {
    acc.clear();
    const float x0 = x_px * plan.inv_extent, y = y_px * plan.inv_extent, step = spacing * plan.inv_extent;
    for (int l = 0; l < plan.lines; ++l)
        kernel::accumulate_line<K, kRun, L>(plan.records + static_cast<std::size_t>(l) * plan.record_floats, x0, y,
                                            step, plan.b, acc);
}

template <int K, Law L>
void exact_rows_t(const CpuJob& job, int y0, int y1) {
    const FramePlan& plan = *job.plan;
    Accum<K, kRun> acc;
    for (int y = y0; y < y1; ++y) {
        for (int x0 = 0; x0 < job.width; x0 += kRun) {
            sum_lines<K, L>(plan, static_cast<float>(x0) + 0.5f, static_cast<float>(y) + 0.5f, 1.0f, acc);
            finish_run(job, acc, x0, y);
        }
    }
}

// Fast mode, pass 1: the sums of all lines at grid points (i·cell + 0.5,
// j·cell + 0.5), kernel::sum_floats(K) floats each.
template <int K, Law L>
void grid_rows_t(const CpuJob& job, int g0, int g1) {
    const FramePlan& plan = *job.plan;
    const float cell = static_cast<float>(plan.fast_cell);
    constexpr int S = kernel::sum_floats(K);
    Accum<K, kRun> acc;
    for (int gy = g0; gy < g1; ++gy) {
        for (int gx0 = 0; gx0 < job.grid_w; gx0 += kRun) {
            sum_lines<K, L>(plan, static_cast<float>(gx0) * cell + 0.5f, static_cast<float>(gy) * cell + 0.5f, cell,
                            acc);
            const int n = job.grid_w - gx0 < kRun ? job.grid_w - gx0 : kRun;
            for (int j = 0; j < n; ++j)
                kernel::store_sums(acc, j, job.grid + (static_cast<std::size_t>(gy) * job.grid_w + gx0 + j) * S);
        }
    }
}

// Fast mode, pass 2, for cell rows [t0, t1): per cell, its near lines and
// far corner sums; per run of R pixels of a cell row, kernel::cell_run
// (kernel.h, "fast mode"). R = 8 (4 for 4-pixel cells) keeps the number of
// instantiations, and the build time, down.
template <int K, Law L, int R>
void fast_tiles_t(const CpuJob& job, int t0, int t1) {
    const FramePlan& plan = *job.plan;
    constexpr int S = kernel::sum_floats(K);
    const int C = plan.fast_cell;
    const float inv_c = 1.0f / static_cast<float>(C);
    const float inv = plan.inv_extent;
    const kernel::FastGrid grid{plan.records, plan.record_floats, plan.lines, job.grid, job.grid_w, S, C, inv_c, inv,
                                kernel::cell_reach(plan.fast_reach, C, inv), plan.b};
    const int tiles_w = (job.width + C - 1) / C;
    unsigned short list[kernel::kMaxNear];
    Accum<K, R> acc;
    for (int ty = t0; ty < t1; ++ty) {
        for (int tx = 0; tx < tiles_w; ++tx) {
            const int count = kernel::cell_near_lines(grid, tx, ty, list);
            float corner[4][S];
            if (count <= kernel::kMaxNear) kernel::cell_corner_sums<K, L>(grid, list, count, tx, ty, corner[0], S);
            for (int r = 0; r < C; ++r) {
                const int y = ty * C + r;
                if (y >= job.height) break;
                const float fy = static_cast<float>(r) * inv_c;
                float left[S], right[S];
                if (count <= kernel::kMaxNear) {
                    for (int q = 0; q < S; ++q) {
                        left[q] = corner[0][q] + fy * (corner[2][q] - corner[0][q]);
                        right[q] = corner[1][q] + fy * (corner[3][q] - corner[1][q]);
                    }
                }
                for (int i0 = 0; i0 < C; i0 += R) {
                    const int x0 = tx * C + i0;
                    if (x0 >= job.width) break;
                    kernel::cell_run<K, R, L>(grid, list, count, left, right, i0, (static_cast<float>(x0) + 0.5f) * inv,
                                              (static_cast<float>(y) + 0.5f) * inv, acc);
                    finish_run(job, acc, x0, y);
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
// source count.
inline void exact_rows(const CpuJob& job, int y0, int y1) {
    kernel::with_sources(job.plan->sources, [&](auto k) { exact_rows_t<decltype(k)::value, Law::Runtime>(job, y0, y1); });
}
inline void grid_rows(const CpuJob& job, int g0, int g1) {
    kernel::with_sources(job.plan->sources, [&](auto k) { grid_rows_t<decltype(k)::value, Law::Runtime>(job, g0, g1); });
}
inline void apply_rows(const CpuJob& job, int t0, int t1) {
    kernel::with_sources(job.plan->sources, [&](auto k) { apply_rows_t<decltype(k)::value, Law::Runtime>(job, t0, t1); });
}

const CpuKernels& kernels() {
    static const CpuKernels table{&exact_rows, &grid_rows, &apply_rows};
    return table;
}

}  // namespace emoface::morph::detail::EMOFACE_CPU_KERNELS_IMPL
#endif
