#pragma once
// The project's exceptions and their two message forms (DESIGN.md, "Errors"):
//   bad data:   "module: file:line: expected X, found Y"  (or "file: key.path:"
//               for JSON, "file:line: key.path:" when both are known)
//   API misuse: "module: Class::fn(): expected X, got Y"
// Apps catch them, print one line and exit with exit_code(): bad input 2, the
// environment 3, anything else (an internal failure, a bug) 1.
#include <exception>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>

namespace emoface {

class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// Bad input from the user (a file, a mix string, an option): exit code 2.
class InputError : public Error {
public:
    using Error::Error;
};

// The environment lacks something (no display, no GPU): exit code 3.
class EnvironmentError : public Error {
public:
    using Error::Error;
};

// Something that should not fail did (a shader that does not link, a CUDA
// error): the program is wrong, not its input. Exit code 1, "this is a bug".
class InternalError : public Error {
public:
    using Error::Error;
};

template <typename E = Error, typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
    throw E(fmt::format(format, std::forward<Args>(args)...));
}

// Where in an input file a problem is: the file, a line (0: none) and a key
// path inside a structured file ("emotions.anger[2].depth"; empty: none).
struct FileLoc {
    std::string file;
    int line = 0;
    std::string key;

    // "file", "file:12", "file: a.b", "file:12: a.b"
    std::string str() const;
};

// Throws the bad-data form: InputError("module: <at>: expected X, found Y").
[[noreturn]] void fail_data(std::string_view module, const FileLoc& at, std::string_view expected,
                            std::string_view found);

// Untrusted text (a name, a key, a line of a file) as a message quotes it:
// control characters and bytes that are not UTF-8 escaped (\n, \t, \x1b),
// cut after `max_chars` characters with "…" added, so an echo never breaks
// the one-line form or floods the terminal.
std::string echo_input(std::string_view text, std::size_t max_chars = 60);

// The longest line error_line() returns, in bytes ("emoface: " goes before it;
// README promises at most 300).
inline constexpr std::size_t kMaxErrorLine = 290;

enum ExitCode : int { kExitOk = 0, kExitInternal = 1, kExitBadInput = 2, kExitEnvironment = 3 };

// The exit code for an exception that ended a command: InputError (and a
// plain Error) 2, EnvironmentError 3, InternalError and any exception that is
// not an emoface::Error (std::bad_alloc, ...) 1: the program's fault.
int exit_code(const std::exception& e);
// The one line a command prints for it (without the program's name):
// the message, with "this is a bug" for exit code 1; control characters
// escaped and, past kMaxErrorLine bytes, its middle cut out (a backstop: the
// messages themselves echo input through echo_input()).
std::string error_line(const std::exception& e);

}  // namespace emoface
