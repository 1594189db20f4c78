#pragma once
// The CPU backend's row loops around the shared kernel body (kernel.h). This
// file is compiled twice (cpu_kernels_base.cpp, cpu_kernels_avx2.cpp) with
// different instruction sets; the backend picks one at run time.
#include <cstddef>
#include <cstdint>
#include <cstring>

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
    // Fast mode: displacements (pixels) at grid points (i·cell + 0.5, j·cell + 0.5),
    // grid_w x grid_h points, plan->sources float pairs each.
    float* grid = nullptr;
    int grid_w = 0, grid_h = 0;
};

struct CpuKernels {
    const char* name;
    // Exact warp of rows [y0, y1).
    void (*exact_rows)(const CpuJob& job, int y0, int y1);
    // Fast mode, pass 1: grid rows [g0, g1).
    void (*grid_rows)(const CpuJob& job, int g0, int g1);
    // Fast mode, pass 2: rows [y0, y1) from the grid.
    void (*apply_rows)(const CpuJob& job, int y0, int y1);
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

inline void store_pixel(const CpuJob& job, int x, int y, const kernel::Rgba& c) {
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
inline void finish_point(const CpuJob& job, int x, int y, const float (&dx)[K], const float (&dy)[K]) {
    const float px = static_cast<float>(x) + 0.5f, py = static_cast<float>(y) + 0.5f;
    if (job.positions != nullptr) {
        float* p = job.positions + (static_cast<std::size_t>(y) * job.width + x) * (2 * K);
        for (int k = 0; k < K; ++k) {
            p[2 * k] = px + dx[k];
            p[2 * k + 1] = py + dy[k];
        }
        return;
    }
    store_pixel(job, x, y,
                kernel::blend_sources<K>(job.keys, job.plan->weight, px, py, dx, dy, job.plan->normal_map));
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
            const int n = job.width - x0 < kRun ? job.width - x0 : kRun;
            for (int j = 0; j < n; ++j) {
                float dx[K], dy[K];
                kernel::displacement(acc, j, plan.extent, dx, dy);
                finish_point<K>(job, x0 + j, y, dx, dy);
            }
        }
    }
}

template <int K, Law L>
void grid_rows_t(const CpuJob& job, int g0, int g1) {
    const FramePlan& plan = *job.plan;
    const float cell = static_cast<float>(plan.fast_cell);
    Accum<K, kRun> acc;
    for (int gy = g0; gy < g1; ++gy) {
        for (int gx0 = 0; gx0 < job.grid_w; gx0 += kRun) {
            sum_lines<K, L>(plan, static_cast<float>(gx0) * cell + 0.5f, static_cast<float>(gy) * cell + 0.5f, cell,
                            acc);
            const int n = job.grid_w - gx0 < kRun ? job.grid_w - gx0 : kRun;
            for (int j = 0; j < n; ++j) {
                float dx[K], dy[K];
                kernel::displacement(acc, j, plan.extent, dx, dy);
                float* g = job.grid + (static_cast<std::size_t>(gy) * job.grid_w + gx0 + j) * (2 * K);
                for (int k = 0; k < K; ++k) {
                    g[2 * k] = dx[k];
                    g[2 * k + 1] = dy[k];
                }
            }
        }
    }
}

// Pass 2: bilinear interpolation of the grid. A run of `cell` pixels shares
// one grid cell: interpolate its two columns in y once, then along x.
template <int K>
void apply_rows_t(const CpuJob& job, int y0, int y1) {
    const int cell = job.plan->fast_cell;
    const float inv_cell = 1.0f / static_cast<float>(cell);
    for (int y = y0; y < y1; ++y) {
        const int gy = y / cell;
        const float fy = static_cast<float>(y - gy * cell) * inv_cell;
        const float* top = job.grid + static_cast<std::size_t>(gy) * job.grid_w * (2 * K);
        const float* bottom = top + static_cast<std::size_t>(job.grid_w) * (2 * K);
        for (int x0 = 0; x0 < job.width; x0 += cell) {
            const int gx = x0 / cell;
            float left[2 * K], right[2 * K];
            for (int c = 0; c < 2 * K; ++c) {
                const float* t = top + gx * (2 * K) + c;
                const float* b = bottom + gx * (2 * K) + c;
                left[c] = t[0] + fy * (b[0] - t[0]);
                right[c] = t[2 * K] + fy * (b[2 * K] - t[2 * K]);
            }
            const int n = job.width - x0 < cell ? job.width - x0 : cell;
            for (int j = 0; j < n; ++j) {
                const float fx = static_cast<float>(j) * inv_cell;
                float dx[K], dy[K];
                for (int k = 0; k < K; ++k) {
                    dx[k] = left[2 * k] + fx * (right[2 * k] - left[2 * k]);
                    dy[k] = left[2 * k + 1] + fx * (right[2 * k + 1] - left[2 * k + 1]);
                }
                finish_point<K>(job, x0 + j, y, dx, dy);
            }
        }
    }
}

// Run-time source count and weight law -> template.
#define EMOFACE_CPU_DISPATCH_KL(fn, plan, ...)                                           \
    do {                                                                                 \
        const bool sq = (plan).law == Law::InverseSquare;                                \
        switch ((plan).sources) {                                                        \
            case 1: sq ? fn<1, Law::InverseSquare>(__VA_ARGS__) : fn<1, Law::Power>(__VA_ARGS__); break; \
            case 2: sq ? fn<2, Law::InverseSquare>(__VA_ARGS__) : fn<2, Law::Power>(__VA_ARGS__); break; \
            case 3: sq ? fn<3, Law::InverseSquare>(__VA_ARGS__) : fn<3, Law::Power>(__VA_ARGS__); break; \
            case 4: sq ? fn<4, Law::InverseSquare>(__VA_ARGS__) : fn<4, Law::Power>(__VA_ARGS__); break; \
            case 5: sq ? fn<5, Law::InverseSquare>(__VA_ARGS__) : fn<5, Law::Power>(__VA_ARGS__); break; \
            case 6: sq ? fn<6, Law::InverseSquare>(__VA_ARGS__) : fn<6, Law::Power>(__VA_ARGS__); break; \
            case 7: sq ? fn<7, Law::InverseSquare>(__VA_ARGS__) : fn<7, Law::Power>(__VA_ARGS__); break; \
            default: sq ? fn<8, Law::InverseSquare>(__VA_ARGS__) : fn<8, Law::Power>(__VA_ARGS__); break; \
        }                                                                                \
    } while (0)

#define EMOFACE_CPU_DISPATCH_K(fn, plan, ...)      \
    do {                                           \
        switch ((plan).sources) {                  \
            case 1: fn<1>(__VA_ARGS__); break;     \
            case 2: fn<2>(__VA_ARGS__); break;     \
            case 3: fn<3>(__VA_ARGS__); break;     \
            case 4: fn<4>(__VA_ARGS__); break;     \
            case 5: fn<5>(__VA_ARGS__); break;     \
            case 6: fn<6>(__VA_ARGS__); break;     \
            case 7: fn<7>(__VA_ARGS__); break;     \
            default: fn<8>(__VA_ARGS__); break;    \
        }                                          \
    } while (0)

inline void exact_rows(const CpuJob& job, int y0, int y1) {
    EMOFACE_CPU_DISPATCH_KL(exact_rows_t, *job.plan, job, y0, y1);
}
inline void grid_rows(const CpuJob& job, int g0, int g1) {
    EMOFACE_CPU_DISPATCH_KL(grid_rows_t, *job.plan, job, g0, g1);
}
inline void apply_rows(const CpuJob& job, int y0, int y1) {
    EMOFACE_CPU_DISPATCH_K(apply_rows_t, *job.plan, job, y0, y1);
}

const CpuKernels& kernels() {
    static const CpuKernels table{EMOFACE_CPU_KERNELS_NAME, &exact_rows, &grid_rows, &apply_rows};
    return table;
}

}  // namespace emoface::morph::detail::EMOFACE_CPU_KERNELS_IMPL
#endif
