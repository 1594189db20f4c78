// The writer: what it writes reads back as the same stream; what the format
// cannot carry is refused; files are replaced whole.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/fap/fap_io.h"
#include "fap_test_util.h"

namespace emoface::fap {
namespace {

FapStream random_stream(std::mt19937& rng) {
    std::uniform_int_distribution<int> count(0, 40), fap(1, kFapCount), code(0, 63), pick(0, 5);
    std::uniform_real_distribution<double> real(-5000, 5000);
    FapStream s;
    s.version = pick(rng) == 0 ? "2.0" : "2.1";
    const char* names[] = {"", "a", "C:\\Users\\x y\\TempFile", "name with  spaces", "tab\there", "12 13"};
    s.name = names[pick(rng)];
    const double rates[] = {25, 10, 29.97, 0.5, 1000, 1.0 / 3.0};
    s.fps = rates[pick(rng)];
    long long number = pick(rng) == 0 ? 1000 : 0;
    s.frames.resize(static_cast<std::size_t>(count(rng)));
    for (FapFrame& f : s.frames) {
        f.number = number;
        number += 1 + pick(rng);  // gaps
        for (int n = count(rng); n > 0; --n) {
            const int k = fap(rng);
            if (k == 1) {
                f.set_viseme({code(rng) % 15, code(rng) % 15, code(rng), pick(rng) & 1});
            } else if (k == 2) {
                f.set_expression({code(rng) % 7, code(rng), code(rng) % 7, code(rng), pick(rng) & 1, 0});
            } else {
                // Integers, decimals, tiny and huge magnitudes, negative zero.
                switch (pick(rng)) {
                    case 0: f.set(k, std::round(real(rng))); break;
                    case 1: f.set(k, real(rng)); break;
                    case 2: f.set(k, real(rng) * 1e-300); break;
                    case 3: f.set(k, real(rng) * 1e250); break;
                    case 4: f.set(k, -0.0); break;
                    default: f.set(k, 1.0 / 3.0); break;
                }
            }
        }
    }
    // The reader drops trailing frames that transmit nothing.
    while (!s.frames.empty() && s.frames.back().mask.none()) s.frames.pop_back();
    return s;
}

TEST(FapRoundTrip, GeneratedStreams) {
    std::mt19937 rng(2024);
    for (int trial = 0; trial < 200; ++trial) {
        SCOPED_TRACE(trial);
        const FapStream s = random_stream(rng);
        const std::string text = format_fap(s);
        const FapStream back = parse_fap(text, "gen.fap");
        ASSERT_TRUE(same_content(s, back)) << text.substr(0, 300);
        EXPECT_TRUE(back.warnings.empty());
    }
}

TEST(FapRoundTrip, MaskComesFromTheMaskNotFromValues) {
    FapStream s;
    s.frames.resize(1);
    s.frames[0].set(3, 0);        // transmitted zero: written
    s.frames[0].values[30] = 55;  // not transmitted: not written
    s.frames[0].set(40, 7);
    const std::string text = format_fap(s);
    EXPECT_EQ(text, "2.1 25 1\n" + test::mask_line({3, 40}) + "\n0 0 7\n");
    const FapStream back = parse_fap(text, "t.fap");
    EXPECT_TRUE(back.frames[0].has(3));
    EXPECT_FALSE(back.frames[0].has(31));
}

TEST(FapRoundTrip, ExactText) {
    FapStream s;
    s.version = "2.0";
    s.name = "tour";
    s.fps = 12.5;
    s.frames.resize(1);
    s.frames[0].number = 4;
    s.frames[0].set_viseme({3, 0, 0, 0});
    s.frames[0].set_expression({1, 63, 0, 0, 0, 0});
    s.frames[0].set(31, -12.25);
    EXPECT_EQ(format_fap(s), "2.0 tour 12.5 1\n" + test::mask_line({1, 2, 31}) +
                                 "\n4 3 0 0 0 1 63 0 0 0 0 -12.25\n");
}

TEST(FapRoundTrip, WriterRefusesWhatTheFormatCannotCarry) {
    struct Case {
        const char* what;
        FapStream stream;
        const char* message;
    };
    const auto with = [](auto change) {
        FapStream s;
        s.frames.resize(1);
        s.frames[0].set(3, 1);
        change(s);
        return s;
    };
    std::string numeric_name;
    for (int i = 0; i < 65; ++i) numeric_name += (i ? " " : "") + std::to_string(i);
    const Case cases[] = {
        {"line break in name", with([](FapStream& s) { s.name = "a\nb"; }),
         "fap: format_fap: expected a name without line breaks or leading and trailing spaces, found 'a\\x0ab'"},
        {"outer space", with([](FapStream& s) { s.name = " a"; }),
         "fap: format_fap: expected a name without line breaks or leading and trailing spaces, found ' a'"},
        {"version", with([](FapStream& s) { s.version = "two"; }),
         "fap: format_fap: expected a version such as 2.1, found 'two'"},
        {"fps", with([](FapStream& s) { s.fps = 0; }),
         "fap: format_fap: expected a frame rate from 0.001 to 1000000, found 0"},
        {"nan fps", with([](FapStream& s) { s.fps = std::nan(""); }),
         "fap: format_fap: expected a frame rate from 0.001 to 1000000, found nan"},
        {"negative number", with([](FapStream& s) { s.frames[0].number = -2; }),
         "fap: format_fap: frame 1: expected a frame number >= 0, found -2"},
        {"infinite value", with([](FapStream& s) { s.frames[0].set(31, std::numeric_limits<double>::infinity()); }),
         "fap: format_fap: frame 1: expected a finite value for FAP 31 raise_l_i_eyebrow, found inf"},
        {"name that reads as a mask", with([&](FapStream& s) { s.name = numeric_name; }),
         "fap: format_fap: expected a name that is not 65 numbers (the header would read as a mask line), found '0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16...'"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        try {
            format_fap(c.stream);
            ADD_FAILURE();
        } catch (const InputError& e) {
            EXPECT_STREQ(e.what(), c.message);
        }
    }
}

std::string slurp(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

TEST(FapRoundTrip, WriteFileReplacesWholeAndLeavesNoTemporary) {
    namespace fs = std::filesystem;
    const fs::path dir = fs::temp_directory_path() / ("emoface_fap_write_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::string path = (dir / "out.fap").string();
    {
        std::ofstream old(path);
        old << "old content";
    }
    FapStream s;
    s.name = "w";
    s.frames.resize(2);
    s.frames[0].set(3, 1);
    s.frames[1].number = 1;
    s.frames[1].set(4, 2);
    write_fap_file(s, path);
    EXPECT_EQ(slurp(path), format_fap(s));
    EXPECT_TRUE(same_content(read_fap_file(path), s));

    // A stream the writer refuses leaves the old file as it was.
    FapStream bad = s;
    bad.fps = -1;
    EXPECT_THROW(write_fap_file(bad, path), InputError);
    EXPECT_EQ(slurp(path), format_fap(s));
    // A folder that does not exist.
    EXPECT_THROW(write_fap_file(s, (dir / "no" / "x.fap").string()), InputError);

    std::size_t entries = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++entries;
    EXPECT_EQ(entries, 1u);
    fs::remove_all(dir);
}

// for_xface (fap_io.h): what Xface's reader needs, on generated streams:
// a one-token name, a whole frame rate, frames numbered 0..n-1, integer
// values, masks that never drop a FAP; at a whole rate, each frame as
// emoface resolves it, rounded.
TEST(ForXface, GeneratedStreams) {
    std::mt19937 rng(77);
    for (int trial = 0; trial < 200; ++trial) {
        SCOPED_TRACE(trial);
        FapStream s = random_stream(rng);
        if (s.frames.empty()) continue;
        for (FapFrame& f : s.frames)
            for (std::size_t i = 2; i < kFapCount; ++i) f.values[i] = std::clamp(f.values[i], -1e6, 1e6);
        const FapStream x = for_xface(s);
        EXPECT_FALSE(x.name.empty());
        EXPECT_EQ(x.name.find_first_of(" \t\r\n"), std::string::npos) << x.name;
        EXPECT_EQ(x.fps, std::max(1.0, std::round(s.fps)));
        const FapStream back = parse_fap(format_fap(x), "x.fap");
        ASSERT_TRUE(same_content(x, back));
        const FapStream resolved = resolve_untransmitted(s);
        if (x.fps == s.fps) ASSERT_EQ(x.frames.size(), s.frames.size());
        for (std::size_t k = 0; k < x.frames.size(); ++k) {
            const FapFrame& f = x.frames[k];
            EXPECT_EQ(f.number, static_cast<long long>(k));
            if (k > 0) EXPECT_EQ((x.frames[k - 1].mask & ~f.mask).none(), true) << "frame " << k;
            for (std::size_t i = 2; i < kFapCount; ++i) {
                if (!f.mask[i]) continue;
                EXPECT_EQ(f.values[i], std::round(f.values[i]));
                EXPECT_FALSE(std::signbit(f.values[i]) && f.values[i] == 0) << "-0 at FAP " << i + 1;
                if (x.fps == s.fps) EXPECT_EQ(f.values[i], std::round(resolved.frames[k].values[i]) + 0.0);
            }
            if (x.fps == s.fps) EXPECT_EQ(f.mask, resolved.frames[k].mask);
        }
    }
}

TEST(ForXface, NamesRatesAndRefusals) {
    struct Case {
        std::string name, expected;
    };
    for (const Case& c : std::vector<Case>{{"my take", "my_take"},
                                           {"  a \t b  ", "a_b"},
                                           {"", "emoface"},
                                           {" \t ", "emoface"},
                                           {"C:\\Users\\x y\\TempFile", "C:\\Users\\x_y\\TempFile"},
                                           {std::string(300, 'x'), std::string(254, 'x')},
                                           // Not cut inside a two-byte UTF-8 letter.
                                           {std::string(253, 'x') + "\xc3\xa9", std::string(253, 'x')}}) {
        FapStream s;
        s.name = c.name;
        s.frames.resize(1);
        s.frames[0].set(3, 1);
        EXPECT_EQ(for_xface(s).name, c.expected) << c.name;
    }
    // 12.5 fps for 5 frames (0.4 s) plays at 13 fps: 5 frames, each the
    // stream sampled at its time.
    FapStream s;
    s.fps = 12.5;
    for (int k = 0; k < 5; ++k) {
        s.frames.emplace_back();
        s.frames.back().number = 1 + 2 * k;
        s.frames.back().set(3, 100.0 * k);
    }
    const FapStream x = for_xface(s);
    EXPECT_EQ(x.fps, 13);
    ASSERT_EQ(x.frames.size(), 5u);
    for (std::size_t k = 0; k < 5; ++k) {
        EXPECT_EQ(x.frames[k].number, static_cast<long long>(k));
        EXPECT_EQ(x.frames[k].get(3), std::round(s.sample(double(k) / 13).get(3))) << k;
    }
    // A rate under 1 plays at 1.
    s.fps = 0.2;
    EXPECT_EQ(for_xface(s).fps, 1);
    EXPECT_EQ(for_xface(s).frames.size(), 25u);

    FapStream empty;
    EXPECT_THROW(for_xface(empty), InputError);
    FapStream huge;
    huge.frames.resize(1);
    huge.frames[0].set(3, 1e12);
    EXPECT_THROW(for_xface(huge), InputError);
}

}  // namespace
}  // namespace emoface::fap
