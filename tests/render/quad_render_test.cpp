// The renderer against lighting computed by hand: a flat quad filling a
// headless frame, a 16x16 normal map with a different tangent-space normal in
// each quadrant, a constant sRGB base texture. At the centre of each quadrant
// the pixel must be thesis 5.5.1's Blinn-Phong (Shading::Thesis) of the
// decoded normal brought to world space through T, B = w N x T, N, encoded
// to sRGB. The skin model is checked for its properties on the same quad:
// energy bounded, Fresnel rising at grazing angles, a monotonic tone curve.
#include <array>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/render/platform.h"
#include "emoface/render/renderer.h"
#include "emoface/render/skin_shading.h"
#include "emoface/render/wrinkle_texture.h"
#include "quad_mesh.h"
#include "skin_maps.h"

namespace {

using namespace emoface::render;
using emoface::expression::TriMesh;

constexpr int kFrame = 64;
constexpr int kMap = 16;

// Tangent-space normals of the four quadrants (x along +u, y along +v).
const glm::vec3 kQuadrantNormal[4] = {
    {0.0f, 0.0f, 1.0f},
    glm::normalize(glm::vec3(0.5f, 0.0f, 0.866f)),
    glm::normalize(glm::vec3(0.0f, 0.5f, 0.866f)),
    glm::normalize(glm::vec3(-0.3f, -0.4f, 0.866f)),
};
const std::uint8_t kBaseSrgb[3] = {200, 160, 120};

std::uint8_t encode_unit(float c) {  // [-1, 1] -> byte
    return std::uint8_t(std::lround((c * 0.5f + 0.5f) * 255.0f));
}
float decode_unit(std::uint8_t b) { return float(b) / 255.0f * 2.0f - 1.0f; }
float srgb_to_linear(float c) {
    return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
}
float linear_to_srgb(float c) {
    c = std::fmin(std::fmax(c, 0.0f), 1.0f);
    return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

enum class UvLayout { VDown, VUp, VDownMirroredWrinkleU };

struct Case {
    std::string name;
    UvLayout layout;
    Light light;
    bool wrinkles;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

// UVs of a point of the quad (x, y in [-1, 1]).
glm::vec2 base_uv(UvLayout layout, float x, float y) {
    const float u = (x + 1) / 2;
    return layout == UvLayout::VUp ? glm::vec2(u, (y + 1) / 2) : glm::vec2(u, (1 - y) / 2);
}
glm::vec2 wrinkle_uv(UvLayout layout, float x, float y) {
    glm::vec2 uv = base_uv(layout, x, y);
    if (layout == UvLayout::VDownMirroredWrinkleU) uv.x = 1 - uv.x;
    return uv;
}
// World-space dp/du and dp/dv of the wrinkle UVs (the quad spans 2 units).
glm::vec3 dpdu(UvLayout layout) {
    return layout == UvLayout::VDownMirroredWrinkleU ? glm::vec3(-1, 0, 0) : glm::vec3(1, 0, 0);
}
glm::vec3 dpdv(UvLayout layout) {
    return layout == UvLayout::VUp ? glm::vec3(0, 1, 0) : glm::vec3(0, -1, 0);
}

// The quad spans [-1, 1]^2 at z = 0, facing +z.
TriMesh make_quad(UvLayout layout) {
    const std::array<glm::vec3, 4> corners = {glm::vec3(-1, -1, 0), glm::vec3(1, -1, 0), glm::vec3(1, 1, 0),
                                              glm::vec3(-1, 1, 0)};
    std::array<glm::vec2, 4> uvs;
    for (int i = 0; i < 4; ++i) uvs[i] = base_uv(layout, corners[i].x, corners[i].y);
    return emoface::render::testing::quad_mesh(corners, uvs);
}

std::vector<std::uint8_t> quadrant_normal_map() {
    std::vector<std::uint8_t> px(kMap * kMap * 4);
    for (int y = 0; y < kMap; ++y)
        for (int x = 0; x < kMap; ++x) {
            const glm::vec3 n = kQuadrantNormal[(x >= kMap / 2) + 2 * (y >= kMap / 2)];
            std::uint8_t* p = &px[(y * kMap + x) * 4];
            p[0] = encode_unit(n.x); p[1] = encode_unit(n.y); p[2] = encode_unit(n.z);
            p[3] = 255;
        }
    return px;
}

Camera ortho_camera() {
    Camera c;
    c.position = {0, 0, 2};
    c.view = glm::lookAt(c.position, glm::vec3(0), glm::vec3(0, 1, 0));
    c.projection = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, 0.1f, 10.0f);
    return c;
}

constexpr float kShininess = 16.0f;

// The hand computation for the pixel at (px, py), top row 0.
glm::vec3 expected_srgb(const Case& c, int px, int py) {
    const float x = -1 + (px + 0.5f) * 2.0f / kFrame, y = 1 - (py + 0.5f) * 2.0f / kFrame;
    const glm::vec3 p(x, y, 0);
    glm::vec3 n(0, 0, 1);
    if (c.wrinkles) {
        const glm::vec2 uv = wrinkle_uv(c.layout, x, y);
        const glm::vec3 q =
            kQuadrantNormal[(uv.x * kMap >= kMap / 2) + 2 * (uv.y * kMap >= kMap / 2)];
        // The shader sees the bytes, not the exact vector.
        const glm::vec3 t(decode_unit(encode_unit(q.x)), decode_unit(encode_unit(q.y)),
                          decode_unit(encode_unit(q.z)));
        n = glm::normalize(t.x * dpdu(c.layout) + t.y * dpdv(c.layout) + t.z * glm::vec3(0, 0, 1));
    }
    const glm::vec3 l = c.light.position.w == 0
                            ? glm::normalize(glm::vec3(c.light.position))
                            : glm::normalize(glm::vec3(c.light.position) - p);
    const glm::vec3 base(srgb_to_linear(kBaseSrgb[0] / 255.0f),
                         srgb_to_linear(kBaseSrgb[1] / 255.0f),
                         srgb_to_linear(kBaseSrgb[2] / 255.0f));
    const float ndl = std::fmax(0.0f, glm::dot(n, l));
    glm::vec3 color = c.light.ambient * base + c.light.diffuse * ndl * base;
    if (ndl > 0) {
        const glm::vec3 v = glm::normalize(glm::vec3(0, 0, 2) - p);
        const glm::vec3 h = glm::normalize(l + v);
        color += c.light.specular * std::pow(std::fmax(0.0f, glm::dot(n, h)), kShininess);
    }
    return {linear_to_srgb(color.r) * 255, linear_to_srgb(color.g) * 255,
            linear_to_srgb(color.b) * 255};
}

Light directional(glm::vec3 towards) {
    Light l;
    l.position = glm::vec4(glm::normalize(towards), 0.0f);
    l.ambient = glm::vec3(0.1f);
    l.diffuse = glm::vec3(0.8f, 0.75f, 0.7f);
    l.specular = glm::vec3(0.3f);
    return l;
}
Light point(glm::vec3 at) {
    Light l = directional({0, 0, 1});
    l.position = glm::vec4(at, 1.0f);
    return l;
}

class QuadRender : public ::testing::TestWithParam<Case> {
protected:
    static void SetUpTestSuite() {
        PlatformOptions o;
        o.width = o.height = kFrame;
        o.samples = 4;
        platform_ = std::make_unique<HeadlessPlatform>(o);
    }
    static void TearDownTestSuite() { platform_.reset(); }
    static std::unique_ptr<HeadlessPlatform> platform_;
};
std::unique_ptr<HeadlessPlatform> QuadRender::platform_;

TEST_P(QuadRender, ThesisShadingMatchesBlinnPhongByHand) {
    const Case& c = GetParam();
    Platform& platform = *platform_;
    Renderer renderer(platform);
    Material material;
    auto base = std::make_shared<ImageRGBA8>(4, 4);
    for (int i = 0; i < 16; ++i) {
        std::uint8_t* p = base->pixels.data() + 4 * i;
        p[0] = kBaseSrgb[0]; p[1] = kBaseSrgb[1]; p[2] = kBaseSrgb[2]; p[3] = 255;
    }
    material.base_texture = base;
    material.shininess = kShininess;
    const TriMesh quad = make_quad(c.layout);
    const Renderer::MeshId id = renderer.add_mesh(quad, material);
    std::vector<glm::vec2> uvs;
    for (const auto vh : quad.vertices()) {
        const auto& p = quad.point(vh);
        uvs.push_back(wrinkle_uv(c.layout, p[0], p[1]));
    }
    renderer.update_mesh(id, quad, uvs);

    WrinkleTexture map(kMap, kMap, TexelFormat::RGBA8, NormalEncoding::Unsigned);
    const std::vector<std::uint8_t> normals = quadrant_normal_map();
    map.upload(normals.data());

    DrawOptions options;
    options.camera = ortho_camera();
    options.light = c.light;
    options.wrinkles = c.wrinkles;
    options.shading = Shading::Thesis;
    platform.begin_frame();
    renderer.draw(options, &map);
    platform.end_frame();
    const ImageRGBA8 image = platform.read_rgba();
    ASSERT_EQ(image.width, kFrame);

    for (const int py : {16, 47})
        for (const int px : {16, 47}) {
            const glm::vec3 want = expected_srgb(c, px, py);
            const std::uint8_t* got = image.at(px, py);
            for (int ch = 0; ch < 3; ++ch)
                // Within 1.5 of 255: 8-bit rounding of the output plus the
                // GPU's approximate pow() in the sRGB encode.
                EXPECT_NEAR(float(got[ch]), want[ch], 1.5f)
                    << c.name << ": pixel (" << px << ", " << py << ") channel " << ch;
            EXPECT_EQ(got[3], 255);
        }
}

std::vector<Case> cases() {
    return {
        {"flat_normals_directional", UvLayout::VDown, directional({0.3f, 0.5f, 1.0f}), false},
        {"v_down_directional", UvLayout::VDown, directional({0.3f, 0.5f, 1.0f}), true},
        {"v_up_directional", UvLayout::VUp, directional({0.3f, 0.5f, 1.0f}), true},
        {"mirrored_wrinkle_u", UvLayout::VDownMirroredWrinkleU, directional({0.6f, -0.2f, 1.0f}),
         true},
        {"v_down_point_light", UvLayout::VDown, point({0.5f, 0.8f, 1.5f}), true},
        {"grazing_light_some_unlit", UvLayout::VDown, directional({-1.0f, 0.0f, 0.35f}), true},
    };
}

INSTANTIATE_TEST_SUITE_P(Cases, QuadRender, ::testing::ValuesIn(cases()),
                         [](const auto& info) { return info.param.name; });

TEST(Platform, HeadlessReportsItsRendererAndSize) {
    PlatformOptions o;
    o.width = 40;
    o.height = 24;
    HeadlessPlatform p(o);
    EXPECT_EQ(p.width(), 40);
    EXPECT_EQ(p.height(), 24);
    EXPECT_GE(p.samples(), 1);
    EXPECT_NE(p.description().find("OpenGL"), std::string::npos) << p.description();
    // A cleared frame reads back with the clear colour, top row first.
    p.begin_frame();
    Renderer r(p);
    DrawOptions d;
    d.background = {1.0f, 0.0f, 0.0f};
    d.viewport = {0, 0, 40, 12};  // GL's bottom half
    r.draw(d, nullptr);
    d.background = {0.0f, 0.0f, 1.0f};
    d.viewport = {0, 12, 40, 12};  // top half
    r.draw(d, nullptr);
    p.end_frame();
    const ImageRGBA8 img = p.read_rgba();
    EXPECT_EQ(img.at(5, 2)[2], 255);   // top row: blue
    EXPECT_EQ(img.at(5, 2)[0], 0);
    EXPECT_EQ(img.at(5, 21)[0], 255);  // bottom: red
}

TEST(Platform, BadSizesAreErrors) {
    PlatformOptions o;
    o.width = 0;
    EXPECT_THROW(HeadlessPlatform{o}, emoface::Error);
}

}  // namespace

namespace {

// A curved patch (z = a bump over [-1, 1]^2) seen from the front, bump-mapped
// with a striped normal map through the projective layout: the frames the
// CPU computes on the mesh (TangentFrames on projected UVs) and the closed
// form the vertex shader derives must light it the same way.
TEST(ProjectiveFrames, ShaderClosedFormMatchesCpuTangentFrames) {
    PlatformOptions o;
    o.width = o.height = 128;
    HeadlessPlatform platform(o);
    TriMesh m;
    m.request_vertex_normals();
    m.request_face_normals();
    const int n = 40;
    std::vector<TriMesh::VertexHandle> v;
    for (int j = 0; j <= n; ++j)
        for (int i = 0; i <= n; ++i) {
            const float x = -1 + 2.0f * i / n, y = -1 + 2.0f * j / n;
            v.push_back(m.add_vertex({x, y, 0.6f * std::exp(-2.0f * (x * x + y * y))}));
        }
    for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
            const auto a = v[j * (n + 1) + i], b = v[j * (n + 1) + i + 1],
                       c = v[(j + 1) * (n + 1) + i + 1], d = v[(j + 1) * (n + 1) + i];
            m.add_face(a, b, c);
            m.add_face(a, c, d);
        }
    m.update_normals();
    const std::array<float, 4> box{-1.0f, -1.0f, 1.0f, 1.0f};
    std::vector<glm::vec2> uvs;
    for (const auto vh : m.vertices()) {
        const auto& p = m.point(vh);
        uvs.push_back({(p[0] - box[0]) / (box[2] - box[0]), (box[3] - p[1]) / (box[3] - box[1])});
    }
    constexpr int kSize = 64;
    std::vector<std::uint8_t> map(kSize * kSize * 4);
    for (int y = 0; y < kSize; ++y)
        for (int x = 0; x < kSize; ++x) {
            const glm::vec3 nn = glm::normalize(glm::vec3(0.5f * std::sin(x * 0.6f),
                                                          0.5f * std::cos(y * 0.45f), 1.0f));
            std::uint8_t* p = &map[(y * kSize + x) * 4];
            p[0] = encode_unit(nn.x); p[1] = encode_unit(nn.y); p[2] = encode_unit(nn.z); p[3] = 255;
        }
    WrinkleTexture texture(kSize, kSize, TexelFormat::RGBA8, NormalEncoding::Unsigned);
    texture.upload(map.data());
    Renderer renderer(platform);
    Material material;
    material.base_color = glm::vec3(0.7f);
    const auto id = renderer.add_mesh(m, material);
    renderer.update_mesh(id, m, uvs);  // CPU frames on the projected UVs

    DrawOptions d;
    d.camera = Camera::look_at({0, 0, 4}, {0, 0, 0}, {0, 1, 0}, 32.0f, 1.0f, 0.5f, 10.0f);
    d.light = directional({-0.5f, 0.7f, 0.6f});
    auto render = [&](bool projective, bool wrinkles) {
        d.projective_wrinkles = projective;
        d.projective_box = box;
        d.wrinkles = wrinkles;
        platform.begin_frame();
        renderer.draw(d, &texture);
        platform.end_frame();
        return platform.read_rgba();
    };
    const ImageRGBA8 cpu = render(false, true), shader = render(true, true),
                     flat = render(false, false);
    double diff = 0, bump = 0;
    int worst = 0;
    for (std::size_t i = 0; i < cpu.pixels.size(); ++i) {
        if (i % 4 == 3) continue;
        const int dc = std::abs(int(cpu.pixels[i]) - int(shader.pixels[i]));
        worst = std::max(worst, dc);
        diff += dc;
        bump += std::abs(int(cpu.pixels[i]) - int(flat.pixels[i]));
    }
    const double count = 3.0 * cpu.width * cpu.height;
    // The normal map changes the picture a lot (mean 23 steps here), and the
    // two frames agree (mean 0.001, one step at worst: the CPU frame averages
    // the faces around a vertex, the closed form is exact at it). A flipped
    // handedness gives a mean of 34.
    EXPECT_GT(bump / count, 5.0) << "the normal map must visibly change the image";
    EXPECT_LT(diff / count, 0.1);
    EXPECT_LE(worst, 4);
}

}  // namespace

namespace {

// --- the skin model on the flat quad ---------------------------------------
// White (or black) albedo, no wrinkle map, the rig dark unless a test lights
// it, an orthographic camera far along +z so every pixel is seen from +z.
// The quad is turned about x by `view_deg` to see it at that angle.

constexpr int kSkinFrame = 16;

SkinShading dark_rig() {
    SkinShading s;
    s.fill.colour = s.rim.colour = s.sky = s.ground = glm::vec3(0.0f);
    s.tone_mapping = ToneMapping::None;
    s.exposure = 1.0f;
    return s;
}

class SkinQuad : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        PlatformOptions o;
        o.width = o.height = kSkinFrame;
        o.samples = 4;
        platform_ = std::make_unique<HeadlessPlatform>(o);
        renderer_ = std::make_unique<Renderer>(*platform_);
        white_ = renderer_->add_mesh(make_quad(UvLayout::VUp), Material{});
    }
    static void TearDownTestSuite() {
        renderer_.reset();
        platform_.reset();
    }

    // The mean linear value (sRGB decoded) of the frame's central 4x4 pixels.
    static glm::vec3 draw(const glm::vec3& albedo, float view_deg, const Light& light,
                          const SkinShading& skin) {
        Material m;
        m.base_color = albedo;
        return draw(m, view_deg, light, skin);
    }
    static glm::vec3 draw(const Material& m, float view_deg, const Light& light, const SkinShading& skin) {
        renderer_->set_material(white_, m);
        DrawOptions d;
        d.camera.position = {0.0f, 0.0f, 50.0f};
        d.camera.view = glm::lookAt(d.camera.position, glm::vec3(0), glm::vec3(0, 1, 0));
        d.camera.projection = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, 40.0f, 60.0f);
        // Large enough to fill the frame even when seen at 85 degrees.
        d.model = glm::rotate(glm::mat4(1.0f), glm::radians(view_deg), glm::vec3(1, 0, 0)) *
                  glm::scale(glm::mat4(1.0f), glm::vec3(2.0f, 24.0f, 1.0f));
        d.light = light;
        d.shading = Shading::Skin;
        d.skin = skin;
        platform_->begin_frame();
        renderer_->draw(d, nullptr);
        platform_->end_frame();
        const ImageRGBA8 img = platform_->read_rgba();
        glm::vec3 sum(0.0f);
        for (int y = kSkinFrame / 2 - 2; y < kSkinFrame / 2 + 2; ++y)
            for (int x = kSkinFrame / 2 - 2; x < kSkinFrame / 2 + 2; ++x)
                for (int c = 0; c < 3; ++c) sum[c] += srgb_to_linear(img.at(x, y)[c] / 255.0f);
        return sum / 16.0f;
    }

    static std::unique_ptr<HeadlessPlatform> platform_;
    static std::unique_ptr<Renderer> renderer_;
    static Renderer::MeshId white_;
};
std::unique_ptr<HeadlessPlatform> SkinQuad::platform_;
std::unique_ptr<Renderer> SkinQuad::renderer_;
Renderer::MeshId SkinQuad::white_ = -1;

// White furnace by reciprocity: for a fixed view, the light swept over a
// Fibonacci sphere of directions, each of radiance 1 over its solid angle.
// What a white surface sends back, summed, is its directional albedo: at
// most 1 (all the light it gets), and most of it for a white diffuser.
TEST_F(SkinQuad, WhiteSurfaceNeverReturnsMoreLightThanItGets) {
    constexpr int kDirections = 400;
    constexpr float kIntensity = 0.5f;  // the sharp lobe's peak stays below 1
    const SkinShading skin = dark_rig();
    for (const float view_deg : {0.0f, 60.0f, 80.0f}) {
        double albedo = 0.0;
        const double golden = 3.14159265358979 * (3.0 - std::sqrt(5.0));
        for (int k = 0; k < kDirections; ++k) {
            const double z = 1.0 - (k + 0.5) * 2.0 / kDirections;
            const double r = std::sqrt(1.0 - z * z), phi = golden * k;
            Light light;
            light.position = glm::vec4(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z), 0.0f);
            light.diffuse = glm::vec3(kIntensity);
            const glm::vec3 c = draw(glm::vec3(1.0f), view_deg, light, skin);
            // A light of colour I is E / pi: the solid angle 4 pi / N of
            // unit radiance gives I = 4 / N.
            albedo += double(c.g) / kIntensity * 4.0 / kDirections;
        }
        // 0.98 head-on and at 60 degrees, 0.83 at 80 (one-bounce GGX loses
        // some light at grazing angles).
        EXPECT_LE(albedo, 1.02) << "seen at " << view_deg << " degrees";
        EXPECT_GE(albedo, view_deg < 70.0f ? 0.9 : 0.75) << "seen at " << view_deg << " degrees";
    }
}

// A black surface under a uniform white sky reflects only its sheen, which
// Fresnel makes rise towards grazing angles: F0 = 0.028 head-on.
TEST_F(SkinQuad, FresnelSheenRisesAtGrazingAngles) {
    SkinShading skin = dark_rig();
    skin.sky = skin.ground = glm::vec3(1.0f);
    Light off;
    off.diffuse = glm::vec3(0.0f);
    float previous = 0.0f;
    std::vector<float> seen;
    for (const float view_deg : {0.0f, 40.0f, 60.0f, 75.0f, 85.0f}) {
        const glm::vec3 c = draw(glm::vec3(0.0f), view_deg, off, skin);
        EXPECT_NEAR(c.r, c.g, 0.005f) << "an uncoloured reflection";
        EXPECT_GT(c.g, previous) << "at " << view_deg << " degrees";
        previous = c.g;
        seen.push_back(c.g);
    }
    EXPECT_NEAR(seen.front(), 0.028f, 0.012f) << "head-on reflectance is about F0";
    EXPECT_GT(seen.back(), 3.0f * seen.front());
}

// The ACES curve: black stays black, more light never gives a darker pixel,
// and bright light rolls off to white instead of clipping early.
TEST_F(SkinQuad, ToneMappingIsMonotonicAndKeepsBlack) {
    SkinShading skin = dark_rig();
    skin.tone_mapping = ToneMapping::Aces;
    Light light;
    light.position = glm::vec4(0.0f, 0.0f, 1.0f, 0.0f);
    glm::vec3 previous(-1.0f);
    for (const float intensity : {0.0f, 0.01f, 0.03f, 0.1f, 0.2f, 0.4f, 0.8f, 1.5f, 3.0f, 8.0f, 30.0f}) {
        light.diffuse = glm::vec3(intensity);
        const glm::vec3 c = draw(glm::vec3(0.8f, 0.6f, 0.5f), 0.0f, light, skin);
        if (intensity == 0.0f) EXPECT_EQ(c, glm::vec3(0.0f));
        for (int ch = 0; ch < 3; ++ch) {
            EXPECT_GE(c[ch], previous[ch]) << "intensity " << intensity << " channel " << ch;
            if (intensity > 0.0f && intensity <= 1.5f)
                EXPECT_GT(c[ch], previous[ch]) << "intensity " << intensity << " channel " << ch;
        }
        previous = c;
    }
    EXPECT_GT(previous.r, 0.95f);
    EXPECT_LT(previous.r, 1.0f + 1e-6f);
}

// Without the rig, the wrinkle map's alpha is its cavity: 1 (255) is open
// skin, the same as no map; a cavity darkens the skin under the key light.
TEST_F(SkinQuad, WrinkleAlphaIsACavity) {
    const SkinShading skin = dark_rig();
    Material m;
    m.base_color = glm::vec3(0.7f);
    renderer_->set_material(white_, m);
    auto draw_with_alpha = [&](const WrinkleTexture* map) {
        DrawOptions d;
        d.camera = ortho_camera();
        d.light = directional({0.2f, 0.3f, 1.0f});
        d.skin = skin;
        platform_->begin_frame();
        renderer_->draw(d, map);
        platform_->end_frame();
        return platform_->read_rgba();
    };
    auto flat_map = [](std::uint8_t alpha) {
        auto map = std::make_unique<WrinkleTexture>(4, 4, TexelFormat::RGBA8, NormalEncoding::Unsigned);
        std::vector<std::uint8_t> px(4 * 4 * 4);
        for (int i = 0; i < 16; ++i) {
            px[i * 4 + 0] = 128; px[i * 4 + 1] = 128; px[i * 4 + 2] = 255; px[i * 4 + 3] = alpha;
        }
        map->upload(px.data());
        return map;
    };
    const ImageRGBA8 none = draw_with_alpha(nullptr);
    const auto open = flat_map(255), cavity = flat_map(64);
    const ImageRGBA8 open_skin = draw_with_alpha(open.get()), creviced = draw_with_alpha(cavity.get());
    const int c = kSkinFrame / 2;
    for (int ch = 0; ch < 3; ++ch) {
        EXPECT_NEAR(open_skin.at(c, c)[ch], none.at(c, c)[ch], 1) << "channel " << ch;
        EXPECT_LT(creviced.at(c, c)[ch] + 5, open_skin.at(c, c)[ch]) << "channel " << ch;
    }
}

// The base map's alpha is the region's roughness scale (the default face's
// painter: lips, T-zone, tear line below 1): a glossier region's lobe is
// narrower, brighter towards the mirror direction and darker away from it.
TEST_F(SkinQuad, BaseMapAlphaNarrowsTheSheen) {
    SkinShading skin = dark_rig();
    skin.albedo_bump_mm = 0.0f;
    auto sheen = [&](std::uint8_t alpha, const glm::vec3& towards) {
        Material m;
        auto base = std::make_shared<ImageRGBA8>(4, 4);
        for (int i = 0; i < 16; ++i) {
            std::uint8_t* p = base->pixels.data() + 4 * i;
            p[0] = p[1] = p[2] = 0;  // black: only the sheen comes back
            p[3] = alpha;
        }
        m.base_texture = base;
        Light light;
        light.position = glm::vec4(glm::normalize(towards), 0.0f);
        light.diffuse = glm::vec3(1.0f);
        return draw(m, 0.0f, light, skin).g;
    };
    const glm::vec3 mirror{0.0f, 0.0f, 1.0f}, off{0.0f, std::sin(0.9f), std::cos(0.9f)};  // 52 degrees off
    const float rough_peak = sheen(255, mirror), glossy_peak = sheen(90, mirror);
    const float rough_off = sheen(255, off), glossy_off = sheen(90, off);
    EXPECT_GT(glossy_peak, 1.5f * rough_peak) << "a narrower lobe is brighter at its peak";
    EXPECT_LT(glossy_off, 0.8f * rough_off) << "and darker away from it";
    // Alpha 255 is the data's roughness, the same as no base map.
    Light head_on;
    head_on.position = glm::vec4(mirror, 0.0f);
    head_on.diffuse = glm::vec3(1.0f);
    EXPECT_NEAR(rough_peak, draw(glm::vec3(0.0f), 0.0f, head_on, skin).g, 0.002f);
}

// The base colour's relief, baked at load into slopes (render/src/skin_maps.h):
// at a step from a light half (left, -x) to a dark one the surface steps
// down towards +x, so its normal leans to +x and a light from +x lights it
// more than the mirrored light from -x; without the relief both are equal.
TEST_F(SkinQuad, AlbedoReliefLeansTheNormalDownItsSlope) {
    SkinShading skin = dark_rig();
    skin.pore_strength = 0.0f;
    Material m;
    auto base = std::make_shared<ImageRGBA8>(16, 16);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            std::uint8_t* p = base->at(x, y);
            p[0] = p[1] = p[2] = x < 8 ? 200 : 90;
            p[3] = 255;
        }
    m.base_texture = base;
    m.uses_wrinkle_map = true;  // a skin surface
    auto lit_from = [&](float side) {
        Light light;
        light.position = glm::vec4(glm::normalize(glm::vec3(side, 0.0f, 0.6f)), 0.0f);
        light.diffuse = glm::vec3(1.0f);
        return draw(m, 0.0f, light, skin).g;
    };
    skin.albedo_bump_mm = 0.0f;
    const float flat_plus = lit_from(1.0f), flat_minus = lit_from(-1.0f);
    EXPECT_NEAR(flat_plus, flat_minus, 0.01f * flat_plus) << "no relief: mirrored lights light it alike";
    skin.albedo_bump_mm = 0.15f * skin.mm_per_unit;
    const float plus = lit_from(1.0f), minus = lit_from(-1.0f);
    EXPECT_GT(plus, 1.1f * minus) << "the step down towards +x faces the light from +x";
    EXPECT_GT(plus, flat_plus);
    EXPECT_LT(minus, flat_minus);
}

// Hair (a base colour whose local mean is darker than
// SkinShading::hair_luminance) is not skin: at its terminator a grey hair
// stays grey and dark (a little wrap), where skin's wrap and scattering
// carry light past it.
TEST_F(SkinQuad, HairIsLitWithoutSkinsScatteringAtItsTerminator) {
    SkinShading skin = dark_rig();
    skin.pore_strength = 0.0f;
    skin.key_tint = glm::vec3(1.0f);
    // A soft rig (skin.json's was 0.2 before the portrait rig's 0.1): the
    // test tells the two terminators apart, not the rig's softness.
    skin.softness = 0.2f;
    Material m;
    auto base = std::make_shared<ImageRGBA8>(16, 16);
    for (int y = 0; y < 16; ++y)
        for (int x = 0; x < 16; ++x) {
            std::uint8_t* p = base->at(x, y);
            p[0] = p[1] = p[2] = 60;  // linear luminance 0.045
            p[3] = 255;
        }
    m.base_texture = base;
    m.uses_wrinkle_map = true;  // a skin surface
    Light light;
    light.position = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);  // at the terminator
    light.diffuse = glm::vec3(20.0f);  // bright enough for 8-bit channels to tell red from green
    ASSERT_LT(0.045f, skin.hair_luminance[0]);
    const glm::vec3 hair = draw(m, 0.0f, light, skin);
    skin.hair_luminance = {0.0f, 0.001f};  // the same colour taken for skin
    const glm::vec3 as_skin = draw(m, 0.0f, light, skin);
    ASSERT_GT(hair.g, 0.0f);
    ASSERT_GT(as_skin.g, 0.0f);
    EXPECT_NEAR(hair.r, hair.g, 0.03f * hair.g) << "grey hair stays grey";
    EXPECT_LT(hair.g, 0.5f * as_skin.g) << "hair's terminator is a Lambert one, barely wrapped";
}

// The GPU draw order: runs of kFrontFirstRun triangles nearest +z first, each
// run whole and in its own order, every triangle kept once. Three layers of
// two runs each are listed back (z 0), front (z 2), middle (z 1), and a
// short last run of one triangle lies in front of all.
TEST(DrawOrder, RunsNearestTheFrontalCameraFirst) {
    TriMesh mesh;
    const float layer_z[3] = {0.0f, 2.0f, 1.0f};
    std::vector<std::uint32_t> triangles;
    std::vector<float> triangle_z;
    for (const float z : layer_z)
        for (std::size_t t = 0; t < 2 * kFrontFirstRun; ++t) {
            for (int c = 0; c < 3; ++c) {
                // Each triangle's own vertices, leaning a little within the
                // layer so that a run's mean stays the layer's depth.
                const float x = float(t) + (c == 1 ? 1.0f : 0.0f), y = c == 2 ? 1.0f : 0.0f;
                const float lean = 0.01f * (float(c) - 1.0f);
                triangles.push_back(std::uint32_t(mesh.add_vertex({x, y, z + lean}).idx()));
            }
            triangle_z.push_back(z);
        }
    for (int c = 0; c < 3; ++c) triangles.push_back(std::uint32_t(mesh.add_vertex({float(c), float(c == 2), 5.0f}).idx()));
    triangle_z.push_back(5.0f);
    const std::vector<std::uint32_t> given = triangles;

    order_front_first(mesh, triangles);
    ASSERT_EQ(triangles.size(), given.size());
    // Each triangle's vertices are its own (first vertex index / 3 = the
    // triangle it was listed as), so the order can be read back.
    std::vector<std::size_t> listed;
    for (std::size_t t = 0; t < triangles.size() / 3; ++t) {
        const std::uint32_t first = triangles[3 * t];
        ASSERT_EQ(first % 3, 0u);
        EXPECT_EQ(triangles[3 * t + 1], first + 1);
        EXPECT_EQ(triangles[3 * t + 2], first + 2);
        listed.push_back(first / 3);
    }
    std::vector<std::size_t> expected;
    expected.push_back(6 * kFrontFirstRun);                                            // the short run at z 5
    for (std::size_t t = 2 * kFrontFirstRun; t < 4 * kFrontFirstRun; ++t) expected.push_back(t);  // front
    for (std::size_t t = 4 * kFrontFirstRun; t < 6 * kFrontFirstRun; ++t) expected.push_back(t);  // middle
    for (std::size_t t = 0; t < 2 * kFrontFirstRun; ++t) expected.push_back(t);                   // back
    EXPECT_EQ(listed, expected);
    for (std::size_t i = 1; i < listed.size(); ++i)
        EXPECT_GE(triangle_z[listed[i - 1]], triangle_z[listed[i]]) << "position " << i;
}

#ifdef EMOFACE_DATA_DIR
// The baked ambient occlusion (Renderer::set_occlusion) under the sky
// alone: an occluded surface gets less of the sky's diffuse light, and its
// sheen (a black surface: nothing else comes back) fades with it, as the
// wrinkle cavity's does.
TEST_F(SkinQuad, OcclusionDimsTheSkyAndItsSheen) {
    SkinShading skin = dark_rig();
    skin.sky = skin.ground = glm::vec3(0.6f);
    Light off;
    off.diffuse = glm::vec3(0.0f);
    Material m;
    m.uses_wrinkle_map = true;  // a skin surface
    const std::size_t n = make_quad(UvLayout::VUp).n_vertices();
    auto lit = [&](const glm::vec3& albedo, float occlusion, float view_deg) {
        renderer_->set_occlusion(white_, std::vector<float>(n, occlusion));
        m.base_color = albedo;
        return draw(m, view_deg, off, skin);
    };
    const glm::vec3 grey(0.5f), black(0.0f);
    const glm::vec3 open = lit(grey, 1.0f, 0.0f), shut = lit(grey, 0.3f, 0.0f);
    const float open_sheen = lit(black, 1.0f, 60.0f).g, shut_sheen = lit(black, 0.3f, 60.0f).g;
    renderer_->set_occlusion(white_, std::vector<float>(n, 1.0f));  // the other tests' quad: open
    EXPECT_LT(shut.g, 0.6f * open.g) << "occlusion dims the sky's diffuse light";
    EXPECT_GT(shut.g, 0.0f);
    EXPECT_GT(open_sheen, 0.0f);
    EXPECT_LT(shut_sheen, 0.5f * open_sheen) << "and its sheen";
}

// The key's contact shadow (shaders.cpp, u_key_cone): an occluded point is
// open to a cone that leans down from its normal (a face's occluders lie
// above), so a grazing key from above is dimmed by up to occlusion.key, the
// same key from below less, a key the surface faces is not dimmed at all,
// and an open point (occlusion 1) never is. The thesis shading ignores it.
TEST_F(SkinQuad, KeyContactShadowFollowsTheOcclusionsCone) {
    const SkinShading skin = dark_rig();
    Material m;
    m.uses_wrinkle_map = true;  // a skin surface
    m.base_color = glm::vec3(0.5f);
    const std::size_t n = make_quad(UvLayout::VUp).n_vertices();
    const float graze = glm::radians(75.0f);
    auto lit = [&](float occlusion, glm::vec3 towards, Shading shading = Shading::Skin) {
        renderer_->set_occlusion(white_, std::vector<float>(n, occlusion));
        Light key = directional(towards);
        if (shading == Shading::Skin) return draw(m, 0.0f, key, skin).g;
        renderer_->set_material(white_, m);
        DrawOptions d;
        d.camera.position = {0.0f, 0.0f, 50.0f};
        d.camera.view = glm::lookAt(d.camera.position, glm::vec3(0), glm::vec3(0, 1, 0));
        d.camera.projection = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, 40.0f, 60.0f);
        d.model = glm::scale(glm::mat4(1.0f), glm::vec3(2.0f, 24.0f, 1.0f));
        d.light = key;
        d.shading = shading;
        platform_->begin_frame();
        renderer_->draw(d, nullptr);
        platform_->end_frame();
        return srgb_to_linear(platform_->read_rgba().at(kSkinFrame / 2, kSkinFrame / 2)[1] / 255.0f);
    };
    const glm::vec3 above(0.0f, std::sin(graze), std::cos(graze)), below(0.0f, -std::sin(graze), std::cos(graze));
    const glm::vec3 facing(0.0f, 0.0f, 1.0f);
    const float open_above = lit(1.0f, above), shut_above = lit(0.3f, above);
    const float open_below = lit(1.0f, below), shut_below = lit(0.3f, below);
    const float open_facing = lit(1.0f, facing), shut_facing = lit(0.3f, facing);
    const float thesis_open = lit(1.0f, above, Shading::Thesis), thesis_shut = lit(0.3f, above, Shading::Thesis);
    renderer_->set_occlusion(white_, std::vector<float>(n, 1.0f));  // the other tests' quad: open
    ASSERT_GT(open_above, 0.01f);
    // Occlusion 0.3: the cone's cos is capped at key_cone_max 0.5; from
    // above, N.L 0.26 less the lean lies below the 0.3-wide ramp: 1 - 0.4.
    EXPECT_NEAR(shut_above / open_above, 1.0f - skin.occlusion_key, 0.06f) << "a grazing key from above";
    EXPECT_GT(shut_below / open_below, shut_above / open_above + 0.1f) << "the cone leans down";
    EXPECT_LT(shut_below / open_below, 0.97f);
    EXPECT_NEAR(shut_facing / open_facing, 1.0f, 0.02f) << "skin facing the key stays lit";
    EXPECT_NEAR(thesis_shut, thesis_open, 1e-6f) << "the thesis's Blinn-Phong has no occlusion";
}

// The key's baked cast shadow (Renderer::set_key_shadow): while the key
// shines from where the shadow was baked, a point the bake saw in shadow
// loses key_shadow of the key's light; a key 30 degrees away (past
// key_shadow_fade_deg) ignores it, as does a point the bake saw lit.
TEST_F(SkinQuad, BakedKeyShadowHoldsWhileTheKeyIsWhereItWasBaked) {
    const SkinShading skin = dark_rig();
    ASSERT_LT(skin.key_shadow_fade_deg[1], 30.0f);
    Material m;
    m.uses_wrinkle_map = true;  // a skin surface
    m.base_color = glm::vec3(0.5f);
    // The shadow is drawn from the base map's relief map (its alpha).
    auto white = std::make_shared<ImageRGBA8>(8, 8);
    std::fill(white->pixels.begin(), white->pixels.end(), std::uint8_t(255));
    m.base_texture = white;
    const std::size_t n = make_quad(UvLayout::VUp).n_vertices();
    const glm::vec3 baked(0.0f, 0.0f, 1.0f), away(0.0f, std::sin(glm::radians(30.0f)), std::cos(glm::radians(30.0f)));
    auto lit = [&](float visible, glm::vec3 towards) {
        renderer_->set_key_shadow(white_, std::vector<float>(n, visible), baked);
        return draw(m, 0.0f, directional(towards), skin).g;
    };
    const float open_baked = lit(1.0f, baked), shut_baked = lit(0.0f, baked);
    const float open_away = lit(1.0f, away), shut_away = lit(0.0f, away);
    // Without a base map there is no relief map to carry the shadow.
    Material plain = m;
    plain.base_texture = nullptr;
    const float plain_shut = draw(plain, 0.0f, directional(baked), skin).g;
    renderer_->set_key_shadow(white_, std::vector<float>(n, 1.0f), baked);  // the other tests' quad: lit
    const float plain_open = draw(plain, 0.0f, directional(baked), skin).g;
    ASSERT_GT(open_baked, 0.05f);
    EXPECT_NEAR(shut_baked / open_baked, 1.0f - skin.key_shadow, 0.05f) << "in the baked shadow";
    EXPECT_NEAR(shut_away / open_away, 1.0f, 0.02f) << "a key moved away ignores it";
    EXPECT_NEAR(plain_shut, plain_open, 1e-6f);
    EXPECT_THROW(renderer_->set_key_shadow(white_, std::vector<float>(n + 1, 1.0f), baked), emoface::Error);
}

// The dim lights (fill, rim) shade with wrapped Lambert instead of the
// scattering table (shaders.cpp): that holds while the table's flattest row,
// where most of the face is looked up, is Lambert.
TEST(SkinMaps, ScatterTablesFlattestRowIsLambert) {
    constexpr int kWidth = 128, kHeight = 64;
    const SkinShading skin;
    const std::vector<float> table = emoface::render::detail::preintegrated_scatter_table(skin, kWidth, kHeight);
    const int row = int(skin.min_curvature / skin.max_curvature * kHeight);
    float worst = 0.0f;
    for (int i = 0; i < kWidth; ++i) {
        const float n_dot_l = -1.0f + 2.0f * (i + 0.5f) / kWidth;
        for (int c = 0; c < 3; ++c)
            worst = std::max(worst, std::abs(table[(std::size_t(row) * kWidth + i) * 3 + c] - std::max(n_dot_l, 0.0f)));
    }
    EXPECT_LT(worst, 0.03f) << "row " << row;
    // ... and is not at the top row: the key's lookups are not Lambert there.
    float top = 0.0f;
    for (int i = 0; i < kWidth; ++i) {
        const float n_dot_l = -1.0f + 2.0f * (i + 0.5f) / kWidth;
        top = std::max(top, std::abs(table[(std::size_t(kHeight - 1) * kWidth + i) * 3] - std::max(n_dot_l, 0.0f)));
    }
    EXPECT_GT(top, 2.0f * worst) << "top row " << top << ", flattest " << worst;
}

// The pore map (skin_maps.h): pits over a network of furrows that cross
// (the skin's microrelief), tiling without a seam.
// Vertex values painted into the base UVs (the key's baked shadow in the
// relief map's alpha): interpolated across a triangle, grown a few texels
// past its edge into the gutter, and `empty` beyond that.
TEST(SkinMaps, VertexValuesArePaintedIntoTheirUvsAndGrownPastTheEdges) {
    using emoface::render::detail::vertex_values_in_uv;
    // One triangle over the lower-left half of a 16x16 map: 0 at u = 0, 1 at u = 1.
    const std::vector<glm::vec2> uvs = {{0.0f, 0.0f}, {1.0f, 0.0f}, {0.0f, 1.0f}};
    const std::vector<unsigned> triangle = {0, 1, 2};
    const std::vector<float> values = {0.0f, 1.0f, 0.0f};
    const std::vector<float> map = vertex_values_in_uv(uvs, triangle, values, 16, 16, 2, -1.0f);
    ASSERT_EQ(map.size(), 256u);
    auto at = [&](int x, int y) { return map[std::size_t(y) * 16 + std::size_t(x)]; };
    EXPECT_NEAR(at(0, 0), 0.5f / 16.0f, 1e-5f);
    EXPECT_NEAR(at(7, 3), 7.5f / 16.0f, 1e-5f);    // u = 7.5 / 16 inside
    EXPECT_GT(at(8, 8), 0.0f) << "the texel past the diagonal is grown from its neighbours";
    EXPECT_EQ(at(15, 15), -1.0f) << "far from the triangle: empty";
    EXPECT_THROW(vertex_values_in_uv(uvs, triangle, {0.0f}, 16, 16, 2, 1.0f), emoface::Error);
    EXPECT_THROW(vertex_values_in_uv(uvs, {0, 1, 3}, values, 16, 16, 2, 1.0f), emoface::Error);
}

TEST(SkinMaps, PoreMapIsPitsOverCrossingFurrowsAndTiles) {
    emoface::render::PoreMapSpec spec;
    const int n = spec.size;
    const std::vector<std::uint8_t> map = emoface::render::detail::pore_map(spec);
    ASSERT_EQ(map.size(), std::size_t(n) * n * 4);
    auto at = [&](const std::vector<std::uint8_t>& m, int x, int y, int c) {
        return int(m[(std::size_t((y + n) % n) * n + std::size_t((x + n) % n)) * 4 + std::size_t(c)]);
    };
    // Tiles: the normal steps across the tile's edge no more than between
    // neighbours inside it.
    double inside = 0.0, seam = 0.0;
    for (int k = 0; k < n; ++k)
        for (int c = 0; c < 2; ++c) {
            seam += std::abs(at(map, n - 1, k, c) - at(map, 0, k, c)) + std::abs(at(map, k, n - 1, c) - at(map, k, 0, c));
            inside += std::abs(at(map, n / 2 - 1, k, c) - at(map, n / 2, k, c)) +
                      std::abs(at(map, k, n / 2 - 1, c) - at(map, k, n / 2, c));
        }
    EXPECT_LT(seam, 1.5 * inside) << "a seam at the tile's edge";
    // Pits: deep cavities on mostly open skin.
    int deepest = 255;
    double mean = 0.0;
    for (int i = 0; i < n * n; ++i) {
        deepest = std::min(deepest, int(map[std::size_t(i) * 4 + 3]));
        mean += map[std::size_t(i) * 4 + 3];
    }
    mean /= double(n) * n;
    EXPECT_LT(deepest, 150);
    EXPECT_GT(mean, 0.8 * 255.0);
    // Without the pits, the furrows' relief remains, and it runs every way
    // (families of lines that cross, not one grain): the normals' tilt,
    // binned by its axis, has weight in every bin.
    spec.pit_depth = 0.0f;
    const std::vector<std::uint8_t> furrows = emoface::render::detail::pore_map(spec);
    constexpr int kBins = 6;
    std::array<double, kBins> tilt{};
    double mean_tilt = 0.0;
    for (int i = 0; i < n * n; ++i) {
        const double x = furrows[std::size_t(i) * 4] / 127.5 - 1.0, y = furrows[std::size_t(i) * 4 + 1] / 127.5 - 1.0;
        double axis = std::atan2(y, x);
        if (axis < 0.0) axis += 3.14159265358979;
        tilt[std::size_t(std::min(kBins - 1, int(axis / 3.14159265358979 * kBins)))] += x * x + y * y;
        mean_tilt += std::hypot(x, y);
    }
    mean_tilt /= double(n) * n;
    EXPECT_GT(mean_tilt, 0.1) << "relief between the pits";
    const double total = tilt[0] + tilt[1] + tilt[2] + tilt[3] + tilt[4] + tilt[5];
    for (int b = 0; b < kBins; ++b) EXPECT_GT(tilt[std::size_t(b)], 0.3 * total / kBins) << "tilts about axis bin " << b;
}

// SkinShading's defaults are data/render/skin.json's values.
TEST(SkinShadingData, DefaultsAreTheDataFile) {
    const SkinShading loaded = load_skin_shading(std::string(EMOFACE_DATA_DIR) + "/render/skin.json");
    EXPECT_TRUE(loaded == SkinShading{}) << "render/skin_shading.h and data/render/skin.json differ";
}
TEST(SkinShadingData, UnknownKeysAndBadValuesAreInputErrors) {
    const std::string dir = ::testing::TempDir();
    std::string text;
    {
        std::ifstream in(std::string(EMOFACE_DATA_DIR) + "/render/skin.json");
        text.assign(std::istreambuf_iterator<char>(in), {});
    }
    auto write = [&](const std::string& name, const std::string& body) {
        std::ofstream(dir + name) << body;
        return dir + name;
    };
    std::string bad = text;
    bad.replace(bad.find("\"f0\": 0.028"), 11, "\"f0\": 1.5");
    EXPECT_THROW(load_skin_shading(write("skin_bad_f0.json", bad)), emoface::InputError);
    bad = text;
    bad.replace(bad.find("\"aces\""), 6, "\"filmic\"");
    EXPECT_THROW(load_skin_shading(write("skin_bad_tone.json", bad)), emoface::InputError);
    EXPECT_THROW(load_skin_shading(dir + "no_such_skin.json"), emoface::InputError);
}
#endif

}  // namespace
