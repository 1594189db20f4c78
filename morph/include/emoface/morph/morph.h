#pragma once
// morph: Beier-Neely multi-source warp and blend (DESIGN.md "Beier-Neely
// warp", thesis 3.2 and 5). Knows nothing of faces: K key images, each with a
// layout of N feature lines, are warped onto a target layout and blended by
// K weights over a rest value:
//   out = Σ_k w_k · warp(key_k, layout_k -> target) + (1 − Σ_k w_k) · rest.
// Weights summing to 1 are the thesis's convex blend (rest drops out). Keys
// that are deviations from a rest state (per-Action-Unit wrinkles over flat
// skin) take weights summing to more than 1: each adds w_k · (key_k − rest).
// A key may declare a region (KeyMap::region) outside which it equals rest;
// it is stored cropped and evaluated only where its region lands in the
// target, so small keys cost about their size.
//
// Coordinates. Line end points are normalised texture coordinates: x = 0 at
// the left edge and 1 at the right edge of the image, y = 0 at the top edge
// and 1 at the bottom (origin top-left, x right, y down; pixel (i, j) has its
// centre at ((i + 0.5) / W, (j + 0.5) / H)). So one layout serves every
// resolution. Distances (MorphParams::a) are in units of the image's longer
// side, so a non-square image is warped without distortion. Pixel rows are
// stored top to bottom. Sampling is bilinear with clamp-to-edge.
//
// Cost model. The constructor allocates and uploads the key maps once (the
// thesis's steps 1 and 2); a frame validates the target layout and weights,
// builds the line table (N records) and runs one pass (exact) or two
// (fast), allocating nothing (buffers that only some calls need, such as the
// fast mode's displacement grid, are allocated at their first use). A key at
// weight 0 is neither warped nor sampled; the kernel keeps the sums of at
// most 8 keys at once and runs its line loop once per 8 keys that overlap a
// block of pixels.
#include <cstddef>
#include <memory>
#include <string>
#include <array>
#include <vector>

#include "emoface/morph/limits.h"

namespace emoface::morph {

enum class Backend { Auto, Cpu, Cuda };
enum class Accuracy { Exact, Fast };
enum class PixelFormat { Rgba8, RgbaF32 };

const char* to_string(Backend backend);
const char* to_string(Accuracy accuracy);
const char* to_string(PixelFormat format);

// A directed feature line from P = (px, py) to Q = (qx, qy), normalised
// texture coordinates (see above).
struct Line {
    float px, py, qx, qy;
};
using Layout = std::vector<Line>;

struct MorphParams {
    // Beier-Neely's weight (len^p / (a + dist))^b: a > 0 (units of the longer
    // side) sets how sharply lines hold nearby pixels, b >= 0 how fast their
    // influence falls off with distance, p >= 0 how much longer lines count.
    // b = 2 takes a faster path than other values.
    float a = 0.01f;
    float b = 2.0f;
    float p = 0.5f;
    // The keys are normal maps encoded 0.5 + 0.5 n: renormalise the blended
    // vector and keep the encoding (alpha is blended as is).
    bool normal_map = false;
    Accuracy accuracy = Accuracy::Exact;
    // Accuracy::Fast evaluates all lines exactly only on a grid every
    // fast_cell pixels (4, 8, 16 or 32) and interpolates their sums bilinearly
    // in between, except for the lines that pass within fast_reach cells of a
    // cell, which are evaluated exactly at each of its pixels (so the kink of
    // the weight across a line is never interpolated). fast_reach = 0 gives
    // plain grid interpolation; larger values trade speed for accuracy (the
    // error of the interpolated part falls as 1 / fast_reach²).
    int fast_cell = 8;
    float fast_reach = 4.0f;
    // What the blend tends to where keys say nothing: the value a key has
    // outside its region, and the (1 − Σ w) share of every pixel. RGBA in
    // [0, 1] units of the format (Rgba8: 1 = 255). Normal maps of wrinkles
    // pass flat skin {0.5, 0.5, 1, 1}: slopes of overlapping keys then add,
    // and alpha (1 = open skin) becomes 1 + Σ w (a_k − 1). The blend is
    // clamped to the format's range ([0, 1] for normal maps, [0, 255] for
    // Rgba8) before a normal map is renormalised and stored. Pick a value
    // the format holds exactly (Rgba8: a multiple of 1/255) if the keys'
    // rest pixels must cancel to the last bit. When the weights of the keys
    // evaluated at a pixel sum to 1 (within 1e-5) rest is not added at all, so
    // the convex blend is bit-identical with any rest.
    std::array<float, 4> rest{0.0f, 0.0f, 0.0f, 0.0f};
};

// A rectangle in normalised coordinates of a key's own layout (see above:
// x right, y down, 0..1 across the map), x0 < x1, y0 < y1.
struct Region {
    float x0 = 0.0f, y0 = 0.0f, x1 = 1.0f, y1 = 1.0f;
};

struct KeyMap {
    // width * height pixels of the Morpher's format, rows top to bottom, tightly
    // packed (4 bytes a pixel for Rgba8, 16 for RgbaF32). Copied by the Morpher.
    const void* pixels = nullptr;
    Layout layout;
    // The key's size if the caller knows it: checked against the Morpher's.
    // 0 means "the Morpher's size".
    int width = 0;
    int height = 0;
    // Where the key differs from MorphParams::rest; outside it the key IS
    // rest, whatever its pixels hold there. The Morpher keeps only the pixels
    // the region touches, and evaluates the key per frame only for target
    // pixels within a bound of where the region lands: the region's
    // rectangle grown by the largest displacement of any line end point
    // between the key's layout and the target, by a quarter of that again and
    // by 2 pixels. Beier-Neely moves a pixel by a weighted mean of what its
    // lines do at its position, which can exceed their end points' moves
    // where lines rotate or stretch far from the pixel; the margin covers
    // that for layouts whose lines move together (faces), it is not a proof.
    Region region;
};

// What the constructor spent on the thesis's steps 1 (allocate) and 2 (upload).
struct SetupTimes {
    double allocate_ms = 0.0;
    double upload_ms = 0.0;
};

// True when this build has the CUDA backend and a CUDA device is usable.
bool cuda_available();
// "NVIDIA H100 80GB HBM3 (sm_90, 132 SMs)", or why there is none.
std::string cuda_device_description();
// The CPU backend's row loops a Morpher made now would run: "avx2" (AVX2 +
// FMA, where the build and the processor have them) or "baseline" (the
// target's base instruction set). EMOFACE_MORPH_BASELINE=1 in the environment
// forces "baseline"; it is read each time a Morpher is made.
const char* cpu_kernels_name();

class Morpher {
public:
    static constexpr int kMaxKeys = morph::kMaxKeys;
    static constexpr int kMaxSide = 16384;
    static constexpr int kMaxLines = 4096;

    // Throws emoface::InputError for bad keys (count 0 or over kMaxKeys, null
    // pixels, sizes that differ, layouts with different line counts or over
    // kMaxLines lines, a line of zero length or with a non-finite coordinate,
    // a region that is not a non-empty rectangle within [0, 1]²) and emoface::EnvironmentError
    // for Backend::Cuda where no device is usable. Backend::Auto picks CUDA when
    // a device is usable, otherwise the CPU with a one-line notice on stderr.
    Morpher(int width, int height, PixelFormat format, std::vector<KeyMap> keys,
            Backend backend = Backend::Auto);
    ~Morpher();
    Morpher(Morpher&&) noexcept;
    Morpher& operator=(Morpher&&) noexcept;
    Morpher(const Morpher&) = delete;
    Morpher& operator=(const Morpher&) = delete;

    Backend backend() const;  // Cpu or Cuda, never Auto
    int width() const;
    int height() const;
    int keys() const;
    int lines() const;
    PixelFormat format() const;
    std::size_t pixel_bytes() const;  // 4 or 16
    SetupTimes setup_times() const;

    // Each frame: `target` has lines() lines (a target line of zero length,
    // collapsed in this pose, is skipped for the frame), `weights` keys() entries, each
    // finite and >= 0, summing to at most kMaxKeys (a key with weight 0 costs
    // nothing; see MorphParams::rest for sums other than 1). Bad input
    // throws emoface::InputError before anything is written.

    // out: width * height pixels of format(), tightly packed, host memory.
    // Returns when `out` is written.
    void morph_to_host(const Layout& target, const std::vector<float>& weights,
                       const MorphParams& params, void* out);

    // CUDA backend only. Device memory of `pitch_bytes` a row. Ordered on
    // cuda_stream(): returns once the work is queued; call synchronize() (or
    // order your own stream after it) before reading.
    void morph_to_device(const Layout& target, const std::vector<float>& weights,
                         const MorphParams& params, void* device_ptr, std::size_t pitch_bytes);

    // CUDA backend only. A cudaSurfaceObject_t over a width x height array of
    // the key format (RGBA8: cudaChannelFormat 8,8,8,8 unsigned; RgbaF32:
    // 32,32,32,32 float), e.g. a GL texture mapped through CUDA-GL interop.
    // Ordered on cuda_stream() like morph_to_device: map and unmap the GL
    // resource on that stream (cudaGraphicsMapResources(..., stream)) so GL sees
    // the finished texture without a host round trip.
    void morph_to_surface(const Layout& target, const std::vector<float>& weights,
                          const MorphParams& params, unsigned long long surface);

    // For tests and the benchmark: where each pixel samples each key. out gets
    // width * height * keys() * 2 floats: for pixel (x, y) (row-major) and key k,
    // out[((y * width + x) * keys() + k) * 2 + {0, 1}] = the (x, y) pixel
    // coordinates in key k, pixel centres at i + 0.5. Returns when written.
    void positions_to_host(const Layout& target, const MorphParams& params, float* out);

    // Waits for the work queued by morph_to_device / morph_to_surface.
    void synchronize();
    // The backend's cudaStream_t (as void*), nullptr on the CPU backend.
    void* cuda_stream() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

}  // namespace emoface::morph
