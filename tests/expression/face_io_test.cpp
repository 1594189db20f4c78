// Faces in files: OBJ + FDP round trip, a user OBJ with UV seams, Candide-3
// (.wfm written here), PNG, and the readers' messages.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <unistd.h>

#include "emoface/common/error.h"
#include "emoface/expression/face_io.h"
#include "emoface/fap/feature_points.h"
#include "support/expect_error.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

using testing::fp;
using testing::test_face;

class FaceFiles : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = std::filesystem::temp_directory_path() /
               ("emoface_face_io_" + std::to_string(::getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    std::string write(const std::string& name, const std::string& text) const {
        std::ofstream(path(name)) << text;
        return path(name);
    }
    std::filesystem::path dir_;
};

TEST_F(FaceFiles, DefaultFaceRoundTripsThroughObjAndFdp) {
    const Face& face = test_face();
    save_obj(face, path("face.obj"), "face.mtl");
    save_fdp(face, path("face.fdp.json"), "face.obj", "face.png");
    // No temporaries left behind.
    int files = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir_)) {
        ++files;
        EXPECT_EQ(e.path().string().find(".tmp"), std::string::npos) << e.path();
    }
    EXPECT_EQ(files, 2);

    const Face back = load_obj_with_fdp(path("face.obj"), path("face.fdp.json"));
    EXPECT_EQ(back.name, face.name);
    ASSERT_EQ(back.vertex_count(), face.vertex_count());
    EXPECT_EQ(back.mesh.n_faces(), face.mesh.n_faces());
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        EXPECT_EQ(back.feature_points[k].present, face.feature_points[k].present);
        EXPECT_EQ(back.feature_points[k].vertex, face.feature_points[k].vertex);
        EXPECT_LT(testing::distance(back.feature_points[k].position, face.feature_points[k].position), 1e-3);
    }
    EXPECT_NEAR(back.fapu.es, face.fapu.es, 1e-6);
    EXPECT_NEAR(back.fapu.mns, face.fapu.mns, 1e-6);
    ASSERT_EQ(back.eyeballs.size(), 2u);
    EXPECT_EQ(back.eyeballs[0].upper_margin, face.eyeballs[0].upper_margin);
    EXPECT_EQ(back.eyeballs[1].vertices.first, face.eyeballs[1].vertices.first);
    EXPECT_EQ(back.parts, face.parts);
    EXPECT_EQ(back.welded, face.welded);
    EXPECT_NEAR(back.jaw_pivot[1], face.jaw_pivot[1], 1e-9);
    EXPECT_NEAR(back.texture_box.max.x, face.texture_box.max.x, 1e-4);
    EXPECT_EQ(back.base_colour_file, path("face.png"));
    const auto t0 = face.mesh.texcoord2D(TriMesh::VertexHandle(1234));
    const auto t1 = back.mesh.texcoord2D(TriMesh::VertexHandle(1234));
    EXPECT_NEAR(t0[0], t1[0], 1e-5);
    EXPECT_NEAR(t0[1], t1[1], 1e-5);

    // The same rig drives it: the reloaded face closes its lids like the original.
    FaceRig rig(back);
    FapValues faps{};
    faps[19 - 1] = 1024;
    const DeformedFace d = rig.deform(faps);
    EXPECT_NEAR(d.feature_points[fp("3.1")][1], d.feature_points[fp("3.3")][1], 1e-3);
}

// A small user face: a quad strip with a UV seam, feature points by vertex
// and by position. Enough for FAPU and the rig.
std::string user_obj() {
    std::string s = "# user face\n";
    // 4 x 4 grid, 60 mm wide, 90 mm high, vertices 0..15 row by row (y down).
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) s += fmt::format("v {} {} {}\n", -30 + 20 * c, 45 - 30 * r, 80 - std::abs(c - 1.5) * 6);
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) s += fmt::format("vt {} {}\n", c / 3.0, 1 - r / 3.0);
    s += "vt 0.99 0.5\n";  // a second coordinate for vertex 5: a seam
    for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) {
            const int a = r * 4 + c + 1, b = a + 1, d = a + 4, e = a + 5;
            const int ta = (a == 6) ? 17 : a;
            s += fmt::format("f {}/{} {}/{} {}/{} {}/{}\n", a, ta, d, d, e, e, b, b);
        }
    return s;
}

std::string user_fdp() {
    return R"({
  "name": "user",
  "feature_points": {
    "3.5": {"vertex": 6}, "3.6": {"vertex": 5},
    "3.1": {"position": [10, 20, 80]}, "3.3": {"position": [10, 10, 80]},
    "9.15": {"vertex": 9}, "2.2": {"vertex": 13},
    "8.3": {"vertex": 14}, "8.4": {"vertex": 12},
    "4.1": {"vertex": 2}
  }
})";
}

TEST_F(FaceFiles, UserObjWithSeamsAndPositionsLoadsAndRigs) {
    // Written mirrored on purpose? No: x = face's left, so the left pupil (3.5)
    // is the vertex with larger x.
    const Face face = load_obj_with_fdp(write("user.obj", user_obj()), write("user.fdp.json", user_fdp()));
    EXPECT_EQ(face.name, "user");
    EXPECT_EQ(face.vertex_count(), 17);  // 16 + one seam copy
    ASSERT_EQ(face.welded.size(), 1u);
    EXPECT_EQ(face.welded[0][0], 5);
    EXPECT_EQ(face.mesh.n_faces(), 18u);
    EXPECT_NEAR(face.fapu.es * 1024, 20.0, 1e-4);  // 3.5.x - 3.6.x
    EXPECT_NEAR(face.fapu.irisd * 1024, 10.0, 1e-4);
    EXPECT_EQ(face.feature_points[fp("3.1")].vertex, -1);
    EXPECT_FALSE(face.has(fp("11.4")));
    FaceRig rig(face);
    EXPECT_TRUE(rig.has_effect(31));
    EXPECT_FALSE(rig.has_effect(23));  // no eyeballs
    EXPECT_FALSE(rig.has_effect(3));   // no chin point
    FapValues faps{};
    faps[31 - 1] = 100;
    const DeformedFace d = rig.deform(faps);
    EXPECT_NEAR(d.feature_points[fp("4.1")][1] - face.position(fp("4.1"))[1], 100 * face.fapu.ens, 1e-4);
}

TEST_F(FaceFiles, ReadersNameTheFileLineAndProblem) {
    const std::string fdp = write("f.fdp.json", user_fdp());
    struct Case {
        std::string obj;
        std::string message;  // after "expression: <obj path>"
    } const objs[] = {
        {"v 1 2\n", ":1: expected \"v x y z\", found 2 numbers"},
        {"v 1 2 x\n", ":1: expected a number (within a float's range, 3.4e38), found \"x\""},
        // Finite doubles that a float (the mesh's type) cannot hold, and NaN/inf spelt several ways.
        {"v 1 2 1e39\n", ":1: expected a number (within a float's range, 3.4e38), found \"1e39\""},
        {"v 1e300 2 3\n", ":1: expected a number (within a float's range, 3.4e38), found \"1e300\""},
        {"v nan 2 3\n", ":1: expected a number (within a float's range, 3.4e38), found \"nan\""},
        {"v 1 -Infinity 3\n", ":1: expected a number (within a float's range, 3.4e38), found \"-Infinity\""},
        {"v 1 2 \x1b[31m\n", ":1: expected a number (within a float's range, 3.4e38), found \"\\x1b[31m\""},
        {"v 1 2 " + std::string(5000, '9') + "x\n",
         ":1: expected a number (within a float's range, 3.4e38), found \"" + std::string(40, '9') + "\u2026\""},
        {"\xff\xfe\x00junk\n", ": expected vertices and faces, found 0 and 0"},
        {"", ": expected vertices and faces, found 0 and 0"},
        // Twice the same triangles: OpenMesh's per-triangle lines become one count.
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\nf 1 2 3\nf 2 4 3\nf 3 2 1\n",
         ":7: expected a manifold mesh (each edge in at most two triangles, wound alike), found 3 of 5 triangles "
         "rejected: complex edges (the first one here)"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 9\n", ":4: vertex index 9 outside the 3 vertices read so far"},
        {"v 0 0 0\nv 1 0 0\nf 1 2\n", ":3: a face needs at least 3 corners, found 2"},
        {"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 a\n", ":4: expected a vertex index, found \"a\""},
        {"# nothing\n", ": expected vertices and faces, found 0 and 0"},
    };
    for (const auto& c : objs) {
        const std::string obj = write("bad.obj", c.obj);
        emoface::testing::expect_error<InputError>([&] { load_obj_with_fdp(obj, fdp); },
                                                   "expression: " + obj + c.message);
    }
    const std::string obj = write("user.obj", user_obj());
    struct FdpCase {
        std::string fdp;
        std::string message;
    } fdps[] = {
        {"{", ":1: expected valid JSON, found syntax error while parsing object key - unexpected end of input; "
              "expected string literal"},
        {"{}", ": feature_points: expected a value, found no such key"},
        {R"({"feature_points": {"12.1": {"vertex": 0}}})",
         ": feature_points.\"12.1\": expected an MPEG-4 feature point id as the key, found \"12.1\""},
        {R"({"feature_points": {"2.1": {"vertex": 99}}})",
         ": feature_points.\"2.1\".vertex: expected an integer in [0, 15], found 99"},
        {R"({"feature_points": {"2.1": {"vertex": 1.5}}})",
         ": feature_points.\"2.1\".vertex: expected an integer in [0, 15], found 1.5"},
        {R"({"feature_points": {"2.1": {"position": [1, 2]}}})",
         ": feature_points.\"2.1\".position: expected an array of 3 numbers, found [1,2]"},
        {R"({"feature_points": {"2.1": 3}})",
         ": feature_points.\"2.1\": expected {\"vertex\": i} or {\"position\": [x, y, z]}, found 3"},
        // Typos: a misspelt key is an error, not a key quietly ignored.
        {R"({"feature_points": {"2.1": {"vertx": 3}}})",
         ": feature_points.\"2.1\": expected {\"vertex\": i} or {\"position\": [x, y, z]}, found {\"vertx\":3}"},
        {R"({"feature_points": {"2.1": {"vertex": 3, "postion": [1, 2, 3]}}})",
         ": feature_points.\"2.1\".postion: expected a known key (vertex, position), found \"postion\""},
        {R"({"feature_points": {}, "jaw_pivto": [0, 0, 0]})",
         ": jaw_pivto: expected a known key (format, version, mesh, name, feature_points, parts, eyeballs, "
         "welded, jaw_pivot, head_pivot, texture_box, base_colour, frame), found \"jaw_pivto\""},
        {R"({"feature_points": {}, "parts": [{"part": "lips", "first": 0, "count": 1}]})",
         ": parts[0].part: expected skin, eyeball_left, eyeball_right, mouth_upper, mouth_lower or tongue, "
         "found \"lips\""},
        // Wrong types and numbers beyond double or float range, at their key path.
        {R"({"feature_points": {}, "eyeballs": [{"vertices": [0, 1], "centre": [0, 0, 0], "radius": "12"}]})",
         ": eyeballs[0].radius: expected a number, found \"12\""},
        {R"({"feature_points": {}, "eyeballs": [{"vertices": [0, 1], "centre": [0, 0, 0], "radius": null}]})",
         ": eyeballs[0].radius: expected a number, found null"},
        {"{\"feature_points\": {},\n \"eyeballs\": [{\"vertices\": [0, 1], \"centre\": [0, 0, 0], \"radius\": 1e999}]}",
         ":2: eyeballs[0].radius: expected a number, found 1e999, beyond the range of a double"},
        {R"({"feature_points": {}, "jaw_pivot": [0, 1e39, 0]})",
         ": jaw_pivot[1]: expected a number within the range of a float (3.4e38), found 1e+39"},
        {R"({"feature_points": {"2.1": {"position": [0, 0, -1e300]}}})",
         ": feature_points.\"2.1\".position[2]: expected a number within the range of a float (3.4e38), found -1e+300"},
        // Keys with control characters or of any length come back escaped and cut.
        {"{\"feature_points\": {}, \"bad\\nkey\\u001b\": 1}",
         ": \"bad\\nkey\\x1b\": expected a known key (format, version, mesh, name, feature_points, parts, eyeballs, "
         "welded, jaw_pivot, head_pivot, texture_box, base_colour, frame), found \"bad\\nkey\\x1b\""},
        {"{\"feature_points\": {}, \"" + std::string(100000, 'k') + "\": 1}",
         ": \"" + std::string(24, 'k') + "\u2026\": expected a known key (format, version, mesh, name, feature_points, "
         "parts, eyeballs, welded, jaw_pivot, head_pivot, texture_box, base_colour, frame), found \"" +
             std::string(24, 'k') + "\u2026\""},
        {std::string(1000, '[') , ": expected at most 256 levels of nesting, found more"},
    };
    for (const auto& c : fdps) {
        const std::string f = write("bad.fdp.json", c.fdp);
        emoface::testing::expect_error<InputError>([&] { load_obj_with_fdp(obj, f); },
                                                   "expression: " + f + c.message);
    }
    // A face without the points FAPU need says which, naming the file.
    const std::string few = write("few.fdp.json", R"({"feature_points": {"3.5": {"vertex": 6}}})");
    emoface::testing::expect_error<InputError>(
        [&] { load_obj_with_fdp(obj, few); },
        "expression: " + few + ": cannot compute FAPU without feature points 3.1, 3.3, 3.6, 9.15, 2.2, 8.3, 8.4");
    emoface::testing::expect_error<InputError>(
        [&] { load_obj_with_fdp(path("missing.obj"), fdp); },
        "expression: " + path("missing.obj") + ": expected a regular file of at most 1024 MiB, found no such file");
}

// A Candide-3 file built here: the 113 vertices at the default face's
// feature points (scaled to Candide's unit size and mirrored, as the model's
// x runs to the face's right), the others on a sphere, and a few triangles.
std::string candide_text(bool mirror) {
    const Face& face = test_face();
    std::vector<Vec3d> v(113);
    for (int i = 0; i < 113; ++i) v[i] = {std::cos(i * 0.7) * 0.5, std::sin(i * 0.3) * 0.5, 0.2};
    for (int k = 0; k < fap::kFeaturePointCount; ++k)
        for (int c : fap::feature_points()[k].candide3_vertices)
            if (c >= 0 && face.has(k)) {
                const Vec3d p = face.position(k);
                v[c] = {(mirror ? -p[0] : p[0]) / 100.0, p[1] / 100.0, p[2] / 100.0};
            }
    std::string s = "# CANDIDE-3 test model\n# VERTEX LIST:\n113\n";
    for (const auto& p : v) s += fmt::format("{} {} {}\n", p[0], p[1], p[2]);
    s += "\n# FACE LIST:\n4\n0 1 2\n2 1 3\n3 1 4\n10 11 12\n";
    s += "\n# ANIMATION UNITS LIST:\n1\n# AU0\n1\n5 0.0 0.1 0.0\n# END OF FILE\n";
    return s;
}

TEST_F(FaceFiles, Candide3ImportReportsMissingPointsAndFixesTheFrame) {
    Candide3Report report;
    const Face face = load_candide3(write("candide3.wfm", candide_text(true)), &report);
    EXPECT_EQ(report.vertices, 113);
    EXPECT_EQ(report.triangles, 4);
    EXPECT_TRUE(report.mirrored_x);
    EXPECT_FALSE(report.flipped_z);
    // Missing: exactly the points the table gives no Candide-3 vertex.
    std::vector<std::string> expected;
    for (const auto& info : fap::feature_points())
        if (info.candide3_vertex < 0) expected.emplace_back(info.id);
    EXPECT_EQ(report.missing_feature_points, expected);
    EXPECT_EQ(missing_feature_points(face), expected);
    for (const char* id : {"6.1", "7.1", "9.8", "10.1", "11.5"}) EXPECT_FALSE(face.has(fp(id))) << id;
    // Pupils are the mean of four vertices: free positions, mirrored back.
    EXPECT_EQ(face.feature_points[fp("3.5")].vertex, -1);
    EXPECT_NEAR(face.position(fp("3.5"))[0], test_face().position(fp("3.5"))[0] / 100.0, 1e-6);
    EXPECT_EQ(face.feature_points[fp("2.1")].vertex, 10);
    // FAPU in Candide's units: the default face's / 100.
    EXPECT_NEAR(face.fapu.es, test_face().fapu.es / 100.0, 1e-8);
    EXPECT_NEAR(face.fapu.mw, test_face().fapu.mw / 100.0, 1e-8);
    // The rig drives it.
    FaceRig rig(face);
    FapValues faps{};
    faps[31 - 1] = 100;
    const DeformedFace d = rig.deform(faps);
    EXPECT_NEAR(d.feature_points[fp("4.1")][1] - face.position(fp("4.1"))[1], 100 * face.fapu.ens, 1e-6);

    Candide3Report plain;
    load_candide3(write("plain.wfm", candide_text(false)), &plain);
    EXPECT_FALSE(plain.mirrored_x);
}

TEST_F(FaceFiles, Candide3ReaderErrors) {
    struct Case {
        std::string text;
        std::string message;
    } cases[] = {
        {"# nothing here\n", ": no \"# VERTEX LIST:\" section"},
        {"# VERTEX LIST:\nmany\n", ":2: expected the number of vertices (0 to 10 million), found \"many\""},
        {"# VERTEX LIST:\n2\n0 0 0\n1 1\n", ":4: vertex 1: expected 3 coordinates, found 2"},
        {"# VERTEX LIST:\n1\n0 0 z\n", ":3: vertex 0: expected a number (within a float's range, 3.4e38), found \"z\""},
        {"# VERTEX LIST:\n1\n0 0 1e39\n",
         ":3: vertex 0: expected a number (within a float's range, 3.4e38), found \"1e39\""},
        {"# VERTEX LIST:\n4\n0 0 0\n1 0 0\n0 1 0\n1 1 0\n# FACE LIST:\n4\n0 1 2\n1 3 2\n0 1 2\n2 1 0\n",
         ":11: expected a manifold mesh (each edge in at most two triangles, wound alike), found 2 of 4 triangles "
         "rejected: complex edges (the first one here)"},
        {"# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n", ": no \"# FACE LIST:\" section"},
        {"# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n# FACE LIST:\n1\n0 1 3\n",
         ":8: face 0: expected a vertex index in [0, 3), found \"3\""},
        {"# VERTEX LIST:\n2\n0 0 0\n", ": ended before all vertices were read"},
        {"# VERTEX LIST:\n3\n0 0 0\n1 0 0\n0 1 0\n# FACE LIST:\n1\n0 1 2\n",
         ": cannot compute FAPU without feature points 3.1, 3.3, 3.5, 3.6, 9.15, 2.2, 8.3, 8.4"},
    };
    for (const auto& c : cases) {
        emoface::testing::expect_error<InputError>([&] { parse_candide3(c.text, "t.wfm"); },
                                                   "expression: t.wfm" + c.message);
    }
}

TEST_F(FaceFiles, PngHasSignatureHeaderAndEveryByte) {
    Image img;
    img.width = 3;
    img.height = 2;
    img.rgba.assign(3 * 2 * 4, 0);
    for (std::size_t i = 0; i < img.rgba.size(); ++i) img.rgba[i] = static_cast<std::uint8_t>(i * 7);
    save_png(img, path("t.png"));
    std::ifstream in(path("t.png"), std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(in)), {});
    ASSERT_GT(bytes.size(), 33u);
    EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
    EXPECT_EQ(bytes.substr(12, 4), "IHDR");
    EXPECT_EQ(static_cast<unsigned char>(bytes[19]), 3u);  // width
    EXPECT_EQ(static_cast<unsigned char>(bytes[23]), 2u);  // height
    // Stored deflate: the pixels appear verbatim after each row's filter byte.
    const std::string row0(reinterpret_cast<const char*>(img.rgba.data()), 12);
    EXPECT_NE(bytes.find(std::string(1, '\0') + row0), std::string::npos);
    EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND");
    EXPECT_THROW(save_png(Image{}, path("e.png")), InputError);
}

}  // namespace
}  // namespace emoface::expression
