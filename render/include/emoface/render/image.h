#pragma once
// Plain pixel buffers exchanged between the renderer, the morph and the
// output target (render_io). Rows run top to bottom, RGBA interleaved.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace emoface::render {

struct ImageRGBA8 {
    int width = 0;
    int height = 0;
    std::vector<std::uint8_t> pixels;  // width * height * 4 bytes

    ImageRGBA8() = default;
    ImageRGBA8(int w, int h) : width(w), height(h), pixels(std::size_t(w) * h * 4, 0) {}
    std::uint8_t* at(int x, int y) { return pixels.data() + (std::size_t(y) * width + x) * 4; }
    const std::uint8_t* at(int x, int y) const {
        return pixels.data() + (std::size_t(y) * width + x) * 4;
    }
    std::size_t row_bytes() const { return std::size_t(width) * 4; }
};

// Linear float RGBA, for high-dynamic-range output (EXR) and float normal maps.
struct ImageRGBA32F {
    int width = 0;
    int height = 0;
    std::vector<float> pixels;  // width * height * 4 floats

    ImageRGBA32F() = default;
    ImageRGBA32F(int w, int h) : width(w), height(h), pixels(std::size_t(w) * h * 4, 0.0f) {}
    float* at(int x, int y) { return pixels.data() + (std::size_t(y) * width + x) * 4; }
    const float* at(int x, int y) const {
        return pixels.data() + (std::size_t(y) * width + x) * 4;
    }
    std::size_t row_bytes() const { return std::size_t(width) * 4 * sizeof(float); }
};

}  // namespace emoface::render
