#pragma once
// Parity between two results (CPU and CUDA, exact and fast, before and after
// a round trip). A NaN or a size mismatch is never "close": each makes the
// difference infinite, so every EXPECT_LT/LE/EQ on it fails.
#include <cmath>
#include <limits>
#include <vector>

namespace emoface::testing {

// The largest |a[i] - b[i]|; +infinity when the sizes differ or either side
// holds a NaN.
template <class T>
double max_abs_diff(const std::vector<T>& a, const std::vector<T>& b) {
    constexpr double kNever = std::numeric_limits<double>::infinity();
    if (a.size() != b.size()) return kNever;
    double m = 0.0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const double d = std::fabs(static_cast<double>(a[i]) - static_cast<double>(b[i]));
        if (std::isnan(d)) return kNever;
        m = std::fmax(m, d);
    }
    return m;
}

}  // namespace emoface::testing
