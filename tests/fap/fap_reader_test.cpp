// The reader on hand-made inputs: every accepted style, and a table of bad
// inputs with the exact message each must produce.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/fap/fap_io.h"
#include "fap_test_util.h"
#include "support/expect_error.h"

namespace emoface::fap {
namespace {

using test::mask_line;

// The message parse_fap throws for `text` ("(no error)" when it parses).
std::string error_of(const std::string& text) {
    return emoface::testing::thrown_message<InputError>([&] { parse_fap(text, "t.fap"); });
}

// Two frames: FAP 3 and 31 in both, FAP 2 (6 values) in the second.
const std::string kCanonical = "2.1 anim 25 2\n" + mask_line({3, 31}) + "\n0 10 -20\n" +
                               mask_line({2, 3, 31}) + "\n1 3 40 0 0 0 0 12.5 -7\n";

TEST(FapReader, Canonical) {
    const FapStream s = parse_fap(kCanonical, "t.fap");
    EXPECT_EQ(s.version, "2.1");
    EXPECT_EQ(s.name, "anim");
    EXPECT_EQ(s.fps, 25);
    ASSERT_EQ(s.frames.size(), 2u);
    EXPECT_TRUE(s.warnings.empty());
    EXPECT_EQ(s.frames[0].number, 0);
    EXPECT_EQ(s.frames[0].get(3), 10);
    EXPECT_EQ(s.frames[0].get(31), -20);
    EXPECT_FALSE(s.frames[0].has(2));
    EXPECT_EQ(s.frames[1].expression, (Expression{3, 40, 0, 0, 0, 0}));
    EXPECT_EQ(s.frames[1].get(3), 12.5);
    EXPECT_EQ(s.frames[1].mask.count(), 3u);
}

// Each variant must read as exactly the canonical stream, with no warning.
struct Variant {
    const char* what;
    std::string text;
};

std::string replace_all(std::string s, const std::string& from, const std::string& to) {
    for (std::size_t p = 0; (p = s.find(from, p)) != std::string::npos; p += to.size())
        s.replace(p, from.size(), to);
    return s;
}

TEST(FapReader, StylesThatReadTheSame) {
    const std::string m1 = mask_line({3, 31}), m2 = mask_line({2, 3, 31});
    const Variant variants[] = {
        {"CRLF", replace_all(kCanonical, "\n", "\r\n")},
        {"lone CR", replace_all(kCanonical, "\n", "\r")},
        {"UTF-8 byte order mark", "\xEF\xBB\xBF" + kCanonical},
        {"tabs", replace_all(kCanonical, " ", "\t")},
        {"trailing spaces and tabs", replace_all(kCanonical, "\n", " \t \n")},
        {"no final newline", kCanonical.substr(0, kCanonical.size() - 1)},
        {"comments and blank lines everywhere",
         "# before the header\n\n   # indented\n2.1 anim 25 2\n#between header and frames\n" + m1 +
             "\n\n# between mask and values\n0 10 -20\n   \n# between frames\n" + m2 +
             "\n1 3 40 0 0 0 0 12.5 -7\n# at the end\n\n"},
        {"mask tokens other than 1", "2.1 anim 25 2\n" + replace_all(m1, "1", "7") + "\n0 10 -20\n" +
                                         replace_all(m2, "1", "-1") + "\n1 3 40 0 0 0 0 12.5 -7\n"},
        {"decimal and signed numbers",
         "2.1 anim 25.0 2\n" + m1 + "\n+0 10.0 -2e1\n" + m2 + "\n1 3 40.0 0 0 0 0 1.25e1 -7.000\n"},
        {"leading spaces", "  2.1 anim 25 2\n  " + m1 + "\n  0 10 -20\n" + m2 + "\n1 3 40 0 0 0 0 12.5 -7\n"},
    };
    const FapStream expected = parse_fap(kCanonical, "t.fap");
    for (const Variant& v : variants) {
        SCOPED_TRACE(v.what);
        const FapStream s = parse_fap(v.text, "t.fap");
        EXPECT_TRUE(same_content(s, expected));
        EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
    }
}

TEST(FapReader, HeaderForms) {
    struct Case {
        std::string header;
        std::string version, name;
        double fps;
    };
    const Case cases[] = {
        {"2.1 C:\\Users\\x\\My Files\\TempFile 25 1", "2.1", "C:\\Users\\x\\My Files\\TempFile", 25},
        {"2.0 jag 5 1", "2.0", "jag", 5},
        {"2.1   name  with   spaces 29.97 1", "2.1", "name  with   spaces", 29.97},
        {"2.1 25 1", "2.1", "", 25},                 // no name
        {"2.1 12 25 1", "2.1", "12", 25},            // a numeric name
        {"2.1\tS100_anger.fap\t10\t1", "2.1", "S100_anger.fap", 10},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.header);
        const FapStream s = parse_fap(c.header + "\n" + mask_line({3}) + "\n0 1\n", "t.fap");
        EXPECT_EQ(s.version, c.version);
        EXPECT_EQ(s.name, c.name);
        EXPECT_EQ(s.fps, c.fps);
        EXPECT_TRUE(s.warnings.empty());
        EXPECT_EQ(s.frames.size(), 1u);
    }
}

TEST(FapReader, HighLevelFapForms) {
    struct Case {
        std::initializer_list<int> mask;
        std::string values;
        Viseme viseme;
        Expression expression;
        double fap3;
    };
    const Case cases[] = {
        {{1}, "0 5", {5, 0, 0, 0}, {}, 0},
        {{1}, "0 5 6 30 1", {5, 6, 30, 1}, {}, 0},
        {{2}, "0 4", {}, {4, 0, 0, 0, 0, 0}, 0},
        {{2}, "0 1 63 6 20 1 0", {}, {1, 63, 6, 20, 1, 0}, 0},
        {{1, 2, 3}, "0 5 4 -9", {5, 0, 0, 0}, {4, 0, 0, 0, 0, 0}, -9},
        {{1, 2, 3}, "0 5 6 30 1 4 -9", {5, 6, 30, 1}, {4, 0, 0, 0, 0, 0}, -9},
        {{1, 2, 3}, "0 5 1 63 6 20 1 0 -9", {5, 0, 0, 0}, {1, 63, 6, 20, 1, 0}, -9},
        {{1, 2, 3}, "0 5 6 30 1 1 63 6 20 1 0 -9", {5, 6, 30, 1}, {1, 63, 6, 20, 1, 0}, -9},
        {{1, 2, 3}, "0 5.0 6 30 1 1 63.0 6 20 1 0 -9", {5, 6, 30, 1}, {1, 63, 6, 20, 1, 0}, -9},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.values);
        const FapStream s = parse_fap("2.1 a 25 1\n" + mask_line(c.mask) + "\n" + c.values + "\n", "t.fap");
        ASSERT_EQ(s.frames.size(), 1u);
        EXPECT_EQ(s.frames[0].viseme, c.viseme);
        EXPECT_EQ(s.frames[0].expression, c.expression);
        EXPECT_EQ(s.frames[0].get(3), c.fap3);
        EXPECT_TRUE(s.warnings.empty());
    }
}

TEST(FapReader, FrameNumbersAreKeptNotUsedForTiming) {
    std::string text = "2.1 ms 25 3\n";
    for (const char* number : {"0", "40", "1000000000000"})
        text += mask_line({3}) + "\n" + number + " 1\n";
    const FapStream s = parse_fap(text, "t.fap");
    ASSERT_EQ(s.frames.size(), 3u);
    EXPECT_EQ(s.frames[2].number, 1000000000000);
    EXPECT_DOUBLE_EQ(s.duration(), 3.0 / 25);
    EXPECT_TRUE(s.warnings.empty());
}

struct WarningCase {
    const char* what;
    std::string text;
    std::size_t frames;
    std::vector<std::string> warnings;
};

TEST(FapReader, ToleratedWithWarnings) {
    const std::string m3 = mask_line({3});
    const WarningCase cases[] = {
        {"no header", m3 + "\n0 1\n" + m3 + "\n1 2\n", 2,
         {"t.fap:1: no header line `version name fps count`; read as version 2.1 at 25 fps"}},
        {"no header after comments", "# c\n\n" + mask_line({1, 3}, 69) + "\n0 1 2\n", 1,
         {"t.fap:3: no header line `version name fps count`; read as version 2.1 at 25 fps",
          "t.fap:3: mask lines have 69 tokens (Greta's Java writer): the 69th is ignored"}},
        {"fewer frames than declared", "2.1 a 25 3\n" + m3 + "\n0 1\n", 1,
         {"t.fap:1: the header declares 3 frames, found 1"}},
        {"more frames than declared", "2.1 a 25 1\n" + m3 + "\n0 1\n" + m3 + "\n1 1\n", 2,
         {"t.fap:1: the header declares 1 frame, found 2"}},
        {"69-token masks, warned once", "2.1 a 25 2\n" + mask_line({3}, 69) + "\n0 1\n" +
                                            mask_line({3}, 69) + "\n1 1\n",
         2, {"t.fap:2: mask lines have 69 tokens (Greta's Java writer): the 69th is ignored"}},
        {"unknown version", "3.0 a 25 1\n" + m3 + "\n0 1\n", 1,
         {"t.fap:1: version 3.0 is not 2.0 or 2.1; read as 2.1"}},
        {"frame numbers going back", "2.1 a 25 3\n" + m3 + "\n5 1\n" + m3 + "\n3 1\n" + m3 + "\n3 1\n", 3,
         {"t.fap:5: frame 2: frame number 3 does not follow 5; timing follows the order in the file"}},
        {"codes out of range", "2.1 a 25 1\n" + mask_line({1, 2}) + "\n0 15 0 64 0 7 64 -1 0 0 0\n", 1,
         {"t.fap:3: frame 1: viseme_select1 15 is outside 0..14",
          "t.fap:3: frame 1: viseme_blend 64 is outside 0..63",
          "t.fap:3: frame 1: expression_select1 7 is outside 0..6",
          "t.fap:3: frame 1: expression_intensity1 64 is outside 0..63",
          "t.fap:3: frame 1: expression_select2 -1 is outside 0..6"}},
        {"a trailing empty frame (Greta's empty file)",
         "# Empty FAP\r\n2.1 empty 25 1\r\n#\r\n" + mask_line({}) + " \r\n0 \r\n", 0,
         {"t.fap:4: the last frame transmits no FAP: dropped"}},
        {"trailing empty frames after a real one",
         "2.1 a 25 3\n" + m3 + "\n0 1\n" + mask_line({}) + "\n1\n" + mask_line({}) + "\n2\n", 1,
         {"t.fap:4: the last 2 frames transmit no FAP: dropped"}},
    };
    for (const WarningCase& c : cases) {
        SCOPED_TRACE(c.what);
        const FapStream s = parse_fap(c.text, "t.fap");
        EXPECT_EQ(s.frames.size(), c.frames);
        EXPECT_EQ(s.warnings, c.warnings);
    }
}

TEST(FapReader, EmptyFramesInsideAStreamAreKept) {
    const std::string text = "2.1 a 25 3\n" + mask_line({3}) + "\n0 1\n" + mask_line({}) + "\n1\n" +
                             mask_line({3}) + "\n2 5\n";
    const FapStream s = parse_fap(text, "t.fap");
    ASSERT_EQ(s.frames.size(), 3u);
    EXPECT_TRUE(s.frames[1].mask.none());
    EXPECT_EQ(s.resolved(1).get(3), 1);
}

TEST(FapReader, WarningsAreCapped) {
    std::string text = "2.1 a 25 100\n";
    for (int i = 0; i < 100; ++i) text += mask_line({2}) + "\n" + std::to_string(i) + " 9\n";
    const FapStream s = parse_fap(text, "t.fap");
    ASSERT_EQ(s.warnings.size(), kMaxWarnings);
    EXPECT_EQ(s.warnings.front(), "t.fap:3: frame 1: expression_select1 9 is outside 0..6");
    EXPECT_EQ(s.warnings.back(), "... and 69 more warnings");
}

struct BadCase {
    const char* what;
    std::string text;
    const char* message;
};

// The exact message for each malformed input.
TEST(FapReader, BadInputs) {
    const std::string m3 = mask_line({3}), m31 = mask_line({31, 32});
    const std::string h = "2.1 anim 25 1\n";
    const BadCase cases[] = {
        {"empty file", "", "fap: t.fap:1: expected a header line `version name fps count`, found end of file"},
        {"only comments", "# a\n\n# b\n",
         "fap: t.fap:4: expected a header line `version name fps count`, found end of file"},
        {"one word", "hello\n", "fap: t.fap:1: expected a header `version name fps count`, found 'hello'"},
        {"two tokens", "2.1 25\n", "fap: t.fap:1: expected a header `version name fps count`, found '2.1 25'"},
        {"not a version", "v2.1 anim 25 10\n",
         "fap: t.fap:1: expected a header `version name fps count`, found 'v2.1 anim 25 10'"},
        {"count missing", "2.1 anim 25\n",
         "fap: t.fap:1: expected a frame rate from 0.001 to 1000000 as the header's second-to-last field, found 'anim'"},
        {"zero fps", "2.1 anim 0 10\n",
         "fap: t.fap:1: expected a frame rate from 0.001 to 1000000 as the header's second-to-last field, found '0'"},
        {"nan fps", "2.1 anim nan 10\n",
         "fap: t.fap:1: expected a frame rate from 0.001 to 1000000 as the header's second-to-last field, found 'nan'"},
        {"negative fps", "2.1 anim -25 10\n",
         "fap: t.fap:1: expected a frame rate from 0.001 to 1000000 as the header's second-to-last field, found '-25'"},
        {"word count", "2.1 anim 25 ten\n",
         "fap: t.fap:1: expected a frame count (an integer >= 0) as the header's last field, found 'ten'"},
        {"fractional count", "2.1 anim 25 1.5\n",
         "fap: t.fap:1: expected a frame count (an integer >= 0) as the header's last field, found '1.5'"},
        {"negative count", "2.1 anim 25 -1\n",
         "fap: t.fap:1: expected a frame count (an integer >= 0) as the header's last field, found '-1'"},
        {"2 GB count", "2.1 anim 25 2147483648\n",
         "fap: t.fap:1: expected a frame count of at most 1000000, found 2147483648"},
        {"count beyond 64 bits", "2.1 anim 25 99999999999999999999\n",
         "fap: t.fap:1: expected a frame count (an integer >= 0) as the header's last field, found '99999999999999999999'"},
        {"mask of 67", h + mask_line({3}, 67) + "\n0 1\n",
         "fap: t.fap:2: frame 1: expected a mask of 68 tokens (69 from Greta's Java writer), found 67"},
        {"mask of 70", h + mask_line({3}, 70) + "\n0 1\n",
         "fap: t.fap:2: frame 1: expected a mask of 68 tokens (69 from Greta's Java writer), found 70"},
        {"non-numeric mask token", h + "0 0 0 0 x " + mask_line({}, 63) + "\n0\n",
         "fap: t.fap:2: frame 1: expected a mask token (0 or 1) for FAP 5, found 'x'"},
        {"nan mask token", h + "nan " + mask_line({}, 67) + "\n0\n",
         "fap: t.fap:2: frame 1: expected a mask token (0 or 1) for FAP 1, found 'nan'"},
        {"mask then end of file", h + m3 + "\n# nothing follows\n",
         "fap: t.fap:2: frame 1: expected a values line after this mask line, found end of file"},
        {"too few values", h + m31 + "\n0 10\n",
         "fap: t.fap:3: frame 1: expected 3 tokens (the frame number and 2 values for the low-level FAPs the mask sets), found 2"},
        {"too many values", h + m31 + "\n0 10 20 30\n",
         "fap: t.fap:3: frame 1: expected 3 tokens (the frame number and 2 values for the low-level FAPs the mask sets), found 4"},
        {"FAP 1 with 2 values", h + mask_line({1, 31}) + "\n0 1 2 3\n",
         "fap: t.fap:3: frame 1: expected 3 or 6 tokens (the frame number, FAP 1 as 1 or 4 values and 1 value for the low-level FAPs the mask sets), found 4"},
        {"FAP 2 with 3 values", h + mask_line({2}) + "\n0 1 2 3\n",
         "fap: t.fap:3: frame 1: expected 2 or 7 tokens (the frame number, FAP 2 as 1 or 6 values and 0 values for the low-level FAPs the mask sets), found 4"},
        {"FAP 1 and 2 with 2 values", h + mask_line({1, 2}) + "\n0 1\n",
         "fap: t.fap:3: frame 1: expected 3, 6, 8 or 11 tokens (the frame number, FAP 1 as 1 or 4 values, FAP 2 as 1 or 6 values and 0 values for the low-level FAPs the mask sets), found 2"},
        {"fractional frame number", h + m3 + "\n1.5 7\n",
         "fap: t.fap:3: frame 1: expected a frame number (an integer >= 0), found '1.5'"},
        {"negative frame number", h + m3 + "\n-1 7\n",
         "fap: t.fap:3: frame 1: expected a frame number (an integer >= 0), found '-1'"},
        {"word value", h + m31 + "\n0 10 abc\n",
         "fap: t.fap:3: frame 1: expected a number for FAP 32 raise_r_i_eyebrow, found 'abc'"},
        {"half a number", h + m31 + "\n0 10 12x\n",
         "fap: t.fap:3: frame 1: expected a number for FAP 32 raise_r_i_eyebrow, found '12x'"},
        {"comma decimal", h + m31 + "\n0 1,5 2\n",
         "fap: t.fap:3: frame 1: expected a number for FAP 31 raise_l_i_eyebrow, found '1,5'"},
        {"hex value", h + m31 + "\n0 0x10 2\n",
         "fap: t.fap:3: frame 1: expected a number for FAP 31 raise_l_i_eyebrow, found '0x10'"},
        {"+- value", h + m31 + "\n0 +-1 2\n",
         "fap: t.fap:3: frame 1: expected a number for FAP 31 raise_l_i_eyebrow, found '+-1'"},
        {"nan value", h + m31 + "\n0 nan 2\n",
         "fap: t.fap:3: frame 1: expected a finite number for FAP 31 raise_l_i_eyebrow, found 'nan'"},
        {"inf value", h + m31 + "\n0 1 -inf\n",
         "fap: t.fap:3: frame 1: expected a finite number for FAP 32 raise_r_i_eyebrow, found '-inf'"},
        {"overflowing value", h + m31 + "\n0 1e999 2\n",
         "fap: t.fap:3: frame 1: expected a finite number for FAP 31 raise_l_i_eyebrow, found '1e999'"},
        {"fractional viseme", h + mask_line({1}) + "\n0 2.5\n",
         "fap: t.fap:3: frame 1: expected an integer for viseme_select1, found '2.5'"},
        {"huge expression field", h + mask_line({2}) + "\n0 1 1e12 0 0 0 0\n",
         "fap: t.fap:3: frame 1: expected an integer for expression_intensity1, found '1e12'"},
        {"second frame truncated mid-values", "2.1 anim 25 2\n" + m31 + "\n0 1 2\n" + m31 + "\n1 1",
         "fap: t.fap:5: frame 2: expected 3 tokens (the frame number and 2 values for the low-level FAPs the mask sets), found 2"},
        {"truncated mid-mask", "2.1 anim 25 2\n" + m31 + "\n0 1 2\n" + m31.substr(0, 50),
         "fap: t.fap:4: frame 2: expected a mask of 68 tokens (69 from Greta's Java writer), found 25"},
        {"binary junk", std::string("\x7f" "ELF\x02\x01\x01\0\0\0", 10),
         "fap: t.fap:1: expected a header `version name fps count`, found '\\x7fELF\\x02\\x01\\x01\\x00\\x00\\x00'"},
        {"junk after the header", h + std::string("\xff\xfe\x00\x01 garbage", 12),
         "fap: t.fap:2: frame 1: expected a mask of 68 tokens (69 from Greta's Java writer), found 2"},
        {"long token", h + m31 + "\n0 1 " + std::string(100, 'z') + "\n",
         "fap: t.fap:3: frame 1: expected a number for FAP 32 raise_r_i_eyebrow, found 'zzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzz...'"},
        {"quote in token", "it's a header\n",
         "fap: t.fap:1: expected a header `version name fps count`, found 'it\\x27s a header'"},
    };
    for (const BadCase& c : cases) {
        SCOPED_TRACE(c.what);
        EXPECT_EQ(error_of(c.text), c.message);
    }
}

TEST(FapReader, HugeLinesCostNoMemory) {
    // A values line of a million tokens is an error, reported by count.
    std::string values = "0";
    for (int i = 0; i < 1000000; ++i) values += " 1";
    EXPECT_EQ(error_of("2.1 a 25 1\n" + mask_line({3}) + "\n" + values + "\n"),
              "fap: t.fap:3: frame 1: expected 2 tokens (the frame number and 1 value for the "
              "low-level FAPs the mask sets), found 1000001");
}

TEST(FapReader, MissingFile) {
    try {
        read_fap_file("/nonexistent/x.fap");
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "fap: /nonexistent/x.fap: expected a regular file of at most 256 MiB, found no such file");
    }
    try {
        read_fap_file(EMOFACE_TEST_SOURCE_DIR);
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "fap: " EMOFACE_TEST_SOURCE_DIR ": expected a regular file of at most 256 MiB, found a directory");
    }
}

}  // namespace
}  // namespace emoface::fap
