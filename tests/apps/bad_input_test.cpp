// Bad input of every kind the command line reads (issue 12): OBJ faces, FDP
// JSON, Candide-3 .wfm, `--wrinkles` key folders (maps and layouts) and mix
// strings. Each row is the exact line `emoface` prints; every case exits 2
// with that one line (at most 300 characters) well within 10 seconds, and
// leaves no output file behind. FIFOs and /dev/zero stand in for every
// reader: a reader that opened them naively would hang or fill memory.
#include <sys/stat.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::testing::args_with;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;
using Args = std::vector<std::string>;

const Args kFast = {"--size", "64x64", "--wrinkle-size", "256", "--samples", "1"};

struct Case {
    std::string what;     // the row's name in a failure
    Args args;            // after "emoface"
    std::string message;  // the whole line after "emoface: "
};

class BadInput : public ::testing::Test {
protected:
    void SetUp() override { ASSERT_TRUE(fs::create_directory(out_dir())); }

    std::string path(const std::string& name) const { return scratch_.path(name); }
    std::string write(const std::string& name, const std::string& text) const { return scratch_.write(name, text); }
    std::string out_dir() const { return path("out"); }
    std::string fifo(const std::string& name) const {
        EXPECT_EQ(::mkfifo(path(name).c_str(), 0600), 0) << name;
        return path(name);
    }
    std::string link_to(const std::string& name, const std::string& target) const {
        fs::create_symlink(target, path(name));
        return path(name);
    }

    // A small default face written as OBJ + FDP (good.obj, good.fdp.json, ...).
    void make_face() const {
        const CommandResult r = run_emoface(
            {"face", "--out", path("good.obj"), "--resolution", "0.3", "--texture-size", "256"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
    }
    nlohmann::json good_fdp() const { return nlohmann::json::parse(emoface::testing::read_file(path("good.fdp.json"))); }

    // `emoface mix joy` on the face, its picture into out/: what the rows run.
    Args mix_on(const std::string& obj, const std::string& fdp) const {
        return args_with({"mix", "joy", "--face", obj, "--fdp", fdp, "--out", out_dir() + "/x.png"}, kFast);
    }

    void check(const Case& c) const {
        SCOPED_TRACE(c.what);
        emoface::testing::RunOptions options;
        options.timeout_seconds = 10;
        const CommandResult r = run_emoface(c.args, options);
        EXPECT_FALSE(r.timed_out);
        EXPECT_EQ(r.exit_code, 2) << r.err;
        EXPECT_EQ(r.err, "emoface: " + c.message + "\n");
        EXPECT_EQ(r.err.find('\n'), r.err.size() - 1) << "more than one line";
        EXPECT_LE(r.err.size(), 301u);
        EXPECT_TRUE(fs::is_empty(out_dir())) << "left an output file behind";
    }

    emoface::testing::ScratchDir scratch_;
};

TEST_F(BadInput, ObjFaces) {
    make_face();
    const std::string fdp = path("good.fdp.json");
    const std::string good = emoface::testing::read_file(path("good.obj"));
    const std::string floats = "expected a number (within a float's range, 3.4e38), found ";
    const std::string regular = ": expected a regular file of at most 1024 MiB, found ";
    // The face twice over: every triangle a second time on the same edges.
    std::string twice = good;
    std::string faces;
    for (std::size_t at = good.find("\nf "); at != std::string::npos; at = good.find("\nf ", at + 1))
        faces += good.substr(at + 1, good.find('\n', at + 1) - at);
    twice += faces;
    const std::size_t first_extra = std::count(good.begin(), good.end(), '\n') + 1;
    const std::size_t triangles = std::count(faces.begin(), faces.end(), '\n');
    fs::create_directory(path("folder.obj"));
    const Case cases[] = {
        {"float overflow", mix_on(write("ovf.obj", "v 1 2 1e39\n" + good), fdp),
         "expression: " + path("ovf.obj") + ":1: " + floats + "\"1e39\""},
        {"nan", mix_on(write("nan.obj", "v NaN 2 3\n" + good), fdp),
         "expression: " + path("nan.obj") + ":1: " + floats + "\"NaN\""},
        {"escape in a number", mix_on(write("esc.obj", "v 1 2 \x1b[31m\n" + good), fdp),
         "expression: " + path("esc.obj") + ":1: " + floats + "\"\\x1b[31m\""},
        {"empty", mix_on(write("empty.obj", ""), fdp),
         "expression: " + path("empty.obj") + ": expected vertices and faces, found 0 and 0"},
        {"every triangle twice", mix_on(write("twice.obj", twice), fdp),
         "expression: " + path("twice.obj") + ":" + std::to_string(first_extra) +
             ": expected a manifold mesh (each edge in at most two triangles, wound alike), found " +
             std::to_string(triangles / 1000) + "," + std::to_string(triangles % 1000 + 1000).substr(1) + " of " +
             std::to_string(2 * triangles / 1000) + "," + std::to_string(2 * triangles % 1000 + 1000).substr(1) +
             " triangles rejected: complex edges (the first one here)"},
        {"FIFO", mix_on(fifo("fifo.obj"), fdp), "expression: " + path("fifo.obj") + regular + "a FIFO"},
        {"/dev/zero", mix_on(link_to("zero.obj", "/dev/zero"), fdp),
         "expression: " + path("zero.obj") + regular + "a character device"},
        {"folder", mix_on(path("folder.obj"), fdp), "expression: " + path("folder.obj") + regular + "a directory"},
        {"link loop", mix_on(link_to("loop.obj", path("loop.obj")), fdp),
         "expression: " + path("loop.obj") + regular + "a loop of symbolic links"},
    };
    for (const Case& c : cases) check(c);
}

TEST_F(BadInput, FdpFiles) {
    make_face();
    const std::string obj = path("good.obj");
    auto edited = [&](const std::string& name, auto&& edit) {
        nlohmann::json j = good_fdp();
        edit(j);
        return write(name, j.dump());
    };
    const std::string regular = ": expected a regular file of at most 64 MiB, found ";
    const std::string known = "expected a known key (format, version, mesh, name, feature_points, parts, eyeballs, "
                              "welded, jaw_pivot, head_pivot, texture_box, base_colour, frame), found ";
    std::string huge_angle = good_fdp().dump(1);
    huge_angle.replace(huge_angle.find("\"pupil_angle\": ") + 15, 1, "1e999, \"x\": ");
    const std::size_t angle_line = std::count(huge_angle.begin(), huge_angle.begin() + huge_angle.find("1e999"), '\n') + 1;
    const Case cases[] = {
        {"radius a string", mix_on(obj, edited("s.fdp.json", [](auto& j) { j["eyeballs"][0]["radius"] = "12"; })),
         "expression: " + path("s.fdp.json") + ": eyeballs[0].radius: expected a number, found \"12\""},
        {"angle null", mix_on(obj, edited("n.fdp.json", [](auto& j) { j["eyeballs"][1]["iris_angle"] = nullptr; })),
         "expression: " + path("n.fdp.json") + ": eyeballs[1].iris_angle: expected a number, found null"},
        {"angle 1e999", mix_on(obj, write("h.fdp.json", huge_angle)),
         "expression: " + path("h.fdp.json") + ":" + std::to_string(angle_line) +
             ": eyeballs[0].pupil_angle: expected a number, found 1e999, beyond the range of a double"},
        {"pivot beyond float", mix_on(obj, edited("f.fdp.json", [](auto& j) { j["jaw_pivot"][2] = 1e39; })),
         "expression: " + path("f.fdp.json") +
             ": jaw_pivot[2]: expected a number within the range of a float (3.4e38), found 1e+39"},
        {"key with a newline", mix_on(obj, edited("k.fdp.json", [](auto& j) { j["a\nb\x1b"] = 1; })),
         "expression: " + path("k.fdp.json") + ": \"a\\nb\\x1b\": " + known + "\"a\\nb\\x1b\""},
        {"120 KB key", mix_on(obj, edited("l.fdp.json", [](auto& j) { j[std::string(120000, 'k')] = 1; })),
         "expression: " + path("l.fdp.json") + ": \"" + std::string(24, 'k') + "\u2026\": " + known + "\"" +
             std::string(24, 'k') + "\u2026\""},
        {"two feature points of a line at one place",
         mix_on(obj, edited("c.fdp.json", [](auto& j) { j["feature_points"]["4.3"] = j["feature_points"]["4.1"]; })),
         "expression: " + path("c.fdp.json") +
             ": feature_points: expected 4.3 and 4.1 apart (a feature line of the wrinkle morph joins them), found "
             "them at one place seen from the front"},
        {"FAPU points missing",
         mix_on(obj, edited("m.fdp.json", [](auto& j) { j["feature_points"].erase("3.1"); j["feature_points"].erase("8.4"); })),
         "expression: " + path("m.fdp.json") + ": cannot compute FAPU without feature points 3.1, 8.4"},
        {"FIFO", mix_on(obj, fifo("fifo.fdp.json")), "expression: " + path("fifo.fdp.json") + regular + "a FIFO"},
        {"/dev/zero", mix_on(obj, link_to("zero.fdp.json", "/dev/zero")),
         "expression: " + path("zero.fdp.json") + regular + "a character device"},
    };
    for (const Case& c : cases) check(c);
}

TEST_F(BadInput, Candide3Files) {
    auto convert = [&](const std::string& wfm) { return Args{"face", "--candide3", wfm, "--out", out_dir() + "/c.obj"}; };
    const std::string regular = ": expected a regular file of at most 1024 MiB, found ";
    const Case cases[] = {
        {"float overflow", convert(write("o.wfm", "# VERTEX LIST:\n1\n0 1e300 0\n")),
         "expression: " + path("o.wfm") +
             ":3: vertex 0: expected a number (within a float's range, 3.4e38), found \"1e300\""},
        {"no sections", convert(write("j.wfm", "\xff\xfe junk\n")),
         "expression: " + path("j.wfm") + ": no \"# VERTEX LIST:\" section"},
        {"FIFO", convert(fifo("fifo.wfm")), "expression: " + path("fifo.wfm") + regular + "a FIFO"},
        {"/dev/zero", convert(link_to("zero.wfm", "/dev/zero")),
         "expression: " + path("zero.wfm") + regular + "a character device"},
    };
    for (const Case& c : cases) check(c);
}

TEST_F(BadInput, WrinkleKeyFoldersAndLayouts) {
    make_face();
    const CommandResult made = run_emoface({"wrinkles", "--out", path("keys"), "--size", "256", "--face",
                                            path("good.obj")});
    ASSERT_EQ(made.exit_code, 0) << made.err;
    // A copy of the folder with one file replaced by `make(path)`.
    int copies = 0;
    auto folder_with = [&](const std::string& file, auto&& make) {
        const std::string dir = path("keys" + std::to_string(++copies));
        fs::copy(path("keys"), dir);
        fs::remove(dir + "/" + file);
        make(dir + "/" + file);
        return dir;
    };
    auto mix_with = [&](const std::string& dir) {
        return args_with({"mix", "joy", "--face", path("good.obj"), "--wrinkles", dir, "--out", out_dir() + "/x.png"},
                         kFast);
    };
    const std::string png = "AU17.png", layout = "AU17.layout.json";
    const std::string whole = emoface::testing::read_file(path("keys/" + png));
    auto text = [](const std::string& t) { return [t](const std::string& p) { std::ofstream(p) << t; }; };
    auto as_fifo = [](const std::string& p) { ::mkfifo(p.c_str(), 0600); };
    auto as_zero = [](const std::string& p) { fs::create_symlink("/dev/zero", p); };
    auto as_folder = [](const std::string& p) { fs::create_directory(p); };
    std::vector<std::string> dirs;
    auto dir_for = [&](const std::string& file, auto&& make) {
        dirs.push_back(folder_with(file, make));
        return dirs.back();
    };
    const std::string d1 = dir_for(png, text(whole.substr(0, 3000)));
    const std::string d2 = dir_for(png, as_fifo);
    const std::string d3 = dir_for(png, as_zero);
    const std::string d4 = dir_for(png, as_folder);
    const std::string d5 = dir_for(png, text("hello\n"));
    const std::string d6 = dir_for(layout, text(R"({"points": {"2.1": [1e39, 0]}})"));
    const std::string d7 = dir_for(layout, as_fifo);
    const std::string d8 = dir_for(layout, as_zero);
    const std::string d9 = dir_for(layout, text("{\"points\": [\n"));
    const std::string d10 = dir_for(layout, text("{\"points\": {\"2.1\\n\\u001b\": [0, 0]}}"));
    const Case cases[] = {
        {"truncated PNG", mix_with(d1),
         "render: " + d1 + "/" + png + ": expected a whole image file, found a PNG cut short after 3000 bytes (no IEND chunk)"},
        {"PNG a FIFO", mix_with(d2),
         "render: " + d2 + "/" + png + ": expected a regular file of at most 1024 MiB, found a FIFO"},
        {"PNG /dev/zero", mix_with(d3),
         "render: " + d3 + "/" + png + ": expected a regular file of at most 1024 MiB, found a character device"},
        {"PNG a folder", mix_with(d4),
         "render: " + d4 + "/" + png + ": expected a regular file of at most 1024 MiB, found a directory"},
        {"PNG of text", mix_with(d5), "render: " + d5 + "/" + png + ": cannot read the image: Not a PNG file"},
        {"layout beyond float", mix_with(d6),
         "expression: " + d6 + "/" + layout +
             ": points.\"2.1\"[0]: expected a number within the range of a float (3.4e38), found 1e+39"},
        {"layout a FIFO", mix_with(d7),
         "expression: " + d7 + "/" + layout + ": expected a regular file of at most 64 MiB, found a FIFO"},
        {"layout /dev/zero", mix_with(d8),
         "expression: " + d8 + "/" + layout + ": expected a regular file of at most 64 MiB, found a character device"},
        {"layout cut short", mix_with(d9),
         "expression: " + d9 + "/" + layout +
             ":2: points[0]: expected valid JSON, found syntax error while parsing value - unexpected end of input; "
             "expected '[', '{', or a literal"},
        {"layout key with a newline", mix_with(d10),
         "expression: " + d10 + "/" + layout +
             ": points.\"2.1\\n\\x1b\": expected an MPEG-4 feature point id as the key, found \"2.1\\n\\x1b\""},
    };
    for (const Case& c : cases) check(c);
}

TEST_F(BadInput, MixStrings) {
    const std::string names =
        "expected joy (or happiness), sadness, anger, fear, disgust, surprise, neutral or an action unit (AU4, AU12L)";
    auto mix = [&](const std::string& text) { return args_with({"mix", text, "--out", out_dir() + "/x.png"}, kFast); };
    const std::string huge(120000, 'x');
    const std::string cut40 = std::string(40, 'x') + "\u2026";
    const Case cases[] = {
        {"newline", mix("joy\n+ fear\x1b[31m"),
         "expression: emotion mix \"joy\\n+ fear\\x1b[31m\": unknown emotion \"fear\\x1b[31m\" in part 2; " + names},
        {"120 KB name", mix(huge),
         "expression: emotion mix \"" + std::string(60, 'x') + "\u2026\": unknown emotion \"" + cut40 + "\" in part 1; " + names},
        {"inf", mix("anger=inf"), "expression: emotion mix \"anger=inf\": part 1 (\"anger=inf\"): \"inf\" is not a number"},
        {"UTF-8 junk", mix("\xff\xfe"),
         "expression: emotion mix \"\\xff\\xfe\": unknown emotion \"\\xff\\xfe\" in part 1; " + names},
    };
    for (const Case& c : cases) check(c);
}

}  // namespace
