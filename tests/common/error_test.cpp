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

TEST(EchoInput, EscapesControlsAndCutsLongText) {
    struct Case {
        std::string text;
        std::size_t max;
        std::string shown;
    } cases[] = {
        {"anger", 60, "anger"},
        {"a\nb\tc\rd", 60, "a\\nb\\tc\\rd"},
        {"\x1b[31mred", 60, "\\x1b[31mred"},
        {std::string("nul\0x", 5), 60, "nul\\x00x"},
        {"caf\xc3\xa9 \xe2\x80\x9cq\xe2\x80\x9d", 60, "caf\xc3\xa9 \xe2\x80\x9cq\xe2\x80\x9d"},  // UTF-8 kept
        {"bad \xff\xc3(", 60, "bad \\xff\\xc3("},  // not UTF-8: escaped bytes
        {"\xc2\x85", 60, "\\xc2\\x85"},           // a C1 control
        {"abcdef", 3, "abc\u2026"},
        {"\xc3\xa9\xc3\xa9\xc3\xa9", 2, "\xc3\xa9\xc3\xa9\u2026"},  // whole characters
        {std::string(120000, 'k'), 60, std::string(60, 'k') + "\u2026"},
    };
    for (const Case& c : cases) EXPECT_EQ(echo_input(c.text, c.max), c.shown) << c.text.substr(0, 30);
}

TEST(ErrorLine, IsOneLineOfAtMostTheLimit) {
    const std::string long_key(5000, 'k');
    const InputError e("expression: f.json: " + long_key + ": expected a known key, found \"x\"\nsecond line");
    const std::string line = error_line(e);
    EXPECT_LE(line.size(), kMaxErrorLine);
    EXPECT_EQ(line.find('\n'), std::string::npos);
    EXPECT_EQ(line.rfind("expression: f.json: kkk", 0), 0u) << line;
    const std::string end = "found \"x\"\\nsecond line";
    EXPECT_EQ(line.substr(line.size() - end.size()), end) << line;
    EXPECT_EQ(error_line(InternalError(std::string(1000, 'z'))).size(), kMaxErrorLine);
}

}  // namespace
}  // namespace emoface
