#pragma once
// A re-implementation of the thesis's GPU morph (chapter 5.2-5.3) with its
// structure kept, as the benchmark's point of comparison:
//   step 1 allocate: cudaMalloc for the key textures, their guide lines, the
//          interpolated lines, the u and v matrices (N x W x H floats each),
//          one warped temporary per key and the output;
//   step 2 upload: cudaMemcpy of textures and lines;
//   step 3 per frame, separate kernels with a device-wide sync between them:
//          MakeInterpolationGPUKernel (the target lines from the key lines and
//          the weights), MakeMorphiGPU0 (FindU/FindV: u and v of every pixel
//          for every line, written to the matrices), MakeMorphiGPUA (new
//          position of every pixel, once per key, reading u and v back, then
//          sampling into that key's temporary) and a separate cross-dissolve;
//   step 4 free.
// Plain global memory, one pixel a thread, powf for the weight, as written
// in 2010. Only built with CUDA.
#include <cstdint>
#include <vector>

#include "emoface/morph/morph.h"

namespace emoface::bench {

struct ThesisStages {
    double allocate_ms = 0.0;
    double upload_ms = 0.0;
    double free_ms = 0.0;
};

class ThesisMorph {
public:
    // keys: K RGBA8 images of width x height; layouts: K layouts of N lines.
    ThesisMorph(int width, int height, const std::vector<const std::uint8_t*>& keys,
                const std::vector<morph::Layout>& layouts);
    ~ThesisMorph();
    ThesisMorph(const ThesisMorph&) = delete;
    ThesisMorph& operator=(const ThesisMorph&) = delete;

    // One frame (step 3) for the given weights; the target layout is the
    // weighted mean of the key layouts, computed on the GPU as the thesis
    // did. Returns the GPU time in ms (CUDA events around the 4 kernels).
    float frame(const std::vector<float>& weights, const morph::MorphParams& params);
    // The output of the last frame (RGBA8, tightly packed).
    std::vector<std::uint8_t> output() const;

    const ThesisStages& stages() const { return stages_; }
    // Step 4, timed; the destructor calls it if it was not called.
    void release();

private:
    int width_, height_, keys_, lines_;
    std::vector<std::uint8_t*> d_keys_;
    std::vector<std::uint8_t*> d_warped_;
    float* d_lines_ = nullptr;   // K x N x 4 (px, py, qx, qy), pixel units
    float* d_target_ = nullptr;  // N x 4
    float* d_weights_ = nullptr;
    float* d_u_ = nullptr;
    float* d_v_ = nullptr;
    std::uint8_t* d_out_ = nullptr;
    void* d_warped_list_ = nullptr;  // the K temporaries' addresses, for the dissolve
    void* start_ = nullptr;
    void* stop_ = nullptr;
    ThesisStages stages_;
    bool released_ = false;
};

}  // namespace emoface::bench
