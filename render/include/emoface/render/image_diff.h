#pragma once
// The one image comparison (Filament's imagediff in spirit): per-channel
// differences over RGB, an optional mask of the pixels that count, and the
// fraction of pixels that differ by more than a tolerance. Goldens, the
// tests that compare a window with a rendered frame and the frame_e2e
// benchmark's PSNR check all use it. Alpha is ignored: every picture here is
// opaque, and a window grab has none.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "emoface/render/image.h"

namespace emoface::render {

struct ImageDiffOptions {
    // A pixel fails when any RGB channel differs by more than this (0..255).
    int pixel_tolerance = 0;
    // width * height bytes; only pixels whose byte is non-zero are compared.
    // Empty: every pixel.
    std::vector<std::uint8_t> mask;
};

struct ImageDiff {
    std::size_t compared_pixels = 0;
    std::size_t failing_pixels = 0;  // a channel differs by more than pixel_tolerance
    int max_channel_diff = 0;        // largest |a - b| of any compared RGB channel
    double mean_diff = 0.0;          // mean |a - b| over the compared RGB channels
    double mean_squared = 0.0;       // mean (a - b)^2 over the compared RGB channels
    // Differences amplified 8x in red over a dimmed copy of `expected`, for a
    // person to look at; masked-out pixels stay dimmed.
    ImageRGBA8 visual;

    double failing_fraction() const {
        return compared_pixels ? double(failing_pixels) / double(compared_pixels) : 0.0;
    }
    // Peak signal-to-noise ratio in dB; infinity for identical images.
    double psnr() const;
};

// A mask (ImageDiffOptions::mask) of the pixels in [x0, x1) x [y0, y1).
std::vector<std::uint8_t> box_mask(int width, int height, int x0, int y0, int x1, int y1);

// Throws emoface::Error when the sizes differ (or the mask's does).
ImageDiff diff_images(const ImageRGBA8& actual, const ImageRGBA8& expected, const ImageDiffOptions& options = {});

}  // namespace emoface::render
