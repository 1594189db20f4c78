#pragma once
// Golden-image comparison in the way Filament's imagediff does it: explicit
// tolerances, each with a written reason, and on a mismatch the actual image
// and an amplified difference image are written for a person to look at.
// With EMOFACE_UPDATE_GOLDENS=1 in the environment (scripts/update-goldens)
// the goldens are rewritten instead of compared.
#include <string>

#include "emoface/render/image.h"

namespace emoface::render::testing {

struct Tolerance {
    int max_channel_diff;   // largest |actual - golden| of any RGB channel, 0..255
    double mean_diff;       // mean |actual - golden| over all RGB channels
    const char* reason;     // why these numbers (printed with a failure)
};

// The tolerance of a rendered face (the default face's goldens and the
// anchored-layout head's). Same code and Mesa as when the goldens were made
// give the same bytes; the tolerance absorbs what may differ between
// machines: the morph's AVX2 and plain row loops round the last bit
// differently (a wrinkle pixel off by one step here and there: a mean of
// about 0.001), and a different llvmpipe may place a silhouette sample
// differently (single pixels off by up to ~40 after the 2x reduction). A real
// change is far outside: drawing a face without its wrinkle maps moves the
// mean by more than twice this (each suite checks that it still does).
inline constexpr Tolerance kFaceTolerance{48, 0.04,
                                          "same code and Mesa: identical; other CPUs or Mesa "
                                          "versions: 1-step wrinkle rounding and a few silhouette "
                                          "pixels"};

struct GoldenResult {
    bool ok = false;
    bool updated = false;  // EMOFACE_UPDATE_GOLDENS: the golden was written
    int max_channel_diff = 0;
    double mean_diff = 0.0;
    std::string message;   // what failed and where the actual/diff images are
};

// Compares `actual` with the PNG `golden_path`. On a mismatch (or a missing
// golden) writes <failure_dir>/<name>.actual.png and <name>.diff.png.
GoldenResult compare_with_golden(const ImageRGBA8& actual, const std::string& golden_path,
                                 const Tolerance& tolerance, const std::string& failure_dir);

// A box-filtered 2x reduction (even sizes): goldens are stored at half the
// rendered size, which keeps them small and averages away single-sample
// edge differences.
ImageRGBA8 downsample2x(const ImageRGBA8& image);

}  // namespace emoface::render::testing
