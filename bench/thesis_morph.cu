// The thesis's kernel structure (see thesis_morph.h): kept deliberately as
// described in chapter 5, not optimised.
#include "thesis_morph.h"

#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <stdexcept>
#include <string>

#include "emoface/common/timing.h"

namespace emoface::bench {
namespace {

void check(cudaError_t e, const char* what) {
    if (e != cudaSuccess) throw std::runtime_error(std::string("thesis morph: ") + what + ": " + cudaGetErrorString(e));
}
#define THESIS_CHECK(call) check((call), #call)


// MakeInterpolationGPUKernel: the in-between guide lines.
__global__ void make_interpolation(const float* lines, const float* weights, int keys, int n, float* target) {
    const int i = blockIdx.x * blockDim.x + threadIdx.x;
    if (i >= n * 4) return;
    float sum = 0.0f;
    for (int k = 0; k < keys; ++k) sum += weights[k] * lines[k * n * 4 + i];
    target[i] = sum;
}

// The pixel a thread of a 2D launch works on: its centre (X, Y), its index p,
// and the image's pixel count, the stride between the per-line matrices.
struct PixelThread {
    float X, Y;
    std::size_t p, pixels;
};
__device__ bool pixel_thread(int width, int height, PixelThread& t) {
    const int x = blockIdx.x * blockDim.x + threadIdx.x;
    const int y = blockIdx.y * blockDim.y + threadIdx.y;
    if (x >= width || y >= height) return false;
    t = {x + 0.5f, y + 0.5f, static_cast<std::size_t>(y) * width + x, static_cast<std::size_t>(width) * height};
    return true;
}

// MakeMorphiGPU0: FindU and FindV for every pixel and line, to the matrices.
__global__ void make_morph_uv(const float* target, int n, int width, int height, float* u, float* v) {
    PixelThread t;
    if (!pixel_thread(width, height, t)) return;
    const float X = t.X, Y = t.Y;
    const std::size_t pixels = t.pixels, p = t.p;
    for (int i = 0; i < n; ++i) {
        const float px = target[4 * i], py = target[4 * i + 1];
        const float dx = target[4 * i + 2] - px, dy = target[4 * i + 3] - py;
        const float len2 = dx * dx + dy * dy;
        u[i * pixels + p] = ((X - px) * dx + (Y - py) * dy) / len2;         // FindU
        v[i * pixels + p] = ((X - px) * -dy + (Y - py) * dx) / sqrtf(len2);  // FindV
    }
}

// MakeMorphiGPUA: the new position of every pixel in one key, then its sample.
__global__ void make_morph_position(const float* target, const float* lines, int n, const float* u, const float* v,
                                    const std::uint8_t* key, int width, int height, float a, float b, float p_exp,
                                    std::uint8_t* warped) {
    PixelThread t;
    if (!pixel_thread(width, height, t)) return;
    const float X = t.X, Y = t.Y;
    const std::size_t pixels = t.pixels, p = t.p;
    float sx = 0.0f, sy = 0.0f, wsum = 0.0f;
    for (int i = 0; i < n; ++i) {
        const float uu = u[i * pixels + p], vv = v[i * pixels + p];
        const float px = lines[4 * i], py = lines[4 * i + 1];
        const float dx = lines[4 * i + 2] - px, dy = lines[4 * i + 3] - py;
        const float slen = sqrtf(dx * dx + dy * dy);
        const float nx = px + uu * dx + vv * -dy / slen;
        const float ny = py + uu * dy + vv * dx / slen;
        const float tpx = target[4 * i], tpy = target[4 * i + 1];
        const float tqx = target[4 * i + 2], tqy = target[4 * i + 3];
        float dist;
        if (uu < 0.0f)
            dist = sqrtf((X - tpx) * (X - tpx) + (Y - tpy) * (Y - tpy));
        else if (uu > 1.0f)
            dist = sqrtf((X - tqx) * (X - tqx) + (Y - tqy) * (Y - tqy));
        else
            dist = fabsf(vv);
        const float len = sqrtf((tqx - tpx) * (tqx - tpx) + (tqy - tpy) * (tqy - tpy));
        const float w = powf(powf(len, p_exp) / (a + dist), b);
        sx += (nx - X) * w;
        sy += (ny - Y) * w;
        wsum += w;
    }
    const float fx = fminf(fmaxf(X + sx / wsum - 0.5f, 0.0f), width - 1.0f);
    const float fy = fminf(fmaxf(Y + sy / wsum - 0.5f, 0.0f), height - 1.0f);
    const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
    const int x1 = min(x0 + 1, width - 1), y1 = min(y0 + 1, height - 1);
    const float tx = fx - x0, ty = fy - y0;
    for (int c = 0; c < 4; ++c) {
        const float t00 = key[(static_cast<std::size_t>(y0) * width + x0) * 4 + c];
        const float t10 = key[(static_cast<std::size_t>(y0) * width + x1) * 4 + c];
        const float t01 = key[(static_cast<std::size_t>(y1) * width + x0) * 4 + c];
        const float t11 = key[(static_cast<std::size_t>(y1) * width + x1) * 4 + c];
        const float top = t00 + tx * (t10 - t00), bottom = t01 + tx * (t11 - t01);
        warped[p * 4 + c] = static_cast<std::uint8_t>(fminf(255.0f, top + ty * (bottom - top)) + 0.5f);
    }
}

// The cross-dissolve, as its own pass.
__global__ void cross_dissolve(const std::uint8_t* const* warped, const float* weights, int keys,
                               std::size_t bytes, std::uint8_t* out) {
    const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i >= bytes) return;
    float sum = 0.0f;
    for (int k = 0; k < keys; ++k) sum += weights[k] * warped[k][i];
    out[i] = static_cast<std::uint8_t>(fminf(255.0f, sum) + 0.5f);
}

}  // namespace

ThesisMorph::ThesisMorph(int width, int height, const std::vector<const std::uint8_t*>& keys,
                         const std::vector<morph::Layout>& layouts)
    : width_(width), height_(height), keys_(static_cast<int>(keys.size())),
      lines_(static_cast<int>(layouts[0].size())) {
    THESIS_CHECK(cudaFree(nullptr));
    const std::size_t pixels = static_cast<std::size_t>(width) * height;
    const std::size_t image_bytes = pixels * 4;
    auto t0 = Clock::now();
    d_keys_.assign(keys_, nullptr);
    d_warped_.assign(keys_, nullptr);
    for (int k = 0; k < keys_; ++k) {
        THESIS_CHECK(cudaMalloc(&d_keys_[k], image_bytes));
        THESIS_CHECK(cudaMalloc(&d_warped_[k], image_bytes));
    }
    THESIS_CHECK(cudaMalloc(&d_lines_, sizeof(float) * 4 * lines_ * keys_));
    THESIS_CHECK(cudaMalloc(&d_target_, sizeof(float) * 4 * lines_));
    THESIS_CHECK(cudaMalloc(&d_weights_, sizeof(float) * keys_));
    THESIS_CHECK(cudaMalloc(&d_u_, sizeof(float) * pixels * lines_));
    THESIS_CHECK(cudaMalloc(&d_v_, sizeof(float) * pixels * lines_));
    THESIS_CHECK(cudaMalloc(&d_out_, image_bytes));
    THESIS_CHECK(cudaMalloc(&d_warped_list_, sizeof(void*) * keys_));
    THESIS_CHECK(cudaDeviceSynchronize());
    stages_.allocate_ms = ms_since(t0);

    t0 = Clock::now();
    std::vector<float> lines;
    for (const morph::Layout& l : layouts)
        for (const morph::Line& line : l) {
            lines.push_back(line.px * width);
            lines.push_back(line.py * height);
            lines.push_back(line.qx * width);
            lines.push_back(line.qy * height);
        }
    for (int k = 0; k < keys_; ++k)
        THESIS_CHECK(cudaMemcpy(d_keys_[k], keys[k], image_bytes, cudaMemcpyHostToDevice));
    THESIS_CHECK(cudaMemcpy(d_lines_, lines.data(), sizeof(float) * lines.size(), cudaMemcpyHostToDevice));
    THESIS_CHECK(cudaMemcpy(d_warped_list_, d_warped_.data(), sizeof(void*) * keys_, cudaMemcpyHostToDevice));
    THESIS_CHECK(cudaDeviceSynchronize());
    stages_.upload_ms = ms_since(t0);

    cudaEvent_t e0, e1;
    THESIS_CHECK(cudaEventCreate(&e0));
    THESIS_CHECK(cudaEventCreate(&e1));
    start_ = e0;
    stop_ = e1;
}

ThesisMorph::~ThesisMorph() {
    if (!released_) release();
}

void ThesisMorph::release() {
    if (released_) return;
    released_ = true;
    cudaDeviceSynchronize();
    const auto t0 = Clock::now();
    for (auto* p : d_keys_) cudaFree(p);
    for (auto* p : d_warped_) cudaFree(p);
    cudaFree(d_lines_);
    cudaFree(d_target_);
    cudaFree(d_weights_);
    cudaFree(d_u_);
    cudaFree(d_v_);
    cudaFree(d_out_);
    cudaFree(d_warped_list_);
    cudaDeviceSynchronize();
    stages_.free_ms = ms_since(t0);
    cudaEventDestroy(static_cast<cudaEvent_t>(start_));
    cudaEventDestroy(static_cast<cudaEvent_t>(stop_));
}

float ThesisMorph::frame(const std::vector<float>& weights, const morph::MorphParams& params) {
    const float a = params.a * std::max(width_, height_);  // pixels, as the thesis worked
    THESIS_CHECK(cudaMemcpy(d_weights_, weights.data(), sizeof(float) * keys_, cudaMemcpyHostToDevice));

    const dim3 block(16, 16);
    const dim3 grid((width_ + 15) / 16, (height_ + 15) / 16);
    const std::size_t bytes = static_cast<std::size_t>(width_) * height_ * 4;
    auto start = static_cast<cudaEvent_t>(start_), stop = static_cast<cudaEvent_t>(stop_);
    THESIS_CHECK(cudaEventRecord(start));
    make_interpolation<<<(lines_ * 4 + 127) / 128, 128>>>(d_lines_, d_weights_, keys_, lines_, d_target_);
    THESIS_CHECK(cudaDeviceSynchronize());
    make_morph_uv<<<grid, block>>>(d_target_, lines_, width_, height_, d_u_, d_v_);
    THESIS_CHECK(cudaDeviceSynchronize());
    for (int k = 0; k < keys_; ++k) {
        make_morph_position<<<grid, block>>>(d_target_, d_lines_ + static_cast<std::size_t>(k) * lines_ * 4, lines_,
                                             d_u_, d_v_, d_keys_[k], width_, height_, a, params.b, params.p,
                                             d_warped_[k]);
        THESIS_CHECK(cudaDeviceSynchronize());
    }
    cross_dissolve<<<static_cast<unsigned>((bytes + 255) / 256), 256>>>(
        reinterpret_cast<const std::uint8_t* const*>(d_warped_list_), d_weights_, keys_, bytes, d_out_);
    THESIS_CHECK(cudaEventRecord(stop));
    THESIS_CHECK(cudaEventSynchronize(stop));
    THESIS_CHECK(cudaGetLastError());
    float ms = 0.0f;
    THESIS_CHECK(cudaEventElapsedTime(&ms, start, stop));
    return ms;
}

std::vector<std::uint8_t> ThesisMorph::output() const {
    std::vector<std::uint8_t> out(static_cast<std::size_t>(width_) * height_ * 4);
    THESIS_CHECK(cudaMemcpy(out.data(), d_out_, out.size(), cudaMemcpyDeviceToHost));
    return out;
}

}  // namespace emoface::bench
