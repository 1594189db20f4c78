#pragma once
// The Beier-Neely warp-and-blend kernel body, written once for both backends
// (DESIGN.md "CPU and GPU"): the CPU backend calls these functions from its
// thread pool over runs of 64 pixels, the CUDA backend from one thread per
// 1, 2, 4 or 8 pixels. Nothing here allocates, throws or touches a backend API.
//
// Geometry (DESIGN.md "Beier-Neely warp", thesis 3.2.2 c). Positions are in
// "iso" units: pixel coordinates divided by S = max(W, H), so distances mean the
// same along x and y and MorphParams::a is a fraction of the longer side.
// For a target line (P, Q) with d = Q - P, len = |d|, unit e = d/len,
// unit normal n = perp(d)/len (perp(x, y) = (-y, x), the thesis's convention)
// and midpoint M, a point X has
//   s = (X - M)·e        (along the line, from its midpoint; u = s/len + 1/2)
//   v = (X - P)·n        (signed distance across it)
//   dist = |v| beside the segment, distance to the nearer end beyond it
//        = sqrt(v² + max(|s| - len/2, 0)²)
//   w = (len^p / (a + dist))^b = ((a + dist)·len^-p)^-b
// and in source k, X'_k = P'_k + u d'_k + v n'_k, i.e. a displacement
//   D_k = X'_k - X = (M'_k - M) + s (d'_k - d)/len + v (n'_k - n)
// which is affine in (s, v): the host precomputes A = M' - M, B = (d' - d)/len,
// C = n' - n per line and source, so the kernel does u, v, dist and w once per
// pixel-line and then 6 multiply-adds per source. Writing D relative to X keeps
// float precision where the displacement is small (identity maps give D = 0
// exactly). The pixel's source position is X + Σ w_i D_i / Σ w_i.
//
// Batches. A frame has up to kMaxKeys sources (keys at weight > 0), each with
// its 6 floats in every line record and a bound: the target pixels where its
// region can land. A backend takes a block of pixels (a CPU run, a GPU
// thread block, a fast-mode cell), lists the sources whose bound meets it
// (sources_meeting), and runs the line loop once per batch of at most
// kMaxBatch of them (take_batch), whose sums a compile-time K holds in
// registers. The colours of the batches add up per pixel; finish_blend adds
// the rest value's share, (1 − Σ w of the sources evaluated) · rest.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <type_traits>

#include "emoface/common/hd.h"
#include "emoface/morph/limits.h"

// EMOFACE_UNROLL: loops over a batch's sources (at most kMaxBatch) and other short
// compile-time loops, unrolled on both sides. EMOFACE_PIXEL_LOOP: the loop over
// a run of points, unrolled into registers on the GPU (1 to 8 points) and
// vectorised on the CPU (64 points; the accumulators are a local that nothing
// else can alias).
#if defined(__CUDACC__)
#define EMOFACE_UNROLL _Pragma("unroll")
#define EMOFACE_PIXEL_LOOP _Pragma("unroll")
#elif defined(__GNUC__) && !defined(__clang__)
#define EMOFACE_UNROLL _Pragma("GCC unroll 8")
#define EMOFACE_PIXEL_LOOP _Pragma("GCC ivdep")
#else
#define EMOFACE_UNROLL
#define EMOFACE_PIXEL_LOOP
#endif

namespace emoface::morph::kernel {

using morph::kMaxKeys;
// Sources whose sums one pass of the line loop keeps (the compile-time K).
inline constexpr int kMaxBatch = 8;
static_assert(kMaxKeys <= 32, "source masks are 32-bit");

// One line record (floats): the target line's geometry, then 6 floats for each
// source taking part in the frame; padded to whole float4s so the GPU loads a
// record with 16-byte loads.
enum LineField : int {
    kEx, kEy, kCs,     // s = X·e + cs
    kHalfLen,          // len / 2
    kNx, kNy, kCv,     // v = X·n + cv
    kWk, kWa,          // a + dist scaled by len^-p: q = dist·wk + wa, w = q^-b
    kGeomFloats
};
inline constexpr int kSourceFloats = 6;  // Ax Ay Bx By Cx Cy
EMOFACE_HD constexpr int record_floats(int sources) {
    return (kGeomFloats + kSourceFloats * sources + 3) / 4 * 4;
}

// b = 2 (the default) needs one reciprocal; any other b goes through exp2/log2.
// Runtime picks one of the two per line (per run of points): the CPU uses it,
// so its row loops are compiled once instead of once per law.
enum class Law : int { InverseSquare, Power, Runtime };

struct Rgba {
    float r, g, b, a;
};

// Target pixels [x0, x1) x [y0, y1) where a source is evaluated.
struct Bound {
    int x0, y0, x1, y1;
};

// Bit i set: source i's bound meets pixels [x0, x1) x [y0, y1).
EMOFACE_HD EMOFACE_INLINE std::uint32_t sources_meeting(const Bound* bounds, int sources, int x0, int y0, int x1,
                                                        int y1) {
    std::uint32_t mask = 0;
    for (int i = 0; i < sources; ++i) {
        const Bound& b = bounds[i];
        if (b.x0 < x1 && x0 < b.x1 && b.y0 < y1 && y0 < b.y1) mask |= 1u << i;
    }
    return mask;
}

// Up to K sources of a frame, by their index in the line records (slot);
// slots past n repeat slot 0 so that every read stays in the record.
template <int K>
struct Batch {
    int n;
    int slot[K];
};

EMOFACE_HD EMOFACE_INLINE int lowest_bit(std::uint32_t mask) {
#if defined(__CUDA_ARCH__)
    return __ffs(static_cast<int>(mask)) - 1;
#else
    return __builtin_ctz(mask);
#endif
}

// Moves the lowest (up to) K sources of `mask` into `batch`; false when the
// mask is empty.
template <int K>
EMOFACE_HD EMOFACE_INLINE bool take_batch(std::uint32_t& mask, Batch<K>& batch) {
    batch.n = 0;
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        if (mask != 0) {
            batch.slot[k] = lowest_bit(mask);
            mask &= mask - 1;
            ++batch.n;
        } else {
            batch.slot[k] = batch.n > 0 ? batch.slot[0] : 0;
        }
    }
    return batch.n > 0;
}

// Sources 0..K-1 as one batch: a frame of K <= kMaxBatch sources evaluated
// everywhere (no regions) needs no other. Its slots are compile-time
// constants once inlined, so the GPU reads a record's sources at fixed
// offsets.
template <int K>
EMOFACE_HD EMOFACE_INLINE Batch<K> all_sources() {
    Batch<K> batch;
    batch.n = K;
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) batch.slot[k] = k;
    return batch;
}

// A frame's batch width (min(sources, kMaxBatch), known at run time) as a
// compile-time K: calls fn(std::integral_constant<int, K>{}), so the sums of
// each source of a batch live in registers. The one place a backend turns
// the count into a kernel instantiation (host code).
template <int K = 1, class Fn>
void with_sources(int sources, Fn&& fn) {
    if constexpr (K < kMaxBatch) {
        if (sources > K) {
            with_sources<K + 1>(sources, fn);
            return;
        }
    }
    fn(std::integral_constant<int, K>{});
}

// ---- fast math shared by both sides ---------------------------------------

// EMOFACE_DEVICE_OR_HOST(d, h): expression d in GPU code, h everywhere else,
// for the few operations the two sides spell differently.
#if defined(__CUDA_ARCH__)
#define EMOFACE_DEVICE_OR_HOST(device, host) (device)
// PTX's approximate square root and reciprocal (what -use_fast_math would
// give, without fast math for the whole file).
__device__ EMOFACE_INLINE float ptx_sqrt_approx(float x) {
    float r;
    asm("sqrt.approx.ftz.f32 %0, %1;" : "=f"(r) : "f"(x));
    return r;
}
__device__ EMOFACE_INLINE float ptx_rcp_approx(float x) {
    float r;
    asm("rcp.approx.ftz.f32 %0, %1;" : "=f"(r) : "f"(x));
    return r;
}
#else
#define EMOFACE_DEVICE_OR_HOST(device, host) (host)
#endif

EMOFACE_HD EMOFACE_INLINE float fast_sqrt(float x) { return EMOFACE_DEVICE_OR_HOST(ptx_sqrt_approx(x), std::sqrt(x)); }
EMOFACE_HD EMOFACE_INLINE float fast_rcp(float x) { return EMOFACE_DEVICE_OR_HOST(ptx_rcp_approx(x), 1.0f / x); }
EMOFACE_HD EMOFACE_INLINE float pow_neg(float q, float b) {
    return EMOFACE_DEVICE_OR_HOST(exp2f(-b * __log2f(q)), std::exp2(-b * std::log2(q)));
}

// Branch-free helpers the CPU compiler turns into max/min/and instructions
// (std::fmax's NaN rules would stop it vectorising); fabs is a sign-bit
// mask on the CPU and a free operand modifier on the GPU.
EMOFACE_HD EMOFACE_INLINE float max0(float x) { return x > 0.0f ? x : 0.0f; }
EMOFACE_HD EMOFACE_INLINE float absf(float x) { return EMOFACE_DEVICE_OR_HOST(fabsf(x), std::fabs(x)); }
EMOFACE_HD EMOFACE_INLINE float clampf(float x, float lo, float hi) {
    // NaN compares false both ways and ends up at lo: never an out-of-range index.
    return x > lo ? (x < hi ? x : hi) : lo;
}

template <Law L>
EMOFACE_HD EMOFACE_INLINE float line_weight(float q, float b) {
    if constexpr (L == Law::InverseSquare) {
        const float r = fast_rcp(q);
        return r * r;
    } else {
        return pow_neg(q, b);
    }
}

// ---- per pixel-line accumulation ------------------------------------------

// Sums for PX points on one row: Σw and Σ w·D_k (iso units).
template <int K, int PX>
struct Accum {
    float w[PX];
    float dx[K][PX];
    float dy[K][PX];

    EMOFACE_HD EMOFACE_INLINE void clear() {
        EMOFACE_PIXEL_LOOP
        for (int j = 0; j < PX; ++j) w[j] = 0.0f;
        EMOFACE_UNROLL
        for (int k = 0; k < K; ++k) {
            EMOFACE_PIXEL_LOOP
            for (int j = 0; j < PX; ++j) {
                dx[k][j] = 0.0f;
                dy[k][j] = 0.0f;
            }
        }
    }
};

// Adds one line's contribution to PX points (x0 + j·step, y), j = 0..PX-1,
// in iso units, for the batch's sources (acc.dx[k] for source batch.slot[k]
// of the record). u, v and w are computed once per point and reused for
// every source.
template <int K, int PX, Law L>
EMOFACE_HD EMOFACE_INLINE void accumulate_line(const float* rec, float x0, float y, float step,
                                               float b, const Batch<K>& batch, Accum<K, PX>& acc) {
    const float ex = rec[kEx], ey = rec[kEy];
    const float nx = rec[kNx], ny = rec[kNy];
    const float half_len = rec[kHalfLen], wk = rec[kWk], wa = rec[kWa];
    const float s0 = x0 * ex + (y * ey + rec[kCs]);
    const float v0 = x0 * nx + (y * ny + rec[kCv]);
    const float s_step = step * ex;
    const float v_step = step * nx;
    const float* src = rec + kGeomFloats;
    // In phases over the run of points, so the two special-function steps
    // (square root, reciprocal) of different points overlap on the GPU; the
    // CPU vectorises each phase.
    float s[PX], v[PX], w[PX];
    EMOFACE_PIXEL_LOOP
    for (int j = 0; j < PX; ++j) {
        // (j == 0 spelled out: the GPU's unrolled first point then costs nothing)
        s[j] = j == 0 ? s0 : s0 + static_cast<float>(j) * s_step;
        v[j] = j == 0 ? v0 : v0 + static_cast<float>(j) * v_step;
        const float beyond = max0(absf(s[j]) - half_len);
        w[j] = v[j] * v[j] + beyond * beyond;
    }
    EMOFACE_PIXEL_LOOP
    for (int j = 0; j < PX; ++j) w[j] = fast_sqrt(w[j]) * wk + wa;
    if constexpr (L == Law::Runtime) {
        if (b == 2.0f) {
            EMOFACE_PIXEL_LOOP
            for (int j = 0; j < PX; ++j) w[j] = line_weight<Law::InverseSquare>(w[j], b);
        } else {
            for (int j = 0; j < PX; ++j) w[j] = line_weight<Law::Power>(w[j], b);
        }
    } else {
        EMOFACE_PIXEL_LOOP
        for (int j = 0; j < PX; ++j) w[j] = line_weight<L>(w[j], b);
    }
    EMOFACE_PIXEL_LOOP
    for (int j = 0; j < PX; ++j) acc.w[j] += w[j];
    // (k < n is uniform over the points: a block's batch; a source's
    // coefficients are read once for all points)
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        if (k >= batch.n) break;
        const float* c = src + kSourceFloats * batch.slot[k];
        const float c0 = c[0], c1 = c[1], c2 = c[2], c3 = c[3], c4 = c[4], c5 = c[5];
        EMOFACE_PIXEL_LOOP
        for (int j = 0; j < PX; ++j) {
            acc.dx[k][j] += w[j] * (c0 + s[j] * c2 + v[j] * c4);
            acc.dy[k][j] += w[j] * (c1 + s[j] * c3 + v[j] * c5);
        }
    }
}

// Displacement of point j for source k, in pixels: Σ w D / Σ w scaled by S.
// With no lines (Σw = 0) the warp is the identity.
template <int K, int PX>
EMOFACE_HD EMOFACE_INLINE void displacement(const Accum<K, PX>& acc, int j, float extent,
                                            float (&dx)[K], float (&dy)[K]) {
    const float scale = acc.w[j] > 0.0f ? extent / acc.w[j] : 0.0f;
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        dx[k] = acc.dx[k][j] * scale;
        dy[k] = acc.dy[k][j] * scale;
    }
}

// ---- fast mode: far lines from a coarse grid, near lines exactly -------------
//
// The displacement is a ratio of sums, D = Σ w_i D_i / Σ w_i. A line's terms
// are smooth wherever the point is off its segment: the weight changes on the
// scale a + dist, and D_i is affine. Across the segment, dist = |v| has a
// kink. So for each grid cell (fast_cell pixels square) the lines that pass
// within `reach` of it ("near" lines) are evaluated exactly at each pixel,
// and the sums of all other lines are interpolated bilinearly from the grid
// (whose points hold the sums of all lines, less the near lines' terms at
// the cell's corners). The interpolation error of a far line's terms shrinks
// as (cell / reach)²; the kinks are never interpolated.

inline constexpr int kMaxNear = 16;  // more near lines: the cell is done exactly
EMOFACE_HD constexpr int sum_floats(int sources) { return 1 + 2 * sources; }

// The fast mode's grid and line table as both backends hold them: the sums
// of all lines (sum_floats(K) floats, `stride` apart) at grid points
// (i·cell + 0.5, j·cell + 0.5) pixels, grid_w of them a row.
struct FastGrid {
    const float* records;
    int record_floats;
    int lines;
    const float* sums;
    int grid_w;
    int stride;
    int cell;
    float inv_cell;  // 1 / cell, divided once by the backend
    float inv_extent;
    float reach;  // cell_reach()
    float b;
};

// How far from a cell's centre a line counts as near (iso units): fast_reach
// cells beyond the cell's half-diagonal.
EMOFACE_HD EMOFACE_INLINE float cell_reach(float fast_reach, int cell, float inv_extent) {
    return (fast_reach + 0.70711f) * static_cast<float>(cell) * inv_extent;
}

// Grid point g along x or y (iso units): the centre of pixel g·cell.
EMOFACE_HD EMOFACE_INLINE float grid_coord(int g, int cell, float inv_extent) {
    return (static_cast<float>(g * cell) + 0.5f) * inv_extent;
}

// Distance (iso units) from point (x, y) to a line's segment.
EMOFACE_HD EMOFACE_INLINE float segment_distance(const float* rec, float x, float y) {
    const float s = x * rec[kEx] + (y * rec[kEy] + rec[kCs]);
    const float v = x * rec[kNx] + (y * rec[kNy] + rec[kCv]);
    const float beyond = max0(absf(s) - rec[kHalfLen]);
    return fast_sqrt(v * v + beyond * beyond);
}

// The lines whose segment comes within g.reach of cell (tx, ty)'s centre.
// Writes at most kMaxNear indices to `list`; returns the full count (over
// kMaxNear: the cell is done exactly).
EMOFACE_HD EMOFACE_INLINE int cell_near_lines(const FastGrid& g, int tx, int ty, unsigned short* list) {
    const float half = 0.5f * static_cast<float>(g.cell);
    const float cx = (static_cast<float>(tx * g.cell) + 0.5f + half) * g.inv_extent;
    const float cy = (static_cast<float>(ty * g.cell) + 0.5f + half) * g.inv_extent;
    int count = 0;
    for (int i = 0; i < g.lines; ++i) {
        if (segment_distance(g.records + i * g.record_floats, cx, cy) < g.reach) {
            if (count < kMaxNear) list[count] = static_cast<unsigned short>(i);
            ++count;
        }
    }
    return count;
}

// Point j's sums: sums[0] = Σw, sums[1 + 2k] = Σ w Dx_k, sums[2 + 2k] = Σ w Dy_k
// (iso units). store_sums writes them (a partial sum: k the batch's own
// index), add_sums adds stored ones back; store_frame_sums writes a batch
// into the sums of all the frame's sources (a grid point: k the source's slot).
template <int K, int PX>
EMOFACE_HD EMOFACE_INLINE void store_sums(const Accum<K, PX>& acc, int j, float* sums) {
    sums[0] = acc.w[j];
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        sums[1 + 2 * k] = acc.dx[k][j];
        sums[2 + 2 * k] = acc.dy[k][j];
    }
}
template <int K, int PX>
EMOFACE_HD EMOFACE_INLINE void add_sums(const float* sums, int j, Accum<K, PX>& acc) {
    acc.w[j] += sums[0];
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        acc.dx[k][j] += sums[1 + 2 * k];
        acc.dy[k][j] += sums[2 + 2 * k];
    }
}
template <int K, int PX>
EMOFACE_HD EMOFACE_INLINE void store_frame_sums(const Accum<K, PX>& acc, int j, const Batch<K>& batch, float* sums) {
    sums[0] = acc.w[j];
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        if (k >= batch.n) break;
        sums[1 + 2 * batch.slot[k]] = acc.dx[k][j];
        sums[2 + 2 * batch.slot[k]] = acc.dy[k][j];
    }
}

// One cell before its pixels: the sums of the lines NOT in `list` (its far
// lines) at its four corners, grid points (tx + (c & 1), ty + (c >> 1)) for
// c = 0..3, for the batch's sources, to out + c·out_stride laid out like the
// grid (all the frame's sources, by slot).
template <int K, Law L>
EMOFACE_HD EMOFACE_INLINE void cell_corner_sums(const FastGrid& g, const unsigned short* list, int count, int tx,
                                                int ty, const Batch<K>& batch, float* out, int out_stride) {
    for (int c = 0; c < 4; ++c) {
        const int gx = tx + (c & 1), gy = ty + (c >> 1);
        const float* all = g.sums + (static_cast<std::size_t>(gy) * g.grid_w + gx) * g.stride;
        Accum<K, 1> near;
        near.clear();
        for (int n = 0; n < count; ++n)
            accumulate_line<K, 1, L>(g.records + list[n] * g.record_floats, grid_coord(gx, g.cell, g.inv_extent),
                                     grid_coord(gy, g.cell, g.inv_extent), 0.0f, g.b, batch, near);
        // Into registers first: `out` may be global memory that the compiler
        // cannot prove apart from the grid, and a store before each load
        // would serialise them.
        float far[sum_floats(K)];
        far[0] = all[0] - near.w[0];
        EMOFACE_UNROLL
        for (int k = 0; k < K; ++k) {
            const bool used = k < batch.n;
            far[1 + 2 * k] = used ? all[1 + 2 * batch.slot[k]] - near.dx[k][0] : 0.0f;
            far[2 + 2 * k] = used ? all[2 + 2 * batch.slot[k]] - near.dy[k][0] : 0.0f;
        }
        float* o = out + c * out_stride;
        o[0] = far[0];
        EMOFACE_UNROLL
        for (int k = 0; k < K; ++k) {
            if (k >= batch.n) break;
            o[1 + 2 * batch.slot[k]] = far[1 + 2 * k];
            o[2 + 2 * batch.slot[k]] = far[2 + 2 * k];
        }
    }
}

// A cell row's ends for the batch: the corner sums `top` and `bottom`
// (grid layout, by slot) interpolated to fraction fy of the cell, into
// `row` (the batch's own layout, sum_floats(K) floats; 0 past n).
template <int K>
EMOFACE_HD EMOFACE_INLINE void cell_row_end(const float* top, const float* bottom, float fy, const Batch<K>& batch,
                                            float* row) {
    row[0] = top[0] + fy * (bottom[0] - top[0]);
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        if (k < batch.n) {
            const int x = 1 + 2 * batch.slot[k], y = 2 + 2 * batch.slot[k];
            row[1 + 2 * k] = top[x] + fy * (bottom[x] - top[x]);
            row[2 + 2 * k] = top[y] + fy * (bottom[y] - top[y]);
        } else {
            row[1 + 2 * k] = 0.0f;
            row[2 + 2 * k] = 0.0f;
        }
    }
}

// One run of R neighbouring pixels of a cell row, the first at column i0 of
// its cell and at (x, y) iso units: the far sums interpolated between the
// row's `left` and `right` ends (the cell's corner sums already interpolated
// to this row, the batch's layout), plus the near lines exactly; a crowded
// cell (count > kMaxNear) sums every line exactly.
template <int K, int R, Law L>
EMOFACE_HD EMOFACE_INLINE void cell_run(const FastGrid& g, const unsigned short* list, int count, const float* left,
                                        const float* right, int i0, float x, float y, const Batch<K>& batch,
                                        Accum<K, R>& acc) {
    if (count > kMaxNear) {
        acc.clear();
        for (int l = 0; l < g.lines; ++l)
            accumulate_line<K, R, L>(g.records + l * g.record_floats, x, y, g.inv_extent, g.b, batch, acc);
        return;
    }
    EMOFACE_PIXEL_LOOP
    for (int j = 0; j < R; ++j) {
        const float fx = static_cast<float>(i0 + j) * g.inv_cell;
        acc.w[j] = left[0] + fx * (right[0] - left[0]);
        EMOFACE_UNROLL
        for (int k = 0; k < K; ++k) {
            acc.dx[k][j] = left[1 + 2 * k] + fx * (right[1 + 2 * k] - left[1 + 2 * k]);
            acc.dy[k][j] = left[2 + 2 * k] + fx * (right[2 + 2 * k] - left[2 + 2 * k]);
        }
    }
    for (int n = 0; n < count; ++n)
        accumulate_line<K, R, L>(g.records + list[n] * g.record_floats, x, y, g.inv_extent, g.b, batch, acc);
}

// ---- sampling and blending --------------------------------------------------

// A key map in memory: rows of `pitch` bytes, RGBA8 (4 bytes a pixel) or
// RGBA float (16 bytes a pixel), width x height pixels as the target sees
// them, of which only the crop [crop_x, crop_x + crop_w) x [crop_y, crop_y +
// crop_h) is stored (`base` is its first pixel); texels outside it read as
// `rest` (format units). A key without a region is stored whole.
struct ImageView {
    const unsigned char* base;
    std::size_t pitch;
    int width, height;
    bool is_float;
    int crop_x, crop_y, crop_w, crop_h;
    Rgba rest;
};

EMOFACE_HD EMOFACE_INLINE bool in_crop(const ImageView& img, int x, int y) {
    return static_cast<unsigned>(x - img.crop_x) < static_cast<unsigned>(img.crop_w) &&
           static_cast<unsigned>(y - img.crop_y) < static_cast<unsigned>(img.crop_h);
}

// Texel (x, y) of the whole map (0 <= x < width, 0 <= y < height).
EMOFACE_HD EMOFACE_INLINE Rgba load_texel(const ImageView& img, int x, int y) {
    if (!in_crop(img, x, y)) return img.rest;
    x -= img.crop_x;
    y -= img.crop_y;
    const unsigned char* row = img.base + static_cast<std::size_t>(y) * img.pitch;
    if (img.is_float) {
        const float* p = reinterpret_cast<const float*>(row) + 4 * x;
        return {p[0], p[1], p[2], p[3]};
    }
    const unsigned char* p = row + 4 * x;
    return {static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2]),
            static_cast<float>(p[3])};
}

EMOFACE_HD EMOFACE_INLINE float lerp2(float p, float q, float r, float s, float tx, float ty) {
    const float top = p + tx * (q - p);
    const float bottom = r + tx * (s - r);
    return top + ty * (bottom - top);
}

// Bilinear sample at pixel coordinates (px, py), pixel centres at i + 0.5,
// clamped to the edge. RGBA8 values stay in 0..255 units.
EMOFACE_HD EMOFACE_INLINE Rgba sample_bilinear(const ImageView& img, float px, float py) {
    const float fx = clampf(px - 0.5f, 0.0f, static_cast<float>(img.width - 1));
    const float fy = clampf(py - 0.5f, 0.0f, static_cast<float>(img.height - 1));
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const int x1 = x0 + 1 < img.width ? x0 + 1 : x0;
    const int y1 = y0 + 1 < img.height ? y0 + 1 : y0;
    const float tx = fx - static_cast<float>(x0), ty = fy - static_cast<float>(y0);
    const Rgba a = load_texel(img, x0, y0), b = load_texel(img, x1, y0);
    const Rgba c = load_texel(img, x0, y1), d = load_texel(img, x1, y1);
    return {lerp2(a.r, b.r, c.r, d.r, tx, ty), lerp2(a.g, b.g, c.g, d.g, tx, ty),
            lerp2(a.b, b.b, c.b, d.b, tx, ty), lerp2(a.a, b.a, c.a, d.a, tx, ty)};
}

EMOFACE_HD EMOFACE_INLINE void add_weighted(Rgba& sum, const Rgba& c, float w) {
    sum.r += w * c.r;
    sum.g += w * c.g;
    sum.b += w * c.b;
    sum.a += w * c.a;
}

// A normal map stores 0.5 + 0.5 n (times 255 for RGBA8). The blend of unit
// vectors is shorter than 1; renormalise it and keep the encoding. A blend that
// cancels out (or no source at all) gives the flat normal +z.
EMOFACE_HD EMOFACE_INLINE Rgba renormalise(Rgba c, float unit) {
    const float inv_unit = 1.0f / unit;
    float nx = 2.0f * c.r * inv_unit - 1.0f;
    float ny = 2.0f * c.g * inv_unit - 1.0f;
    float nz = 2.0f * c.b * inv_unit - 1.0f;
    const float len2 = nx * nx + ny * ny + nz * nz;
    if (len2 > 1e-12f) {
        const float inv = 1.0f / std::sqrt(len2);
        nx *= inv;
        ny *= inv;
        nz *= inv;
    } else {
        nx = 0.0f;
        ny = 0.0f;
        nz = 1.0f;
    }
    return {(0.5f + 0.5f * nx) * unit, (0.5f + 0.5f * ny) * unit, (0.5f + 0.5f * nz) * unit, c.a};
}

EMOFACE_HD EMOFACE_INLINE unsigned char to_byte(float v) {
    return static_cast<unsigned char>(clampf(v, 0.0f, 255.0f) + 0.5f);
}

// RGBA8 packed little-endian into one 32-bit word (r in the low byte).
EMOFACE_HD EMOFACE_INLINE std::uint32_t pack_rgba8(const Rgba& c) {
    return static_cast<std::uint32_t>(to_byte(c.r)) |
           (static_cast<std::uint32_t>(to_byte(c.g)) << 8) |
           (static_cast<std::uint32_t>(to_byte(c.b)) << 16) |
           (static_cast<std::uint32_t>(to_byte(c.a)) << 24);
}

// Samples the batch's sources at X + D_k and adds them by weight to `sum`
// (keys and weights indexed by slot): the per-pixel end of a batch, after
// the line loop.
template <int K>
EMOFACE_HD EMOFACE_INLINE void blend_batch(const ImageView* keys, const float* weights, const Batch<K>& batch, float px,
                                           float py, const float (&dx)[K], const float (&dy)[K], Rgba& sum) {
    EMOFACE_UNROLL
    for (int k = 0; k < K; ++k) {
        if (k >= batch.n) break;
        const int i = batch.slot[k];
        add_weighted(sum, sample_bilinear(keys[i], px + dx[k], py + dy[k]), weights[i]);
    }
}

// Below this |1 − Σw| the blend is convex and rest is left out, so weights
// meant to sum to 1 give the plain blend to the last bit, whatever rest is.
inline constexpr float kConvexSlack = 1e-5f;

// The per-pixel end of the kernel: `sum` = Σ w_k key_k over the sources
// evaluated here, whose weights sum to `weight_sum`. Adds (1 − weight_sum)
// · rest (format units); where that share is not 0, clamps to the format's
// range ([0, unit]; RgbaF32 colour keeps its values) since keys added over
// rest can overshoot it; renormalises a normal map.
EMOFACE_HD EMOFACE_INLINE Rgba finish_blend(Rgba sum, float weight_sum, const Rgba& rest, bool normal_map,
                                            bool is_float) {
    const float unit = is_float ? 1.0f : 255.0f;
    const float share = 1.0f - weight_sum;
    if (absf(share) > kConvexSlack) {
        add_weighted(sum, rest, share);
        if (normal_map || !is_float) {
            sum.r = clampf(sum.r, 0.0f, unit);
            sum.g = clampf(sum.g, 0.0f, unit);
            sum.b = clampf(sum.b, 0.0f, unit);
            sum.a = clampf(sum.a, 0.0f, unit);
        }
    }
    if (normal_map) sum = renormalise(sum, unit);
    return sum;
}

}  // namespace emoface::morph::kernel
