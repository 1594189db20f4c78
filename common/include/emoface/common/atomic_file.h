#pragma once
// Output files appear whole or not at all: everything is written to a
// temporary name in the destination's folder and renamed into place when
// complete (a rename within one folder is atomic), so neither a reader nor a
// failed run ever leaves half a file behind.
#include <string>
#include <string_view>

namespace emoface {

// Writes `bytes` to `path` that way. Throws InputError
// "module: path: expected a writable file, found <why>" on failure, leaving
// no temporary behind.
void write_file_atomically(const std::string& path, std::string_view bytes, std::string_view module);

// For writers that need a file name of their own (image and video libraries):
// a name beside `path` that keeps its extension, since those libraries pick
// the format from it: dir/.name.tmp-<pid>-<n>.ext
std::string temporary_path_for(const std::string& path);
// Renames `temp` to `path`; on failure removes `temp` and throws the
// InputError above.
void commit_temporary(const std::string& temp, const std::string& path, std::string_view module);
// Removes `temp` if it exists; never throws.
void discard_temporary(const std::string& temp) noexcept;

}  // namespace emoface
