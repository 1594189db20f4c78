#include "emoface/expression/fap_clamp.h"

#include <algorithm>

#include <fmt/format.h>

namespace emoface::expression {

ClampSummary summarize_clamping(const fap::FapStream& stream, const FapRanges& ranges) {
    const fap::FapStream resolved = fap::resolve_untransmitted(stream);
    std::vector<ClampedFap> by_fap(fap::kFapCount);
    ClampSummary out;
    for (std::size_t k = 0; k < resolved.frames.size(); ++k) {
        const auto& values = resolved.frames[k].values;
        for (int f = 3; f <= fap::kFapCount; ++f) {
            const double v = values[std::size_t(f - 1)];
            if (v >= ranges.min(f) && v <= ranges.max(f)) continue;
            ClampedFap& c = by_fap[std::size_t(f - 1)];
            c.fap = f;
            ++c.values;
            ++out.values;
            if (!c.runs.empty() && c.runs.back().second + 1 == k) c.runs.back().second = k;
            else c.runs.emplace_back(k, k);
        }
    }
    for (ClampedFap& c : by_fap)
        if (c.values > 0) out.faps.push_back(std::move(c));
    std::stable_sort(out.faps.begin(), out.faps.end(),
                     [](const ClampedFap& a, const ClampedFap& b) { return a.values > b.values; });
    return out;
}

namespace {

std::string run_text(const std::pair<std::size_t, std::size_t>& r) {
    return r.first == r.second ? fmt::format("{}", r.first) : fmt::format("{}-{}", r.first, r.second);
}

// "raise_b_midlip in frames 12-80, 95, ..." with at most `max_runs` runs.
std::string fap_text(const ClampedFap& c, std::size_t max_runs) {
    const bool one = c.runs.size() == 1 && c.runs[0].first == c.runs[0].second;
    std::string s = fmt::format("{} in frame{} ", fap::fap_info(c.fap).name, one ? "" : "s");
    for (std::size_t i = 0; i < c.runs.size() && i < max_runs; ++i) s += (i ? ", " : "") + run_text(c.runs[i]);
    if (c.runs.size() > max_runs) s += " etc.";
    return s;
}

}  // namespace

std::string describe_clamping(const ClampSummary& summary, std::size_t max_chars) {
    if (summary.empty()) return "";
    const std::string head = fmt::format("{} FAP value{} beyond the face's range clamped (", summary.values,
                                         summary.values == 1 ? "" : "s");
    std::string list;
    std::size_t shown = 0;
    for (const ClampedFap& c : summary.faps) {
        const std::string first = fap_text(c, 2), only = fap_text(c, 1);
        const std::string sep = shown ? ", " : "";
        // Room kept for ", and 99 more FAPs)" when FAPs are left out.
        const std::size_t room = max_chars > head.size() + 19 ? max_chars - head.size() - 19 : 0;
        if (list.size() + sep.size() + first.size() <= room) list += sep + first;
        else if (list.size() + sep.size() + only.size() <= room || shown == 0) list += sep + only;
        else break;
        ++shown;
    }
    if (shown < summary.faps.size()) list += fmt::format(", and {} more FAP{}", summary.faps.size() - shown,
                                                         summary.faps.size() - shown == 1 ? "" : "s");
    return head + list + ")";
}

}  // namespace emoface::expression
