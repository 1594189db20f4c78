// `emoface face` end to end: the built binary writes a face that loads back.
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "emoface/expression/face_io.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace emoface::expression {
namespace {

using emoface::testing::CommandResult;
using emoface::testing::run_emoface;

TEST(FaceCommand, WritesObjMaterialPngAndFdpThatLoadBack) {
    const emoface::testing::ScratchDir scratch;
    const std::string obj = scratch.path("face.obj");
    const CommandResult r = run_emoface({"face", "--out", obj, "--resolution", "0.3", "--texture-size", "64"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("feature points in " + scratch.path("face.fdp.json")), std::string::npos) << r.out;
    for (const char* name : {"face.obj", "face.mtl", "face.png", "face.fdp.json"})
        EXPECT_TRUE(std::filesystem::exists(scratch.path(name))) << name;
    const Face face = load_obj_with_fdp(obj, scratch.path("face.fdp.json"));
    EXPECT_TRUE(missing_feature_points(face).empty());
    EXPECT_EQ(face.eyeballs.size(), 2u);
    EXPECT_EQ(face.base_colour_file, scratch.path("face.png"));

    const CommandResult bad = run_emoface({"face", "--out", scratch.path("face.txt")});
    EXPECT_EQ(bad.exit_code, 2);
    EXPECT_NE(bad.err.find("face: --out must name an .obj file"), std::string::npos) << bad.err;
    EXPECT_FALSE(std::filesystem::exists(scratch.path("face.txt")));
}

}  // namespace
}  // namespace emoface::expression
