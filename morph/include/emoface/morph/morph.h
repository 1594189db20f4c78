#pragma once
// morph: Beier-Neely multi-source warp and blend (DESIGN.md "Beier-Neely
// warp", thesis 3.2 and 5). Knows nothing of faces: K key images, each with a
// layout of N feature lines, are warped onto a target layout and blended by
// K weights:  out = Σ_k w_k · warp(key_k, layout_k -> target).
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
// fast mode's displacement grid, are allocated at their first use).
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

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
    static constexpr int kMaxKeys = 8;
    static constexpr int kMaxSide = 16384;
    static constexpr int kMaxLines = 4096;

    // Throws emoface::InputError for bad keys (count 0 or over kMaxKeys, null
    // pixels, sizes that differ, layouts with different line counts or over
    // kMaxLines lines, a line of zero length or with a non-finite coordinate) and emoface::EnvironmentError
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
    // >= 0, summing to at most 1 (a key with weight 0 costs nothing). Bad input
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
