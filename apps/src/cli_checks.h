#pragma once
// What every command checks in its options before any slow work (README,
// "Exit codes"): numbers finite and in range after conversion, sizes, and
// output paths that can be written. Each failure is an InputError of one
// line starting "COMMAND: OPTION ...". Built in every build (face and info
// use it too), so it lives apart from session.h.
#include <cmath>
#include <string>
#include <type_traits>
#include <utility>

#include <fmt/format.h>

#include "emoface/common/error.h"
#include "emoface/common/output_batch.h"

namespace emoface::apps {

// Throws "COMMAND: OPTION VALUE: expected LO..HI<what>" unless
// lo <= value <= hi (NaN and infinities never are).
template <typename T>
void check_in_range(const std::string& command, const std::string& option, T value, T lo, T hi,
                    const std::string& what = "") {
    static_assert(std::is_arithmetic_v<T>);
    if (!(value >= lo && value <= hi))
        fail<InputError>("{}: {} {}: expected {}..{}{}", command, option, value, lo, hi, what);
}

// Parses "WIDTHxHEIGHT", each side lo..hi (digits only: no sign, no blanks,
// no wrap-around); InputError "COMMAND: OPTION 'TEXT': expected ...".
std::pair<int, int> parse_size(const std::string& text, const std::string& command,
                               const std::string& option = "--size", int lo = 16, int hi = 8192);

// One output file of a command, as an OutputBatch of one: made when the
// options are checked (so a folder that cannot be written fails before any
// loading, and a missing one is made), written at path(), moved into place
// by commit(); a command that fails before commit() leaves nothing behind.
class OutputFile {
public:
    // InputError "COMMAND: OPTION PATH: ..." for an empty path, a folder
    // where the file should be, or a folder that cannot be written.
    OutputFile(const std::string& path, const std::string& command, const std::string& option = "--out");
    // Where to write it (in the staging folder, same file name).
    const std::string& path() const { return staged_; }
    // The user's path.
    const std::string& destination() const { return destination_; }
    OutputBatch& batch() { return batch_; }
    void commit() { batch_.commit(); }

private:
    std::string destination_;
    OutputBatch batch_;
    std::string staged_;
};

// The folder of `path` ("" for a bare file name) and its file name; throws
// "COMMAND: OPTION PATH: expected a file name, found ..." for "", a path
// ending in '/' or naming "." or "..".
std::pair<std::string, std::string> split_output_path(const std::string& path, const std::string& command,
                                                      const std::string& option);

}  // namespace emoface::apps
