#include "emoface/render/image_diff.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>

#include "emoface/common/error.h"

namespace emoface::render {

double ImageDiff::psnr() const {
    if (mean_squared == 0.0) return std::numeric_limits<double>::infinity();
    return 10.0 * std::log10(255.0 * 255.0 / mean_squared);
}

std::vector<std::uint8_t> box_mask(int width, int height, int x0, int y0, int x1, int y1) {
    std::vector<std::uint8_t> mask(std::size_t(width) * std::size_t(height), 0);
    for (int y = std::max(0, y0); y < std::min(height, y1); ++y)
        for (int x = std::max(0, x0); x < std::min(width, x1); ++x) mask[std::size_t(y) * std::size_t(width) + x] = 1;
    return mask;
}

ImageDiff diff_images(const ImageRGBA8& actual, const ImageRGBA8& expected, const ImageDiffOptions& options) {
    if (actual.width != expected.width || actual.height != expected.height)
        fail("render: diff_images(): expected images of one size, got {}x{} and {}x{}", actual.width,
             actual.height, expected.width, expected.height);
    const std::size_t pixels = std::size_t(actual.width) * std::size_t(actual.height);
    if (!options.mask.empty() && options.mask.size() != pixels)
        fail("render: diff_images(): expected a mask of {} bytes ({}x{}), got {}", pixels, actual.width,
             actual.height, options.mask.size());
    ImageDiff d;
    d.visual = ImageRGBA8(actual.width, actual.height);
    double sum = 0.0, sum_squared = 0.0;
    for (std::size_t i = 0; i < pixels; ++i) {
        const std::uint8_t* a = &actual.pixels[4 * i];
        const std::uint8_t* e = &expected.pixels[4 * i];
        std::uint8_t* v = &d.visual.pixels[4 * i];
        v[0] = std::uint8_t(e[0] / 4);
        v[1] = std::uint8_t(e[1] / 4);
        v[2] = std::uint8_t(e[2] / 4);
        v[3] = 255;
        if (!options.mask.empty() && !options.mask[i]) continue;
        int pixel_max = 0;
        for (int c = 0; c < 3; ++c) {
            const int diff = std::abs(int(a[c]) - int(e[c]));
            pixel_max = std::max(pixel_max, diff);
            sum += diff;
            sum_squared += double(diff) * diff;
        }
        ++d.compared_pixels;
        d.failing_pixels += pixel_max > options.pixel_tolerance;
        d.max_channel_diff = std::max(d.max_channel_diff, pixel_max);
        v[0] = std::uint8_t(std::min(255, v[0] + pixel_max * 8));
    }
    if (d.compared_pixels) {
        d.mean_diff = sum / (3.0 * double(d.compared_pixels));
        d.mean_squared = sum_squared / (3.0 * double(d.compared_pixels));
    }
    return d;
}

}  // namespace emoface::render
