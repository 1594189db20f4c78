#pragma once
// A FAP stream: what a FAP file holds, and how to ask it for the face at a
// time.
//
// Timing: frame k of `frames` is shown at time k / fps, whatever its
// `number` says (files number from 0 or 1, with gaps, or in milliseconds).
// Frame k lasts until frame k + 1, the last one for 1 / fps, so a stream of
// n frames lasts n / fps seconds.
//
// Untransmitted FAPs (the rule every module follows): a FAP that a frame's
// mask does not transmit keeps the value it was last transmitted with in an
// earlier frame of the stream. A FAP not transmitted yet is at its neutral
// value 0 and stays out of the mask. FAP 1 (viseme) and FAP 2 (expression)
// follow the same rule as whole structs.
#include <cstddef>
#include <string>
#include <vector>

#include "emoface/fap/fap_frame.h"

namespace emoface::fap {

struct FapStream {
    std::string version = "2.1";  // as the header gave it: "2.1", "2.0"
    std::string name;
    double fps = 25;
    std::vector<FapFrame> frames;
    // What the reader tolerated (file:line: what), for `emoface info`; at most
    // kMaxWarnings entries, the last one counting any further ones.
    std::vector<std::string> warnings;

    // frames.size() / fps.
    double duration() const;
    // k / fps.
    double frame_time(std::size_t k) const;
    // Frame k with the untransmitted-FAP rule applied: every FAP transmitted
    // in frames 0..k has its latest value, and the mask tells which ones
    // those are. O(k) in the worst case; resolve_untransmitted() does a whole
    // stream in one pass. Throws emoface::Error when k is out of range.
    FapFrame resolved(std::size_t k) const;
    // The face at `seconds`: the resolved frames around that time, low-level
    // values interpolated linearly (a FAP not yet transmitted counts as 0).
    // Viseme and expression are codes and step: they come from the earlier
    // frame. Before 0 it gives frame 0, from the last frame's time on the
    // last frame (held), and for an empty stream a neutral frame with an
    // empty mask. `number` is that of the earlier frame. Throws
    // emoface::Error when seconds is not finite or fps is not positive.
    FapFrame sample(double seconds) const;
};

inline constexpr std::size_t kMaxWarnings = 32;

// Every frame resolved (see FapStream::resolved), in one pass.
FapStream resolve_untransmitted(const FapStream& stream);

}  // namespace emoface::fap
