#include "emoface/fap/fap_stream.h"

#include <cmath>

#include "emoface/common/error.h"

namespace emoface::fap {

namespace {

void check_fps(double fps, const char* function) {
    if (!(std::isfinite(fps) && fps > 0))
        fail("fap: FapStream::{}: expected a frame rate > 0, found {}", function, fps);
}

// Takes into `into` every FAP that `from` transmits and `into` does not have
// yet: used walking backwards from a frame, so the first seen is the latest.
void take_missing(FapFrame& into, const FapFrame& from) {
    const std::bitset<kFapCount> missing = from.mask & ~into.mask;
    if (missing.none()) return;
    if (missing[0]) into.viseme = from.viseme;
    if (missing[1]) into.expression = from.expression;
    for (std::size_t i = 2; i < kFapCount; ++i)
        if (missing[i]) into.values[i] = from.values[i];
    into.mask |= missing;
}

// Frame `next` resolved, given the previous frame already resolved.
FapFrame resolve_after(const FapFrame& previous_resolved, const FapFrame& next) {
    FapFrame out = next;
    take_missing(out, previous_resolved);
    return out;
}

}  // namespace

double FapStream::duration() const {
    check_fps(fps, "duration");
    return static_cast<double>(frames.size()) / fps;
}

double FapStream::frame_time(std::size_t k) const {
    check_fps(fps, "frame_time");
    return static_cast<double>(k) / fps;
}

FapFrame FapStream::resolved(std::size_t k) const {
    if (k >= frames.size())
        fail("fap: FapStream::resolved: expected a frame index below {}, found {}", frames.size(), k);
    FapFrame out = frames[k];
    // Untransmitted values are 0 by the reader's convention; make it so for
    // hand-built frames too, so the result never leaks a stale number.
    for (std::size_t i = 2; i < kFapCount; ++i)
        if (!out.mask[i]) out.values[i] = 0;
    if (!out.mask[0]) out.viseme = Viseme{};
    if (!out.mask[1]) out.expression = Expression{};
    // Walk back until every FAP is found or the stream starts: the latest
    // transmission of each FAP wins.
    for (std::size_t j = k; j-- > 0 && !out.mask.all();) take_missing(out, frames[j]);
    return out;
}

FapFrame FapStream::sample(double seconds) const {
    check_fps(fps, "sample");
    if (!std::isfinite(seconds))
        fail("fap: FapStream::sample: expected a finite time in seconds, found {}", seconds);
    if (frames.empty()) return FapFrame{};
    const double position = seconds * fps;
    const double last = static_cast<double>(frames.size() - 1);
    if (!(position > 0)) return resolved(0);
    if (position >= last) return resolved(frames.size() - 1);

    const auto k = static_cast<std::size_t>(std::floor(position));
    const double t = position - static_cast<double>(k);
    FapFrame a = resolved(k);
    if (t == 0) return a;
    const FapFrame b = resolve_after(a, frames[k + 1]);
    for (std::size_t i = 2; i < kFapCount; ++i) {
        // A FAP b has and a lacks was first transmitted in b: it starts from
        // neutral (a.values[i] is 0 then).
        if (b.mask[i]) a.values[i] = a.values[i] + (b.values[i] - a.values[i]) * t;
    }
    // Viseme and expression (bits 0 and 1) stay those of a, mask included.
    std::bitset<kFapCount> low_level = b.mask;
    low_level.reset(0).reset(1);
    a.mask |= low_level;
    return a;
}

FapStream resolve_untransmitted(const FapStream& stream) {
    FapStream out = stream;
    for (std::size_t k = 0; k < out.frames.size(); ++k) {
        FapFrame& f = out.frames[k];
        for (std::size_t i = 2; i < kFapCount; ++i)
            if (!f.mask[i]) f.values[i] = 0;
        if (!f.mask[0]) f.viseme = Viseme{};
        if (!f.mask[1]) f.expression = Expression{};
        if (k > 0) take_missing(f, out.frames[k - 1]);
    }
    return out;
}

}  // namespace emoface::fap
