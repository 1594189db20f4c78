// The anchored layout (DESIGN.md "Texture layouts", issue 10): a face with its
// own UVs, read from OBJ + FDP files, and key wrinkle maps painted in that UV
// space. The test makes such a head: the default face with its UVs bent by a
// smooth warp (so they are neither the frontal projection nor a scaled copy
// of it) and its base colour resampled to match, written with save_obj /
// save_fdp / a PNG and read back as a user's head is. The keys are painted
// the way a paint program sees an OBJ's UV layout (v up, image row 0 at
// v = 1), from the OBJ's own texcoords, written as a --wrinkles folder and
// read back. Rendered with the anchored layout, the painted marks must sit on
// the skin where they were painted and move with it.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include <unistd.h>
#include <memory>
#include <string>

#include <glm/geometric.hpp>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/expression/default_face.h"
#include "emoface/expression/emotion.h"
#include "emoface/expression/face_io.h"
#include "emoface/expression/face_state.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/image_io.h"
#include "emoface/render/platform.h"
#include "emoface/render/wrinkle_keys_io.h"
#include "golden.h"

namespace {

using namespace emoface;
using render::testing::kFaceTolerance;

constexpr int kMapSize = 512;
constexpr int kImageSize = 512;
// The test head, its painted keys and the last renders, in the build tree.
// One folder per process: ctest runs each test of this suite in its own
// process, in parallel, and every one builds the head in SetUpTestSuite.
const std::string& head_dir() {
    static const std::string dir = "anchored-layout-head-" + std::to_string(::getpid());
    return dir;
}

// The UV warp of the test head: monotone on [0, 1] with fixed ends; it
// widens the middle of the face and squeezes its sides, then places the face
// in a sub-rectangle of the texture.
float warp_u(float u) { return 0.1f + 0.8f * (u - 0.12f * std::sin(6.2831853f * u)); }
float warp_v(float v) { return 0.04f + 0.9f * (v + 0.1f * std::sin(6.2831853f * v)); }
float unwarp(float (*f)(float), float target) {
    float lo = -0.5f, hi = 1.5f;  // f is monotone: bisection
    for (int i = 0; i < 40; ++i) {
        const float mid = 0.5f * (lo + hi);
        (f(mid) < target ? lo : hi) = mid;
    }
    return 0.5f * (lo + hi);
}

// Bilinear sample of an RGBA8 image (rows top first) at OBJ UV (u, v up).
std::array<float, 4> sample(const expression::Image& image, float u, float v) {
    const float x = std::clamp(u, 0.0f, 1.0f) * float(image.width) - 0.5f;
    const float y = (1.0f - std::clamp(v, 0.0f, 1.0f)) * float(image.height) - 0.5f;
    const int x0 = std::clamp(int(std::floor(x)), 0, image.width - 1);
    const int y0 = std::clamp(int(std::floor(y)), 0, image.height - 1);
    const int x1 = std::min(x0 + 1, image.width - 1), y1 = std::min(y0 + 1, image.height - 1);
    const float fx = std::clamp(x - float(x0), 0.0f, 1.0f), fy = std::clamp(y - float(y0), 0.0f, 1.0f);
    std::array<float, 4> out{};
    auto px = [&](int xx, int yy, int c) {
        return float(image.rgba[(std::size_t(yy) * std::size_t(image.width) + std::size_t(xx)) * 4 + std::size_t(c)]);
    };
    for (int c = 0; c < 4; ++c)
        out[std::size_t(c)] = (1 - fy) * ((1 - fx) * px(x0, y0, c) + fx * px(x1, y0, c)) +
                              fy * ((1 - fx) * px(x0, y1, c) + fx * px(x1, y1, c));
    return out;
}

// Writes the test head (OBJ + FDP + PNG) into `dir` and returns the OBJ path.
std::string write_test_head(const std::string& dir) {
    expression::DefaultFaceOptions fo;
    fo.resolution_scale = 0.5;
    fo.texture_size = 256;
    expression::Face face = expression::make_default_face(std::string(EMOFACE_DATA_DIR) + "/face", fo);
    for (const auto vh : face.mesh.vertices()) {
        const auto t = face.mesh.texcoord2D(vh);
        face.mesh.set_texcoord2D(vh, expression::TriMesh::TexCoord2D(warp_u(t[0]), warp_v(t[1])));
    }
    expression::Image base;
    base.width = base.height = 256;
    base.rgba.resize(256 * 256 * 4);
    for (int r = 0; r < 256; ++r)
        for (int c = 0; c < 256; ++c) {
            const float u = unwarp(warp_u, (float(c) + 0.5f) / 256.0f);
            const float v = unwarp(warp_v, 1.0f - (float(r) + 0.5f) / 256.0f);
            const auto s = sample(face.base_colour, u, v);
            for (int k = 0; k < 4; ++k)
                base.rgba[(std::size_t(r) * 256 + std::size_t(c)) * 4 + std::size_t(k)] =
                    std::uint8_t(std::lround(s[std::size_t(k)]));
        }
    expression::save_obj(face, dir + "/head.obj");
    expression::save_png(base, dir + "/head.png");
    expression::save_fdp(face, dir + "/head.fdp.json", "head.obj", "head.png");
    return dir + "/head.obj";
}

// A key map painted as a height field (normalised image units, rows top
// first) and encoded as the project's normal maps (green down).
struct Canvas {
    std::vector<float> height = std::vector<float>(std::size_t(kMapSize) * kMapSize, 0.0f);
    // A groove (depth < 0) or ridge along the segment a-b (pixels), Gaussian
    // across it with sigma pixels.
    void stroke(glm::vec2 a, glm::vec2 b, float depth, float sigma) {
        for (int r = 0; r < kMapSize; ++r)
            for (int c = 0; c < kMapSize; ++c) {
                const glm::vec2 p(float(c) + 0.5f, float(r) + 0.5f);
                const glm::vec2 ab = b - a;
                const float t = std::clamp(glm::dot(p - a, ab) / std::max(glm::dot(ab, ab), 1e-6f), 0.0f, 1.0f);
                const float d = glm::distance(p, a + t * ab);
                height[std::size_t(r) * kMapSize + std::size_t(c)] +=
                    depth * std::exp(-0.5f * d * d / (sigma * sigma));
            }
    }
    expression::NormalMap map() const { return expression::height_to_normal_map(height, kMapSize, 1.0f); }
};

class AnchoredLayout : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        namespace fs = std::filesystem;
        const std::string dir = head_dir();
        fs::remove_all(dir);
        fs::create_directories(dir + "/keys");
        const std::string obj = write_test_head(dir);

        // Read back as a user's head is (the session reads the PNG the FDP names).
        expression::Face face = expression::load_obj_with_fdp(obj, dir + "/head.fdp.json");
        const render::ImageRGBA8 base = render::read_image_rgba8(face.base_colour_file);
        face.base_colour.width = base.width;
        face.base_colour.height = base.height;
        face.base_colour.rgba = base.pixels;

        render::FaceAssetsOptions ao;
        ao.wrinkle_map_size = kMapSize;
        ao.layout = render::WrinkleLayout::Anchored;
        assets_ = render::load_face_assets(std::move(face), EMOFACE_DATA_DIR, ao).release();
        generated_ = new std::vector<render::WrinkleKey>(assets_->keys);

        // Paint the thesis's seven emotion keys in the OBJ's UV space and use
        // them as --wrinkles DIR does (a folder of emotion keys still works).
        std::vector<render::WrinkleKey> painted;
        for (const char* name : {"neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise"}) {
            Canvas canvas;
            paint(name, canvas);
            painted.push_back({name, canvas.map(), assets_->keys.front().layout, {}});
        }
        render::write_wrinkle_keys(dir + "/keys", painted);
        assets_->keys = render::read_wrinkle_keys(dir + "/keys", assets_->lines);

        render::PlatformOptions po;
        po.width = po.height = kImageSize;
        po.samples = 4;
        platform_ = new render::HeadlessPlatform(po);
        render::FaceSceneOptions so;
        so.backend = morph::Backend::Cpu;  // the same pixels with or without a GPU
        scene_ = render::make_face_scene(*platform_, *assets_, so).release();
    }
    static void TearDownTestSuite() {
        std::filesystem::remove_all(head_dir());
        delete scene_;
        delete platform_;
        delete generated_;
        delete assets_;
    }

    // Where a skin feature point's vertex lies in the painted image: its OBJ
    // texcoord, v up, so row = (1 - v) * size (as a paint program shows it).
    static glm::vec2 painted_at(const expression::Face& face, const char* id) {
        const auto& fp = face.feature_points[std::size_t(fap::feature_point_index(id))];
        const auto t = face.mesh.texcoord2D(expression::TriMesh::VertexHandle(fp.vertex));
        return {t[0] * kMapSize, (1.0f - t[1]) * kMapSize};
    }

    // anger: two vertical grooves between the brows; surprise: three
    // horizontal grooves across the forehead; joy: a round bump on each
    // cheek (5.3, 5.4). The other keys stay flat.
    static void paint(const std::string& key, Canvas& canvas) {
        const expression::Face& f = assets_->face;
        const glm::vec2 in_l = painted_at(f, "4.1"), in_r = painted_at(f, "4.2");
        const float gap = glm::distance(in_l, in_r);
        const glm::vec2 up(0.0f, -1.0f);  // up the face = up the painted image
        if (key == "anger") {
            for (const float t : {0.3f, 0.7f}) {
                const glm::vec2 base = glm::mix(in_r, in_l, t);
                canvas.stroke(base + 0.05f * gap * up, base + 0.5f * gap * up, -0.006f, 2.5f);
            }
        } else if (key == "surprise") {
            const glm::vec2 mid_l = painted_at(f, "4.3"), mid_r = painted_at(f, "4.4");
            for (const float h : {0.35f, 0.6f, 0.85f})
                canvas.stroke(mid_r + h * gap * up, mid_l + h * gap * up, -0.005f, 3.0f);
        } else if (key == "joy") {
            for (const char* id : {"5.3", "5.4"}) {
                const glm::vec2 c = painted_at(f, id);
                canvas.stroke(c, c, 0.012f, 7.0f);
            }
        }
    }

    static render::DrawOptions draw_options(bool wrinkles) {
        render::DrawOptions d;
        d.camera = scene_->frontal_camera(1.0f);
        d.light = scene_->portrait_light();
        d.wrinkles = wrinkles;
        return d;
    }
    // A light for measuring, not for looks: dim enough that no lit pixel
    // clips, no highlight, from `direction`.
    static render::Light measuring_light(glm::vec3 direction) {
        render::Light l;
        l.position = glm::vec4(glm::normalize(direction), 0.0f);
        l.ambient = glm::vec3(0.1f);
        l.diffuse = glm::vec3(0.5f);
        l.specular = glm::vec3(0.0f);
        return l;
    }
    // The face posed by `mix`, its keys weighted by the mix or by
    // `key_weights` when given.
    static render::ImageRGBA8 draw(const std::string& mix, bool wrinkles = true,
                                   const render::Light* light = nullptr,
                                   const std::vector<float>* key_weights = nullptr) {
        const expression::FaceState state =
            expression::face_state(expression::parse_emotion_mix(mix), assets_->emotions);
        scene_->update(state.faps, key_weights ? *key_weights : render::key_weights(assets_->keys, state));
        platform_->begin_frame();
        render::DrawOptions d = draw_options(wrinkles);
        // A measuring light is the only light: the thesis's one-light
        // Blinn-Phong, not the skin model's rig of key, fill, rim and sky,
        // whose other lights would pull a mark's shading off its centre.
        if (light) {
            d.light = *light;
            d.shading = render::Shading::Thesis;
        }
        scene_->draw(d);
        platform_->end_frame();
        render::ImageRGBA8 image = platform_->read_rgba();
        // The last picture of each kind, to look at while debugging (the
        // folder goes with the suite's teardown).
        render::write_image(head_dir() + "/" + (wrinkles ? "with" : "without") + ".png", image);
        return image;
    }
    // The posed position of a feature point's vertex, in pixels of the
    // rendered image (x right, y down).
    static glm::vec2 on_screen(const char* id) {
        const auto& fp = assets_->face.feature_points[std::size_t(fap::feature_point_index(id))];
        const auto& p = scene_->mesh().point(expression::TriMesh::VertexHandle(fp.vertex));
        const render::Camera cam = draw_options(true).camera;
        const glm::vec4 c = cam.projection * cam.view * glm::vec4(p[0], p[1], p[2], 1.0f);
        return {(c.x / c.w * 0.5f + 0.5f) * kImageSize, (0.5f - c.y / c.w * 0.5f) * kImageSize};
    }
    // Where a point of the painted image (pixels) lies on the posed face in
    // the rendered image: the skin triangle whose painted UVs hold it, its
    // posed corners interpolated.
    static glm::vec2 screen_of_painted(glm::vec2 spot) {
        const expression::Face& f = assets_->face;
        auto uv = [&](expression::TriMesh::VertexHandle vh) {
            const auto t = f.mesh.texcoord2D(vh);
            return glm::vec2(t[0] * kMapSize, (1.0f - t[1]) * kMapSize);
        };
        for (const auto fh : f.mesh.faces()) {
            expression::TriMesh::VertexHandle v[3];
            int k = 0;
            for (const auto vh : f.mesh.fv_range(fh)) v[k++ % 3] = vh;
            if (f.parts[std::size_t(v[0].idx())] != expression::VertexPart::Skin) continue;
            const glm::vec2 a = uv(v[0]), e1 = uv(v[1]) - a, e2 = uv(v[2]) - a, p = spot - a;
            const float det = e1.x * e2.y - e1.y * e2.x;
            if (std::fabs(det) < 1e-9f) continue;
            const float b1 = (p.x * e2.y - p.y * e2.x) / det, b2 = (e1.x * p.y - e1.y * p.x) / det;
            if (b1 < 0 || b2 < 0 || b1 + b2 > 1) continue;
            glm::vec3 q(0.0f);
            const float w[3] = {1 - b1 - b2, b1, b2};
            for (int i = 0; i < 3; ++i) {
                const auto& pt = scene_->mesh().point(v[i]);
                q += w[i] * glm::vec3(pt[0], pt[1], pt[2]);
            }
            const render::Camera cam = draw_options(true).camera;
            const glm::vec4 c = cam.projection * cam.view * glm::vec4(q, 1.0f);
            return {(c.x / c.w * 0.5f + 0.5f) * kImageSize, (0.5f - c.y / c.w * 0.5f) * kImageSize};
        }
        ADD_FAILURE() << "no skin triangle holds painted point (" << spot.x << ", " << spot.y << ")";
        return glm::vec2(0.0f);
    }
    // Sum of |a - b| over RGB at pixel (x, y).
    static int diff_at(const render::ImageRGBA8& a, const render::ImageRGBA8& b, int x, int y) {
        int s = 0;
        for (int c = 0; c < 3; ++c) {
            const std::size_t i = (std::size_t(y) * std::size_t(a.width) + std::size_t(x)) * 4 + std::size_t(c);
            s += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
        }
        return s;
    }
    // Mean luminance-ish (R+G+B) of a minus b over a box.
    static double signed_diff(const render::ImageRGBA8& a, const render::ImageRGBA8& b, int x0, int y0,
                              int x1, int y1) {
        double s = 0;
        int n = 0;
        for (int y = y0; y <= y1; ++y)
            for (int x = x0; x <= x1; ++x, ++n)
                for (int c = 0; c < 3; ++c) {
                    const std::size_t i = (std::size_t(y) * std::size_t(a.width) + std::size_t(x)) * 4 + std::size_t(c);
                    s += double(a.pixels[i]) - double(b.pixels[i]);
                }
        return s / std::max(n, 1);
    }

    static render::FaceAssets* assets_;
    static std::vector<render::WrinkleKey>* generated_;
    static render::HeadlessPlatform* platform_;
    static render::FaceScene* scene_;
};
render::FaceAssets* AnchoredLayout::assets_ = nullptr;
std::vector<render::WrinkleKey>* AnchoredLayout::generated_ = nullptr;
render::HeadlessPlatform* AnchoredLayout::platform_ = nullptr;
render::FaceScene* AnchoredLayout::scene_ = nullptr;

TEST_F(AnchoredLayout, LayoutIsTheFeaturePointsUvsWithVDown) {
    const expression::Face& f = assets_->face;
    const expression::FeatureLayout& layout = scene_->layout();
    for (const char* id : {"4.1", "4.2", "5.3", "8.1", "9.15"}) {
        SCOPED_TRACE(id);
        const auto& fp = f.feature_points[std::size_t(fap::feature_point_index(id))];
        ASSERT_GE(fp.vertex, 0);
        const auto t = f.mesh.texcoord2D(expression::TriMesh::VertexHandle(fp.vertex));
        EXPECT_FLOAT_EQ(layout.at(id).x, t[0]);
        EXPECT_FLOAT_EQ(layout.at(id).y, 1.0f - t[1]);
    }
    // The pupils lie on the eyeballs, off the skin: they get the UV the skin
    // around them would give, between the eye's corners.
    const glm::vec2 pupil = layout.at("3.5"), inner = layout.at("3.11"), outer = layout.at("3.7");
    EXPECT_GT(pupil.x, std::min(inner.x, outer.x));
    EXPECT_LT(pupil.x, std::max(inner.x, outer.x));
    EXPECT_NEAR(pupil.y, 0.5f * (inner.y + outer.y), 0.5f * glm::distance(inner, outer));
    // The layout does not move with the pose (L* = L_k).
    const std::string before = expression::layout_to_json(scene_->layout());
    draw("anger");
    EXPECT_EQ(expression::layout_to_json(scene_->layout()), before);
}

TEST_F(AnchoredLayout, GeneratedKeysAreMadeInUvSpace) {
    const std::string anchored = expression::layout_to_json(expression::anchored_layout(assets_->face));
    for (const render::WrinkleKey& key : *generated_) {
        SCOPED_TRACE(key.name);
        EXPECT_EQ(expression::layout_to_json(key.layout), anchored);
    }
}

// The cheek bumps painted at 5.3 and 5.4's UVs show on screen at those
// vertices of the posed mesh (joy lifts the cheeks; the bumps go along).
TEST_F(AnchoredLayout, PaintedMarksSitWherePainted) {
    // Lit from the front, a bump shades its rim alike all round: the centre
    // of the change is the bump's centre.
    const render::Light front = measuring_light({0.0f, 0.0f, 1.0f});
    // Against the same pose with the (flat) neutral key alone, so that
    // every change is the painted joy key's.
    std::vector<float> neutral_only(assets_->keys.size(), 0.0f);
    neutral_only[0] = 1.0f;  // read_wrinkle_keys puts neutral first
    const render::ImageRGBA8 with = draw("joy", true, &front);
    const render::ImageRGBA8 without = draw("joy", true, &front, &neutral_only);
    double total = 0, in_windows = 0;
    for (int y = 0; y < kImageSize; ++y)
        for (int x = 0; x < kImageSize; ++x) total += diff_at(with, without, x, y);
    for (const char* id : {"5.3", "5.4"}) {
        SCOPED_TRACE(id);
        const glm::vec2 at = on_screen(id);
        constexpr int kWindow = 40;
        double sx = 0, sy = 0, sw = 0;
        for (int y = int(at.y) - kWindow; y <= int(at.y) + kWindow; ++y)
            for (int x = int(at.x) - kWindow; x <= int(at.x) + kWindow; ++x) {
                if (x < 0 || y < 0 || x >= kImageSize || y >= kImageSize) continue;
                const double w = diff_at(with, without, x, y);
                sx += w * (x + 0.5);
                sy += w * (y + 0.5);
                sw += w;
            }
        ASSERT_GT(sw, 0.0) << "no painted mark near " << id;
        in_windows += sw;
        const glm::vec2 centre(float(sx / sw), float(sy / sw));
        std::printf("%s: vertex on screen (%.1f, %.1f), painted mark's centre (%.1f, %.1f)\n", id, at.x,
                    at.y, centre.x, centre.y);
        // Within the mark's own radius (7 px painted): with session 7's face
        // (jaw, mouth, lids) the shaded centroid lies 5.1-5.4 px below the
        // vertex, the bump's lower rim shading more than its upper.
        EXPECT_LT(glm::distance(centre, at), 6.0f);
    }
    // And nothing of them anywhere else.
    std::printf("change within the two windows: %.1f%% of the whole\n", 100.0 * in_windows / total);
    EXPECT_GT(in_windows, 0.9 * total);
}

// A painted groove is a valley: lit from above, its upper wall (facing down)
// darkens and its lower wall brightens. Reading green up, or v up, turns
// that around or moves the groove.
TEST_F(AnchoredLayout, PaintedGroovesShadeAsValleys) {
    const render::Light above = measuring_light({0.0f, 0.6f, 0.8f});
    const render::ImageRGBA8 with = draw("surprise", true, &above);
    const render::ImageRGBA8 without = draw("surprise", false, &above);
    // The middle forehead groove runs 0.6 brow gaps above the mid-brows.
    const expression::Face& f = assets_->face;
    const glm::vec2 in_l = painted_at(f, "4.1"), in_r = painted_at(f, "4.2");
    const glm::vec2 spot = 0.5f * (painted_at(f, "4.3") + painted_at(f, "4.4")) -
                           glm::vec2(0.0f, 0.6f * glm::distance(in_l, in_r));
    const glm::vec2 at = screen_of_painted(spot);
    // Rows of (with - without) across the groove, averaged over 21 columns.
    // The groove's floor is its darkest row (its cavity darkens it under any
    // light), within 4 rows of where it was painted (the grooves lie about
    // 6 pixels apart on screen, so that stays with this one). Lit from above,
    // a valley's upper wall faces down and darkens more than its lower wall:
    // the first moment of the change about the floor (y down) is positive; a
    // ridge (green read upwards) darkens below its crest and makes it negative.
    const int x = int(at.x);
    auto row_change = [&](int y) { return signed_diff(with, without, x - 10, y, x + 10, y); };
    int floor_row = int(at.y);
    for (int y = int(at.y) - 4; y <= int(at.y) + 4; ++y)
        if (row_change(y) < row_change(floor_row)) floor_row = y;
    double moment = 0;
    for (int dy = -2; dy <= 2; ++dy) moment += dy * row_change(floor_row + dy);
    const double darkest = row_change(floor_row);
    std::printf("forehead groove painted at (%.1f, %.1f): floor at row %+d (%+.1f), first moment about it %+.1f\n",
                at.x, at.y, floor_row - int(at.y), darkest, moment);
    EXPECT_GT(moment, 10.0);
    EXPECT_LT(darkest, -3.0);
}

TEST_F(AnchoredLayout, MatchesTheCommittedImage) {
    const render::ImageRGBA8 image = render::testing::downsample2x(draw("0.5 anger + 0.5 surprise"));
    const auto result = render::testing::compare_with_golden(
        image, std::string(EMOFACE_TEST_SOURCE_DIR) + "/goldens/anchored_painted_anger50_surprise50.png",
        kFaceTolerance, "golden-failures");
    if (result.updated) std::printf("%s\n", result.message.c_str());
    EXPECT_TRUE(result.ok) << result.message;
    // The tolerance tells this picture from the same one without its maps.
    const render::ImageRGBA8 without =
        render::testing::downsample2x(draw("0.5 anger + 0.5 surprise", false));
    double sum = 0;
    for (std::size_t i = 0; i < image.pixels.size(); ++i)
        if (i % 4 != 3) sum += std::abs(int(image.pixels[i]) - int(without.pixels[i]));
    const double mean = sum / (3.0 * image.width * image.height);
    std::printf("with vs without the painted maps: mean %.3f\n", mean);
    EXPECT_GT(mean, 2.0 * kFaceTolerance.mean_diff);
}

TEST(AnchoredLayoutErrors, AFaceWithoutUvsIsRefused) {
    expression::Face face;
    face.name = "flat";
    expression::DefaultFaceOptions fo;
    fo.resolution_scale = 0.2;
    fo.texture_size = 64;
    face = expression::make_default_face(std::string(EMOFACE_DATA_DIR) + "/face", fo);
    for (const auto vh : face.mesh.vertices())
        face.mesh.set_texcoord2D(vh, expression::TriMesh::TexCoord2D(0.5f, 0.5f));
    try {
        expression::anchored_layout(face);
        FAIL() << "expected an InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("UVs span no area"), std::string::npos) << e.what();
    }
}

}  // namespace
