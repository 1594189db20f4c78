#pragma once
// Temporary names next to the destination, renamed into place when complete.
#include <string>

namespace emoface::render::detail {

// A name in the destination's folder that keeps its extension (the image and
// video libraries pick the format from it): dir/.name.tmp-<pid>-<n>.ext
std::string temporary_path_for(const std::string& path);
// Renames `temp` to `path` (same folder, so atomic); removes `temp` and throws
// emoface::Error on failure.
void commit_temporary(const std::string& temp, const std::string& path);
// Removes `temp` if it exists; never throws.
void discard_temporary(const std::string& temp) noexcept;

}  // namespace emoface::render::detail
