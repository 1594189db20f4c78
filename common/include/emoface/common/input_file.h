#pragma once
// Files the user names are untrusted: every reader (OBJ, FDP and data JSON,
// Candide-3, FAP, images) checks them here first, so a FIFO never blocks a
// reader, /dev/zero never fills memory, and a huge file is refused before a
// byte of it is read. Failures are one line in the data form:
//   module: FILE: expected a regular file of at most 64 MiB, found a FIFO
#include <cstdint>
#include <string>
#include <string_view>

namespace emoface {

inline constexpr std::uint64_t kMiB = std::uint64_t(1) << 20;

// Limits per kind of input, far above any real file of that kind.
inline constexpr std::uint64_t kMaxJsonFileBytes = 64 * kMiB;    // data files, FDP, layouts: KBs
inline constexpr std::uint64_t kMaxMeshFileBytes = 1024 * kMiB;  // OBJ, .wfm: 10 million vertices
inline constexpr std::uint64_t kMaxImageFileBytes = 1024 * kMiB;  // 8192^2 RGBA half float is 512 MiB

// Throws InputError "module: path: expected a regular file of at most N MiB,
// found ..." unless `path` (symbolic links followed) is a regular file of at
// most `max_bytes`: found no such file, a directory, a FIFO, a character or
// block device, a socket, a loop of symbolic links, or a file of M MiB.
// For readers that must hand the path to a library (images).
void check_input_file(const std::string& path, std::uint64_t max_bytes, std::string_view module);

// The whole file, after the same checks, made on the opened file itself (a
// FIFO is opened without blocking and refused; a file that grows past the
// limit while being read is refused too). Unreadable: "expected a readable
// file, found <reason>".
std::string read_input_file(const std::string& path, std::uint64_t max_bytes, std::string_view module);

}  // namespace emoface
