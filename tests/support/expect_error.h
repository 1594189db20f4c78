#pragma once
// The one check that code throws a given error type with an exact message
// (Magnum's style: the whole message is the contract, not a fragment of it).
#include <string>

#include <gtest/gtest.h>

namespace emoface::testing {

// The message `fn` throws as E; "(no error)" when it returns, and
// "(another exception: ...)" when it throws something that is not an E.
template <class E, class Fn>
std::string thrown_message(Fn&& fn) {
    try {
        fn();
    } catch (const E& e) {
        return e.what();
    } catch (const std::exception& e) {
        return std::string("(another exception: ") + e.what() + ")";
    }
    return "(no error)";
}

// Fails the test, at the caller's line, unless `fn` throws E with exactly
// `message`. (__builtin_FILE/LINE: GCC and Clang fill in the call site.)
template <class E, class Fn>
void expect_error(Fn&& fn, const std::string& message, const char* file = __builtin_FILE(),
                  int line = __builtin_LINE()) {
    const std::string got = thrown_message<E>(fn);
    if (got != message)
        ADD_FAILURE_AT(file, line) << "expected the error\n  " << message << "\ngot\n  " << got;
}

}  // namespace emoface::testing
