// `emoface face` end to end: the built binary writes a face that loads back.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <sys/wait.h>
#include <unistd.h>

#include "emoface/expression/face_io.h"

namespace emoface::expression {
namespace {

struct CliResult {
    int code;
    std::string output;
};

CliResult run(const std::string& args) {
    const std::string cmd = std::string(EMOFACE_BINARY) + " " + args + " 2>&1";
    FILE* p = popen(cmd.c_str(), "r");
    CliResult r{-1, {}};
    if (!p) return r;
    char buf[512];
    while (std::fgets(buf, sizeof buf, p)) r.output += buf;
    const int status = pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

TEST(FaceCommand, WritesObjMaterialPngAndFdpThatLoadBack) {
    const auto dir = std::filesystem::temp_directory_path() / ("emoface_face_cli_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    const std::string obj = (dir / "face.obj").string();
    const CliResult r = run("face --out " + obj + " --resolution 0.3 --texture-size 64");
    ASSERT_EQ(r.code, 0) << r.output;
    EXPECT_NE(r.output.find("feature points in " + (dir / "face.fdp.json").string()), std::string::npos) << r.output;
    for (const char* name : {"face.obj", "face.mtl", "face.png", "face.fdp.json"})
        EXPECT_TRUE(std::filesystem::exists(dir / name)) << name;
    const Face face = load_obj_with_fdp(obj, (dir / "face.fdp.json").string());
    EXPECT_TRUE(missing_feature_points(face).empty());
    EXPECT_EQ(face.eyeballs.size(), 2u);
    EXPECT_EQ(face.base_colour_file, (dir / "face.png").string());

    const CliResult bad = run("face --out " + (dir / "face.txt").string());
    EXPECT_EQ(bad.code, 2);
    EXPECT_NE(bad.output.find("face: --out must name an .obj file"), std::string::npos) << bad.output;
    EXPECT_FALSE(std::filesystem::exists(dir / "face.txt"));
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace emoface::expression
