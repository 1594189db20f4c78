#pragma once
// Stage timings: milliseconds of the steady clock, the one clock every stage
// table (load, frame, morph) is measured with.
#include <chrono>

namespace emoface {

using Clock = std::chrono::steady_clock;

// Milliseconds from `start` until now.
inline double ms_since(Clock::time_point start) {
    return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

}  // namespace emoface
