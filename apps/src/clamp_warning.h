#pragma once
// The one warning a command gives when a FAP file goes beyond what the face
// can do (the rig clamps it; data/expression/fap_ranges.json). Built in every
// build (info uses it too), so it lives apart from session.h.
#include <string>

#include "emoface/fap/fap_stream.h"

namespace emoface::apps {

// The warning line for `stream` read from `path`, without "emoface: ": e.g.
// "play: anim.fap: 3 FAP values beyond the face's range clamped (raise_b_midlip
// in frames 4-6); --no-clamp keeps them", at most 300 characters with that
// prefix. "" when nothing is clamped, or when `data_dir` has no
// expression/fap_ranges.json (the command's loading then says so).
std::string clamp_warning(const std::string& command, const std::string& path, const fap::FapStream& stream,
                          const std::string& data_dir);
// Prints clamp_warning on stderr as one "emoface: ..." line, unless it is "".
void warn_clamped_faps(const std::string& command, const std::string& path, const fap::FapStream& stream,
                       const std::string& data_dir);

}  // namespace emoface::apps
