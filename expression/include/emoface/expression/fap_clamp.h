#pragma once
// What the rig's clamp to the human FAP ranges (FapRanges) will do to a FAP
// file, found before anything is rendered, so that a command can say it once.
#include <cstddef>
#include <string>
#include <utility>
#include <vector>

#include "emoface/expression/rig.h"
#include "emoface/fap/fap_stream.h"

namespace emoface::expression {

struct ClampedFap {
    int fap = 0;
    std::size_t values = 0;  // frames in which it is beyond its range
    // Runs of consecutive frames [first, last], by index from 0 (as play
    // --frames and inspect --frame count), in order.
    std::vector<std::pair<std::size_t, std::size_t>> runs;
};

struct ClampSummary {
    std::size_t values = 0;       // over every frame and FAP
    std::vector<ClampedFap> faps;  // most clamped values first, then by FAP number
    bool empty() const { return values == 0; }
};

// Scans each frame of `stream` with the untransmitted-FAP rule applied (what
// the rig is given) against `ranges`.
ClampSummary summarize_clamping(const fap::FapStream& stream, const FapRanges& ranges);

// "846 FAP values beyond the face's range clamped (thrust_jaw in frames 2-13,
// 17-39 etc., raise_b_midlip in frames 20-37, and 3 more FAPs)": a FAP's runs
// after the first two, and the FAPs that do not fit `max_chars`, are left out
// as "etc." and "and N more FAPs". Empty for an empty summary.
std::string describe_clamping(const ClampSummary& summary, std::size_t max_chars = 240);

}  // namespace emoface::expression
