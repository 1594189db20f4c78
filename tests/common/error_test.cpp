// The error forms and the exit-code mapping every command ends with
// (DESIGN.md, "Errors"; README, "Exit codes").
#include "emoface/common/error.h"

#include <functional>
#include <new>
#include <string>

#include <gtest/gtest.h>

namespace emoface {
namespace {

TEST(FileLoc, NamesFileLineAndKeyAsGiven) {
    struct Case {
        FileLoc at;
        const char* text;
    } cases[] = {
        {{"a.fap", 0, ""}, "a.fap"},
        {{"a.fap", 12, ""}, "a.fap:12"},
        {{"w.json", 0, "emotions.anger[2].depth"}, "w.json: emotions.anger[2].depth"},
        {{"w.json", 3, "points"}, "w.json:3: points"},
    };
    for (const Case& c : cases) EXPECT_EQ(c.at.str(), c.text);
}

TEST(FailData, ThrowsTheDataFormAsInputError) {
    try {
        fail_data("fap", FileLoc{"anim.fap", 7, ""}, "7 values", "5");
        FAIL() << "no exception";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "fap: anim.fap:7: expected 7 values, found 5");
    }
}

struct ExitCase {
    const char* name;
    std::function<void()> raise;
    int code;
    const char* line;  // what the command prints after "emoface: "
};

TEST(ExitCode, EachErrorClassMapsToItsCodeAndLine) {
    const ExitCase cases[] = {
        {"bad input", [] { throw InputError("fap: a.fap:3: expected a number, found \"x\""); }, kExitBadInput,
         "fap: a.fap:3: expected a number, found \"x\""},
        {"unclassified Error", [] { throw Error("render: out.png: cannot open for writing"); }, kExitBadInput,
         "render: out.png: cannot open for writing"},
        {"environment", [] { throw EnvironmentError("render: no display"); }, kExitEnvironment,
         "render: no display"},
        {"internal", [] { throw InternalError("render: the bump-mapping program does not link: x"); },
         kExitInternal, "render: the bump-mapping program does not link: x (this is a bug)"},
        {"foreign exception", [] { throw std::logic_error("vector::at"); }, kExitInternal,
         "unexpected exception: vector::at (this is a bug)"},
        {"out of memory", [] { throw std::bad_alloc(); }, kExitInternal,
         "unexpected exception: std::bad_alloc (this is a bug)"},
    };
    EXPECT_EQ(kExitOk, 0);
    for (const ExitCase& c : cases) {
        SCOPED_TRACE(c.name);
        try {
            c.raise();
            ADD_FAILURE() << "no exception";
        } catch (const std::exception& e) {
            EXPECT_EQ(exit_code(e), c.code);
            EXPECT_EQ(error_line(e), c.line);
        }
    }
}

}  // namespace
}  // namespace emoface
