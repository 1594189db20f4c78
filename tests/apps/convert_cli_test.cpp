// `emoface convert` and `emoface info` on capture files, end to end: the
// built binary on CSVs written here, the FAP files it writes read back and
// held to Xface's reader's rules, round trips through the command, every
// command's --data reaching the capture tables, and bad input (one line,
// exit 2, no file).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "emoface/fap/fap_io.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;
using emoface::testing::read_file;

const std::string kTour = std::string(EMOFACE_DATA_DIR) + "/fap/tour.fap";

const char* const kShapes[] = {
    "EyeBlinkLeft",     "EyeLookDownLeft",    "EyeLookInLeft",       "EyeLookOutLeft",    "EyeLookUpLeft",
    "EyeSquintLeft",    "EyeWideLeft",        "EyeBlinkRight",       "EyeLookDownRight",  "EyeLookInRight",
    "EyeLookOutRight",  "EyeLookUpRight",     "EyeSquintRight",      "EyeWideRight",      "JawForward",
    "JawLeft",          "JawRight",           "JawOpen",             "MouthClose",        "MouthFunnel",
    "MouthPucker",      "MouthLeft",          "MouthRight",          "MouthSmileLeft",    "MouthSmileRight",
    "MouthFrownLeft",   "MouthFrownRight",    "MouthDimpleLeft",     "MouthDimpleRight",  "MouthStretchLeft",
    "MouthStretchRight", "MouthRollLower",    "MouthRollUpper",      "MouthShrugLower",   "MouthShrugUpper",
    "MouthPressLeft",   "MouthPressRight",    "MouthLowerDownLeft",  "MouthLowerDownRight", "MouthUpperUpLeft",
    "MouthUpperUpRight", "BrowDownLeft",      "BrowDownRight",       "BrowInnerUp",       "BrowOuterUpLeft",
    "BrowOuterUpRight", "CheekPuff",          "CheekSquintLeft",     "CheekSquintRight",  "NoseSneerLeft",
    "NoseSneerRight",   "TongueOut"};

// One second at 30 rows a second: a smile growing, brows down, the head turning.
std::string live_link_csv() {
    std::string out = "Timecode,BlendShapeCount";
    for (const char* s : kShapes) out += std::string(",") + s;
    out += ",HeadYaw,HeadPitch,HeadRoll,LeftEyeYaw,LeftEyePitch,LeftEyeRoll,RightEyeYaw,RightEyePitch,RightEyeRoll\n";
    for (int i = 0; i < 30; ++i) {
        out += fmt::format("12:00:00:{:02}.000,61", i);
        for (const std::string s : kShapes) {
            double w = 0;
            if (s == "MouthSmileLeft" || s == "MouthSmileRight") w = i / 29.0;
            if (s == "BrowDownLeft" || s == "BrowDownRight") w = 0.6;
            out += fmt::format(",{}", w);
        }
        out += fmt::format(",{},0,0,0,0,0,0,0,0\n", 0.01 * i);
    }
    return out;
}

// OpenFace 2.0 with leading spaces in its header, a lost row.
std::string openface_csv() {
    std::string out = "frame, face_id, timestamp, confidence, success, gaze_angle_x, gaze_angle_y, pose_Rx, pose_Ry, "
                      "pose_Rz, AU01_r, AU02_r, AU04_r, AU06_r, AU12_r, AU26_r\n";
    for (int i = 0; i < 25; ++i)
        out += fmt::format("{}, 0, {:.2f}, 0.97, {}, 0.1, 0, 0, 0.1, 0, {:.2f}, {:.2f}, 0, 0, 0, 1\n", i + 1, i * 0.04,
                           i == 10 ? 0 : 1, i * 0.2, i * 0.1);
    return out;
}

// Xface's FAP reader as rules: "" when `text` meets them, else the first it
// breaks. Written from Xface 1.0's FAPFile::open (XFace/src/XFace/FapFile.cpp,
// Xface Core Library, ITC-irst / FBK 2004-2008, Koray Balci, MPL 1.1; read
// in the copy at github.com/copperdong/Xface, and checked against the real
// Xface files below). That reader pulls whitespace-separated tokens with
// istream >>, so line ends (LF, CRLF) and trailing spaces do not matter, and:
//  - it skips a line starting with '#' only when it peeks at a line's start:
//    before the header; after it, it peeks at the newline ending the last
//    token and reads the '#' as a number, which fails;
//  - the header is four tokens: the version into a float, the name into a
//    char[255] (one token of at most 254 bytes: a name with a space shifts
//    the frame rate onto its second word), the frame rate into a short (the
//    2008 version: a float cast to short, so 12.5 plays as 12), the count;
//  - per frame, 68 mask integers (non-zero = transmitted), the frame number,
//    which indexes the table of `count` frames unchecked (0..count-1, each
//    once: a missing one stays neutral), then one value per transmitted FAP,
//    4 for FAP 1 (viseme) and 6 for FAP 2 (expression) read with atoi;
//  - low-level values go through atof, which would take decimals, but
//    MPEG-4's FAP values are integers and so are Xface's own files: required.
// `as_emoface_plays` adds that no frame drops a FAP an earlier frame
// transmitted: Xface reads an untransmitted FAP as 0 where emoface holds it.
std::string xface_problem(const std::string& text, bool as_emoface_plays) {
    std::size_t pos = 0;
    while (pos < text.size() && text[pos] == '#') {
        const std::size_t end = text.find('\n', pos);
        pos = end == std::string::npos ? text.size() : end + 1;
    }
    std::vector<std::string> tokens;
    std::istringstream in(text.substr(pos));
    for (std::string t; in >> t;) tokens.push_back(t);
    const auto whole = [](const std::string& t, bool sign) {
        const std::size_t from = sign && !t.empty() && t[0] == '-' ? 1 : 0;
        return t.size() > from && std::all_of(t.begin() + std::ptrdiff_t(from), t.end(), [](char c) {
                   return c >= '0' && c <= '9';
               });
    };
    if (tokens.size() < 4) return "a header of 4 tokens (version name fps count)";
    char* end = nullptr;
    std::strtod(tokens[0].c_str(), &end);
    if (*end != '\0') return "a version that reads as a float, found " + tokens[0];
    if (tokens[1].size() > 254) return "a name of at most 254 bytes";
    if (!whole(tokens[2], false) || std::stol(tokens[2]) < 1 || std::stol(tokens[2]) > 32767)
        return "a whole frame rate of 1..32767 (one-word name), found " + tokens[2];
    if (!whole(tokens[3], false)) return "a whole frame count, found " + tokens[3];
    const long count = std::stol(tokens[3]);
    for (std::size_t i = 2; i < tokens.size(); ++i)
        if (tokens[i].find('#') != std::string::npos) return "no '#' past the header's start";
    std::size_t t = 4;
    std::vector<bool> held(68, false);
    for (long k = 0; k < count; ++k) {
        if (tokens.size() < t + 69) return fmt::format("frame {}: 68 mask tokens and a number, found the end", k);
        std::vector<bool> mask(68);
        for (int i = 0; i < 68; ++i, ++t) {
            if (!whole(tokens[t], false)) return fmt::format("frame {}: mask integers, found {}", k, tokens[t]);
            mask[std::size_t(i)] = std::stol(tokens[t]) != 0;
            if (as_emoface_plays && held[std::size_t(i)] && !mask[std::size_t(i)])
                return fmt::format("frame {}: FAP {} transmitted as before (Xface reads it as 0)", k, i + 1);
            held[std::size_t(i)] = held[std::size_t(i)] || mask[std::size_t(i)];
        }
        if (tokens[t] != std::to_string(k)) return fmt::format("frame {} numbered {}, found {}", k, k, tokens[t]);
        ++t;
        for (int i = 0; i < 68; ++i) {
            if (!mask[std::size_t(i)]) continue;
            const std::size_t n = i == 0 ? 4 : i == 1 ? 6 : 1;
            if (tokens.size() < t + n) return fmt::format("frame {}: FAP {}'s values, found the end", k, i + 1);
            for (std::size_t j = 0; j < n; ++j, ++t)
                if (!whole(tokens[t], true))
                    return fmt::format("frame {}: FAP {}: an integer, found {}", k, i + 1, tokens[t]);
        }
    }
    if (t != tokens.size()) return fmt::format("nothing after frame {}, found {} more tokens", count - 1, tokens.size() - t);
    return "";
}

// A FAP file as people write them by hand: comments, a name with spaces, a
// fractional frame rate, frames numbered from 1 with gaps, decimals, masks
// that change (FAP 19 and 20 sent once, then held).
std::string hand_fap() {
    const auto mask = [](std::vector<int> faps) {
        std::string m;
        for (int f = 1; f <= 68; ++f)
            m += std::string(std::find(faps.begin(), faps.end(), f) != faps.end() ? "1" : "0") + (f < 68 ? " " : "\n");
        return m;
    };
    return "# a blink and a smile\n2.1 my smile take 12.5 4\n" + mask({3, 12, 13, 19, 20}) + "1 10.4 20 20.6 512 512\n" +
           mask({3, 12, 13}) + "3 12 40 40.25\n" + mask({12, 13}) + "5 80 80\n" + mask({12, 13, 19, 20}) +
           "7 120 120 0 0\n";
}

class ConvertCli : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }
    std::string write(const std::string& name, const std::string& text) const { return scratch_.write(name, text); }
    emoface::testing::ScratchDir scratch_;
};

TEST_F(ConvertCli, CapturesBecomeFapFilesThatInfoReads) {
    for (const auto& [name, text, format, fps, frames] :
         std::vector<std::tuple<std::string, std::string, std::string, double, std::size_t>>{
             {"take.csv", live_link_csv(), "Live Link Face CSV", 30, 30},
             {"openface.csv", openface_csv(), "OpenFace 2.0 CSV", 25, 25}}) {
        const std::string in = write(name, text), out = path(name + ".fap");
        CommandResult r = run_emoface({"convert", in, out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find(fmt::format("({}, {} frames at {:g} fps) -> {} (FAP)", format, frames, fps, out)),
                  std::string::npos)
            << r.out;
        // The FAP reader takes it without a warning (Xface's and Greta's rules:
        // header, 68-token masks, values in FAP order).
        const emoface::fap::FapStream s = emoface::fap::read_fap_file(out);
        EXPECT_TRUE(s.warnings.empty()) << s.warnings[0];
        EXPECT_EQ(s.frames.size(), frames);
        EXPECT_EQ(s.fps, fps);
        r = run_emoface({"info", "--json", out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const nlohmann::json j = nlohmann::json::parse(r.out);
        EXPECT_EQ(j[0]["frames"], frames);
        EXPECT_EQ(j[0]["format"], "FAP");
        // info reads the capture itself too, naming its format.
        r = run_emoface({"info", "--json", in});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_EQ(nlohmann::json::parse(r.out)[0]["format"], format);
    }
}

TEST_F(ConvertCli, InfoShowsTheCapturedAus) {
    const CommandResult r = run_emoface({"info", write("take.csv", live_link_csv())});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("  format    Live Link Face CSV"), std::string::npos) << r.out;
    // The smile and the lowered brows (their peaks).
    EXPECT_NE(r.out.find("1 AU12"), std::string::npos) << r.out;
    EXPECT_NE(r.out.find("0.6 AU4"), std::string::npos) << r.out;
}

TEST_F(ConvertCli, RoundTripsThroughEveryFormat) {
    // FAP -> ARKit CSV -> FAP -> OpenFace CSV -> FAP: the face's AUs survive
    // within 0.05 of FACS E (what the formats share: the AU layer).
    const std::string in = write("take.csv", live_link_csv());
    ASSERT_EQ(run_emoface({"convert", in, path("a.fap")}).exit_code, 0);
    CommandResult r = run_emoface({"convert", path("a.fap"), path("b.csv"), "--to", "arkit"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(run_emoface({"convert", path("b.csv"), path("c.fap")}).exit_code, 0);
    r = run_emoface({"convert", path("c.fap"), path("d.csv"), "--to", "openface"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    ASSERT_EQ(run_emoface({"convert", path("d.csv"), path("e.fap")}).exit_code, 0);
    for (const char* f : {"a.fap", "c.fap", "e.fap"}) {
        r = run_emoface({"info", "--json", "--frame", "29", path(f)});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const nlohmann::json aus = nlohmann::json::parse(r.out)[0]["action_units"]["intensities"];
        EXPECT_NEAR(aus.value("AU12L", 0.0), 1.0, 0.05) << f << " " << aus.dump();
        EXPECT_NEAR(aus.value("AU4R", 0.0), 0.6, 0.05) << f << " " << aus.dump();
    }
    // FAP -> FAP plays the same: every frame as emoface resolves it (the
    // tour's values are whole already), at the same rate, under the name
    // with '_' for its spaces.
    ASSERT_EQ(run_emoface({"convert", kTour, path("tour.fap")}).exit_code, 0);
    const emoface::fap::FapStream tour = emoface::fap::resolve_untransmitted(emoface::fap::read_fap_file(kTour));
    const emoface::fap::FapStream back = emoface::fap::read_fap_file(path("tour.fap"));
    EXPECT_EQ(back.name, "emoface_tour");
    EXPECT_EQ(back.fps, tour.fps);
    ASSERT_EQ(back.frames.size(), tour.frames.size());
    for (std::size_t k = 0; k < tour.frames.size(); ++k) {
        emoface::fap::FapFrame expected = tour.frames[k];
        expected.number = static_cast<long long>(k);
        EXPECT_EQ(back.frames[k], expected) << "frame " << k;
    }
}

TEST_F(ConvertCli, TheFapFilesItWritesMeetXfacesReader) {
    // The rules first bite on what they should: they take the real Xface
    // files and refuse each broken rule.
    const fs::path realdata = fs::path(EMOFACE_REALDATA_DIR) / "fap";
    int real = 0;
    for (const char* name : {"xface_joy.fap", "xface_anger.fap", "xface_beg.fap", "xface_test.fap"})
        if (fs::exists(realdata / name)) {
            ++real;
            EXPECT_EQ(xface_problem(read_file(realdata / name), false), "") << name;
        }
    if (real == 0) std::fprintf(stderr, "note: no real Xface files in %s: the rules go unchecked on them\n", realdata.c_str());
    const std::string mask = [] {
        std::string m;
        for (int f = 1; f <= 68; ++f) m += f == 3 ? "1 " : "0 ";
        return m + "\n";
    }();
    for (const auto& [text, problem] : std::vector<std::pair<std::string, std::string>>{
             {"2.1 a 25 1\n" + mask + "0 7\n", ""},
             {"# c\n#\n2.1 a 25 1\r\n" + mask + "0 7 \r\n", ""},
             {"2.1 a b 25 1\n" + mask + "0 7\n", "a whole frame rate of 1..32767 (one-word name), found b"},
             {"2.1 a 12.5 1\n" + mask + "0 7\n", "a whole frame rate of 1..32767 (one-word name), found 12.5"},
             {"2.1 a 25 1\n#\n" + mask + "0 7\n", "no '#' past the header's start"},
             {"2.1 a 25 1\n" + mask + "1 7\n", "frame 0 numbered 0, found 1"},
             {"2.1 a 25 1\n" + mask + "0 7.5\n", "frame 0: FAP 3: an integer, found 7.5"},
             {"2.1 a 25 2\n" + mask + "0 7\n", "frame 1: 68 mask tokens and a number, found the end"},
             {"2.1 a 25 1\n" + mask + "0 7 8\n", "nothing after frame 0, found 1 more tokens"},
         })
        EXPECT_EQ(xface_problem(text, false), problem) << text;
    // A frame that stops transmitting FAP 3: Xface reads it, as 0 there.
    std::string dropped = "2.1 a 25 2\n" + mask + "0 7\n";
    for (int f = 1; f <= 68; ++f) dropped += "0 ";
    dropped += "\n1\n";
    EXPECT_EQ(xface_problem(dropped, false), "");
    EXPECT_EQ(xface_problem(dropped, true), "frame 1: FAP 3 transmitted as before (Xface reads it as 0)");

    // convert's FAP files meet them, from every kind of input, and play as
    // emoface plays the input: each frame transmits what it holds.
    struct Case {
        std::string name, text, format;
        double fps;
        std::size_t frames;
        std::string note;
    };
    for (const Case& c : std::vector<Case>{
             {"take.csv", live_link_csv(), "Live Link Face CSV", 30, 30, ""},
             {"openface.csv", openface_csv(), "OpenFace 2.0 CSV", 25, 25, ""},
             {"tour.fap", read_file(kTour), "FAP", 25, 50, ""},
             {"hand.fap", hand_fap(), "FAP", 13, 4, ", resampled at 13 fps: Xface reads whole frame rates"}}) {
        const std::string in = write(c.name, c.text), out = path(c.name + ".out.fap");
        const CommandResult r = run_emoface({"convert", in, out});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        EXPECT_NE(r.out.find(fmt::format("-> {} (FAP{})\n", out, c.note)), std::string::npos) << r.out;
        const std::string text = read_file(out);
        EXPECT_EQ(xface_problem(text, true), "") << c.name << ":\n" << text.substr(0, 2000);
        const emoface::fap::FapStream s = emoface::fap::read_fap_file(out);
        EXPECT_TRUE(s.warnings.empty()) << c.name << ": " << s.warnings[0];
        EXPECT_EQ(s.fps, c.fps) << c.name;
        EXPECT_EQ(s.frames.size(), c.frames) << c.name;
    }
    // The hand-written file at 13 fps: frame 0 rounded (10.4 -> 10), the
    // blink held through frame 2; frame 3, at 3/13 s, lies 0.885 of the way
    // from its frame 2 (smile 80, blink 512) to frame 3 (120, 0).
    const emoface::fap::FapStream hand = emoface::fap::read_fap_file(path("hand.fap.out.fap"));
    EXPECT_EQ(hand.name, "my_smile_take");
    EXPECT_EQ(hand.frames.front().get(3), 10);
    EXPECT_EQ(hand.frames.front().get(19), 512);
    EXPECT_EQ(hand.frames.back().get(3), 12);
    EXPECT_EQ(hand.frames.back().get(12), 115);
    EXPECT_EQ(hand.frames.back().get(19), 59);
}

// Every command that reads an animation file takes the AU and ARKit tables
// from its --data: a folder whose arkit.json is broken fails each of them,
// naming that file.
TEST_F(ConvertCli, EveryCommandReadsCapturesWithItsDataFolder) {
    const fs::path data = fs::path(scratch_.dir()) / "data";
    fs::create_directories(data / "expression");
    for (const auto& e : fs::directory_iterator(EMOFACE_DATA_DIR))
        if (e.path().filename() != "expression") fs::create_directory_symlink(e.path(), data / e.path().filename());
    for (const auto& e : fs::directory_iterator(fs::path(EMOFACE_DATA_DIR) / "expression"))
        if (e.path().filename() != "arkit.json") fs::create_symlink(e.path(), data / "expression" / e.path().filename());
    const std::string broken = (data / "expression" / "arkit.json").string();
    write("data/expression/arkit.json", "{\"shapes\": 5}\n");
    const std::string take = write("take.csv", live_link_csv());
    for (const std::vector<std::string>& args : std::vector<std::vector<std::string>>{
             {"play", take, "--out", path("x.mp4")},
             {"play", take},
             {"view", take},
             {"inspect", take, "--out", path("x.png")},
             {"info", take},
             {"convert", take, path("x.fap")}}) {
        const bool draws = args[0] == "play" || args[0] == "view" || args[0] == "inspect";
        if (draws && !EMOFACE_DRAWS) continue;  // this build has no drawing commands
        std::vector<std::string> with_data = args;
        with_data.insert(with_data.end(), {"--data", data.string()});
        const CommandResult r = run_emoface(with_data, emoface::testing::without_display());
        EXPECT_EQ(r.exit_code, 2) << args[0] << ": " << r.out << r.err;
        EXPECT_NE(r.err.find(broken), std::string::npos) << args[0] << ": " << r.err;
    }
}

TEST_F(ConvertCli, BadInputIsOneLineAndNoFile) {
    const std::string truncated = live_link_csv().substr(0, live_link_csv().size() - 30);
    struct Case {
        std::vector<std::string> args;
        std::string message;
    };
    const std::string in = write("take.csv", live_link_csv());
    const std::string cut = write("cut.csv", truncated);
    const std::string other = write("points.csv", "x,y,z\n1,2,3\n");
    const std::vector<Case> cases{
        {{"convert", cut, path("out.fap")},
         "emoface: capture: " + cut + ":31: expected 63 comma-separated fields, as the header on line 1 has, found 50\n"},
        {{"convert", other, path("out.fap")}, "expected a FAP file, or a CSV whose header is OpenFace 2.0's"},
        {{"convert", in, path("out.csv")},
         "emoface: convert: " + path("out.csv") +
             ": a .csv may be an ARKit (Live Link Face) or an OpenFace CSV: say which with --to arkit or --to "
             "openface\n"},
        {{"convert", in, path("out.fap"), "--to", "glb"}, "emoface: convert: --to 'glb': expected fap, arkit or openface\n"},
        {{"convert", in, path("out.txt")}, "expected an output ending in .fap, or --to fap, arkit or openface\n"},
    };
    for (const Case& c : cases) {
        const CommandResult r = run_emoface(c.args);
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_NE(r.err.find(c.message), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        EXPECT_FALSE(fs::exists(path("out.fap")));
        EXPECT_FALSE(fs::exists(path("out.csv")));
    }
}

}  // namespace
