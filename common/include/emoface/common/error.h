#pragma once
// The one exception type of the project. Messages name the module and what
// failed where, with expected and found values:
//   "fap: anim.fap:12: frame 3 has 5 values, mask asks for 7"
// Apps catch it, print the message on one line and exit non-zero.
#include <stdexcept>
#include <string>
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

template <typename E = Error, typename... Args>
[[noreturn]] void fail(fmt::format_string<Args...> format, Args&&... args) {
    throw E(fmt::format(format, std::forward<Args>(args)...));
}

}  // namespace emoface
