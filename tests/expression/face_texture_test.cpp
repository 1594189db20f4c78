// The default face's painted base colour (expression/src/face_texture.cpp):
// brows as hairs that travel with the brow, a soft hairline, cheeks without
// painted discs, and per-region roughness in the alpha channel. Texels are
// found through the mesh's own UVs from the neutral 3D positions face.json
// describes (mm).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "emoface/expression/default_face.h"
#include "emoface/expression/rig.h"
#include "emoface/fap/feature_points.h"
#include "test_face.h"

namespace emoface::expression {
namespace {

constexpr int kSize = 1024;

// A face with a texture fine enough to hold hairs (the shared test face's
// 64 texels cannot); half the mesh resolution keeps it quick.
const Face& painted_face() {
    static const Face face = [] {
        DefaultFaceOptions options;
        options.resolution_scale = 0.5;
        options.texture_size = kSize;
        return make_default_face(testing::data_dir() + "/face", options);
    }();
    return face;
}

struct Texel {
    double r, g, b, a;  // 0..1
    double luminance() const { return 0.2126 * r + 0.7152 * g + 0.0722 * b; }
};

// The same face without the forelock's stray strands (face.json hair
// forelock locks 0): the hairline's own band, with nothing crossing it.
const Face& face_without_forelock() {
    static const Face face = [] {
        std::ifstream in(testing::data_dir() + "/face/face.json");
        std::string text(std::istreambuf_iterator<char>(in), {});
        const std::string key = "\"locks\": ";
        const auto at = text.find(key);
        if (at == std::string::npos) throw std::runtime_error("face.json: no " + key);
        const auto end = text.find_first_of(",}", at + key.size());
        text.replace(at + key.size(), end - at - key.size(), "0");
        const auto dir = std::filesystem::temp_directory_path() / ("emoface_no_forelock_" + std::to_string(::getpid()));
        std::filesystem::create_directories(dir);
        std::ofstream(dir / "face.json") << text;
        DefaultFaceOptions options;
        options.resolution_scale = 0.5;
        options.texture_size = kSize;
        Face f = make_default_face(dir.string(), options);
        std::filesystem::remove_all(dir);
        return f;
    }();
    return face;
}

Texel texel_at(double u, double v, const Face& face = painted_face()) {
    const Image& img = face.base_colour;
    const int x = std::clamp(static_cast<int>(u * img.width), 0, img.width - 1);
    const int y = std::clamp(static_cast<int>((1.0 - v) * img.height), 0, img.height - 1);
    const std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * img.width + x) * 4];
    return {p[0] / 255.0, p[1] / 255.0, p[2] / 255.0, p[3] / 255.0};
}
Texel texel_of(int vertex) {
    const auto t = painted_face().mesh.texcoord2D(TriMesh::VertexHandle(vertex));
    return texel_at(t[0], t[1]);
}

// The front-facing skin vertex nearest (x, y) in frontal projection. The
// lashes are skin too, but take their colour from the atlas' tiles (v below
// 0.25, face_texture.h kSkinV0), not the skin's painting.
int front_vertex(double x, double y, const Face& f = painted_face()) {
    int best = -1;
    double best_d = 1e18;
    for (int v = 0; v < f.vertex_count(); ++v) {
        if (f.parts[v] != VertexPart::Skin || f.mesh.texcoord2D(TriMesh::VertexHandle(v))[1] < 0.25) continue;
        const auto p = f.mesh.point(TriMesh::VertexHandle(v));
        const auto n = f.mesh.normal(TriMesh::VertexHandle(v));
        if (n[2] < 0.3) continue;
        const double d = (p[0] - x) * (p[0] - x) + (p[1] - y) * (p[1] - y);
        if (d < best_d) {
            best_d = d;
            best = v;
        }
    }
    return best;
}

// Luminance along the straight UV path between the vertices nearest two
// frontal points, `steps` + 1 samples.
// The texel a frontal camera sees at (x, y): through the nearest (largest
// z) skin triangle over that point, its UVs interpolated (the lids' rounded
// margins lie between vertices, and the nearest vertex skips them).
Texel seen_at(double x, double y, const Face& f = painted_face()) {
    double best_z = -1e18;
    OpenMesh::Vec2f uv(0.0f, 0.0f);
    for (const auto fh : f.mesh.faces()) {
        std::array<TriMesh::VertexHandle, 3> v;
        int n = 0;
        for (const auto vh : f.mesh.fv_range(fh)) v[n++] = vh;
        bool skin = true;
        for (const auto vh : v)
            skin = skin && f.parts[vh.idx()] == VertexPart::Skin && f.mesh.texcoord2D(vh)[1] >= 0.25;
        if (!skin) continue;
        const auto hit = testing::front_crossing(f.mesh.point(v[0]), f.mesh.point(v[1]), f.mesh.point(v[2]), x, y);
        if (!hit || hit->z <= best_z) continue;
        best_z = hit->z;
        uv = OpenMesh::Vec2f(0.0f, 0.0f);
        for (int k = 0; k < 3; ++k) uv += f.mesh.texcoord2D(v[k]) * static_cast<float>(hit->w[k]);
    }
    return texel_at(uv[0], uv[1], f);
}

std::vector<double> luminance_between(double x, double y0, double y1, int steps, const Face& f = painted_face()) {
    const auto a = f.mesh.texcoord2D(TriMesh::VertexHandle(front_vertex(x, y0, f)));
    const auto b = f.mesh.texcoord2D(TriMesh::VertexHandle(front_vertex(x, y1, f)));
    std::vector<double> out;
    for (int k = 0; k <= steps; ++k) {
        const double t = static_cast<double>(k) / steps;
        out.push_back(texel_at(a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t, f).luminance());
    }
    return out;
}

// Brow hairs travel with the brow: the texels that are brow hair belong to
// vertices the brow raise lifts, so after the raise the hair-dark vertices
// have moved up by about as much as the brow's feature points (a brow painted
// in a fixed frontal projection would stay put and smear).
TEST(FaceTexture, BrowHairsMoveWithTheRaisedBrow) {
    const Face& f = painted_face();
    const FaceRig rig(f);
    FapValues faps{};
    for (int fap = 31; fap <= 36; ++fap) faps[fap - 1] = 300;  // raise inner, middle, outer brows
    const DeformedFace raised = rig.deform(faps);
    const double skin = texel_of(front_vertex(0, 40)).luminance();
    double brow_rise = 0.0;
    for (const char* id : {"4.1", "4.2", "4.3", "4.4", "4.5", "4.6"}) {
        const int k = fap::feature_point_index(id);
        brow_rise += (raised.feature_points[k][1] - f.feature_points[k].position[1]) / 6.0;
    }
    ASSERT_GT(brow_rise, 2.0) << "the brow raise lifts the brows";
    double rise = 0.0;
    int dark = 0;
    for (int v = 0; v < f.vertex_count(); ++v) {
        const auto p = f.mesh.point(TriMesh::VertexHandle(v));
        // Above the upper lashes' tips (lashes are skin too, dark, and the
        // brow raise barely moves them).
        if (f.parts[v] != VertexPart::Skin || p[2] < 40 || p[1] < 10.5 || p[1] > 35 || std::abs(p[0]) > 60) continue;
        if (texel_of(v).luminance() > 0.5 * skin) continue;
        rise += raised.positions[v][1] - p[1];
        ++dark;

    }
    ASSERT_GT(dark, 20) << "brow hair vertices";
    EXPECT_GT(rise / dark, 0.6 * brow_rise);
}

// Brow hairs have a direction: the inner end's hairs grow upward, the
// outer part's run along the brow. The strokes' orientation (the structure
// tensor of the texture's luminance) is more vertical at the inner end.
TEST(FaceTexture, InnerBrowHairsStandUpAndOuterOnesLieAlong) {
    const Face& f = painted_face();
    const Image& img = f.base_colour;
    auto luminance = [&](int x, int y) {
        const std::uint8_t* p = &img.rgba[(static_cast<std::size_t>(y) * img.width + x) * 4];
        return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    };
    // Share of the gradient energy along the texture's columns (v): strokes
    // that run up and down have their gradients across, along u.
    auto vertical_gradient_share = [&](double x, double y) {
        const auto t = f.mesh.texcoord2D(TriMesh::VertexHandle(front_vertex(x, y)));
        const int cx = static_cast<int>(t[0] * img.width), cy = static_cast<int>((1.0 - t[1]) * img.height);
        double gxx = 0, gyy = 0;
        for (int y2 = cy - 5; y2 <= cy + 5; ++y2)
            for (int x2 = cx - 5; x2 <= cx + 5; ++x2) {
                const double gx = luminance(x2 + 1, y2) - luminance(x2 - 1, y2);
                const double gy = luminance(x2, y2 + 1) - luminance(x2, y2 - 1);
                gxx += gx * gx;
                gyy += gy * gy;
            }
        return gyy / (gxx + gyy + 1e-9);
    };
    const auto& inner = f.feature_points[fap::feature_point_index("4.1")].position;
    const auto& outer = f.feature_points[fap::feature_point_index("4.5")].position;
    // A little inside each end, where the hairs are dense.
    const double inner_share = vertical_gradient_share(inner[0] + 3.0, inner[1]);
    const double outer_share = vertical_gradient_share(outer[0] - 8.0, outer[1] + 1.0);
    EXPECT_LT(inner_share, 0.45) << "inner hairs stand up: their gradients run across the texture";
    EXPECT_GT(outer_share, 0.55) << "outer hairs lie along the brow: their gradients run up and down";
}

// The hairline is a band, not a cut: from the forehead up into the hair, the
// luminance falls over several millimetres, and its height, seen over 4 mm
// wide strips, changes little from one strip to the next (no saw-tooth).
// Measured without the forelock, whose strays cross the band on purpose.
TEST(FaceTexture, HairlineIsASoftSmoothBand) {
    constexpr double kFrom = 50.0, kTo = 80.0;  // mm; face.json hairline_y 64
    constexpr int kSteps = 300;                 // 0.1 mm a step
    std::vector<double> crossing;
    for (double x = -16.0; x <= 16.0; x += 2.0) {
        // Across a 4 mm wide strip: single fine hairs and tufts of them
        // reach out of the hair at random, so one line of texels meets them
        // by chance.
        std::vector<double> l(kSteps + 1, 0.0);
        for (double dx = -2.0; dx <= 2.0; dx += 0.5) {
            const std::vector<double> one = luminance_between(x + dx, kFrom, kTo, kSteps, face_without_forelock());
            for (std::size_t k = 0; k < l.size(); ++k) l[k] += one[k] / 9.0;
        }
        // Smooth over 2 mm so single hairs do not decide the edge.
        std::vector<double> s(l.size());
        for (std::size_t k = 0; k < l.size(); ++k) {
            double sum = 0;
            int n = 0;
            for (int d = -10; d <= 10; ++d) {
                const int j = static_cast<int>(k) + d;
                if (j < 0 || j >= static_cast<int>(l.size())) continue;
                sum += l[static_cast<std::size_t>(j)];
                ++n;
            }
            s[k] = sum / n;
        }
        // The hair's tone varies from clump to clump: its level is the mean of the top 3 mm.
        double hair = 0.0;
        for (int k = kSteps - 30; k <= kSteps; ++k) hair += s[static_cast<std::size_t>(k)] / 31.0;
        const double skin = s.front();
        ASSERT_GT(skin, 2.0 * hair) << "forehead skin below, hair above at x = " << x;
        auto first_below = [&](double level) {
            for (std::size_t k = 0; k < s.size(); ++k)
                if (s[k] < level) return static_cast<double>(k) * (kTo - kFrom) / kSteps;
            return kTo - kFrom;
        };
        const double start = first_below(hair + 0.9 * (skin - hair));
        const double end = first_below(hair + 0.1 * (skin - hair));
        EXPECT_GT(end - start, 3.0) << "mm from 90% skin to 10% at x = " << x;
        crossing.push_back(first_below(hair + 0.5 * (skin - hair)));
    }
    // Tufts of fine hairs and clumps of different tone move the strip's
    // half-way point by up to about 4 mm (measured 3.7); teeth cut into the
    // line would move it by their depth from one strip to the next.
    for (std::size_t k = 1; k < crossing.size(); ++k)
        EXPECT_LT(std::abs(crossing[k] - crossing[k - 1]), 4.5) << "hairline jumps between columns " << k - 1 << " and " << k;
}

// Stray strands hang over the forehead below the hairline's band (face.json
// hair forelock): over the middle of the forehead, between 44 and 52 mm up
// (the line is at about 62-70), a share of the texels are hair-dark, far
// more than on the same face without the forelock, where only the band's
// sparse fine hairs reach (measured: 3.96 % and 0.72 %; none until session
// 9 widened the band to 18 mm and grew the fine hairs to 8 mm, so the line
// thins out over the skin instead of stopping at an edge).
TEST(FaceTexture, ForelockStrandsHangOverTheForehead) {
    auto dark_share = [](const Face& f) {
        const double skin = luminance_between(0.0, 38.0, 40.0, 1, f)[0];
        int dark = 0, n = 0;
        for (double x = -30.0; x <= 30.0; x += 0.25) {
            for (double v : luminance_between(x, 44.0, 52.0, 40, f)) {
                ++n;
                if (v < 0.6 * skin) ++dark;
            }
        }
        return static_cast<double>(dark) / n;
    };
    const double with = dark_share(painted_face()), without = dark_share(face_without_forelock());
    EXPECT_GT(with - without, 0.02) << with << " with the forelock, " << without << " without";
    EXPECT_LT(without, 0.015) << with << " with the forelock, " << without << " without";
}

// Cheeks are redder than the forehead, but diffusely: the redness excess at
// the cheek's centre over the ring 25 mm around it is small (a 15 mm
// painted disc of blush gave about 0.06 in g/r).
TEST(FaceTexture, CheekRednessIsDiffuseNotADisc) {
    const Face& f = painted_face();
    auto green_over_red = [&](double cx, double cy, double r0, double r1) {
        double sum = 0;
        int n = 0;
        for (int v = 0; v < f.vertex_count(); ++v) {
            if (f.parts[v] != VertexPart::Skin) continue;
            const auto p = f.mesh.point(TriMesh::VertexHandle(v));
            if (f.mesh.normal(TriMesh::VertexHandle(v))[2] < 0.3) continue;
            const double d = std::hypot(std::abs(p[0]) - cx, p[1] - cy);
            if (d < r0 || d > r1) continue;
            const Texel t = texel_of(v);
            sum += t.g / t.r;
            ++n;
        }
        EXPECT_GT(n, 4);
        return sum / std::max(n, 1);
    };
    const double centre = green_over_red(38, -30, 0, 4);
    const double ring = green_over_red(38, -30, 23, 27);
    const double forehead = green_over_red(20, 45, 0, 6);
    EXPECT_LT(centre, forehead - 0.01) << "cheeks redder than the forehead";
    EXPECT_LT(ring - centre, 0.035) << "no disc of blush";
}

// The skin's tone differs by region at the scale a 512 px picture shows
// (one even tone read as wax to blind observers, session 9): the shaved
// beard zone is bluer than the cheek (stubble under the skin), the forehead
// yellower (HAN: the most yellow site). Ratios of the mean colour over a
// few mm, so pores and blotches average out.
TEST(FaceTexture, BeardZoneIsBluerAndTheForeheadYellowerThanTheCheek) {
    const Face& f = painted_face();
    auto mean = [&](double cx, double cy) {
        Texel m{0, 0, 0, 0};
        int n = 0;
        for (int v = 0; v < f.vertex_count(); ++v) {
            if (f.parts[v] != VertexPart::Skin) continue;
            const auto p = f.mesh.point(TriMesh::VertexHandle(v));
            if (f.mesh.normal(TriMesh::VertexHandle(v))[2] < 0.3) continue;
            if (std::hypot(std::abs(p[0]) - cx, p[1] - cy) > 5.0) continue;
            const Texel t = texel_of(v);
            m = {m.r + t.r, m.g + t.g, m.b + t.b, 0};
            ++n;
        }
        EXPECT_GT(n, 4) << "at " << cx << ", " << cy;
        return Texel{m.r / std::max(n, 1), m.g / std::max(n, 1), m.b / std::max(n, 1), 0};
    };
    const Texel cheek = mean(38, -30), jaw = mean(40, -78), forehead = mean(20, 45);
    EXPECT_GT(jaw.b / jaw.r, cheek.b / cheek.r + 0.03) << "the beard zone's bluish-grey cast";
    EXPECT_LT(forehead.b / forehead.g, cheek.b / cheek.g - 0.02) << "the forehead yellower";
}

// Alpha is the region's roughness scale: lips and the nose (T-zone) are
// glossier than the cheek, the hair and cheek are 1.
TEST(FaceTexture, AlphaHoldsTheRegionsRoughness) {
    const Face& f = painted_face();
    // The lips' sheen is broken up (wet where they meet, drier in patches
    // towards the border): their mean over both lips' middles, not one texel.
    auto uv_of = [&](const char* id) {
        return f.mesh.texcoord2D(TriMesh::VertexHandle(f.feature_points[fap::feature_point_index(id)].vertex));
    };
    double lips = 0.0;
    int samples = 0;
    for (const auto& [inner, outer] : {std::pair{"2.2", "8.1"}, std::pair{"2.3", "8.2"}})
        for (const float t : {0.2f, 0.35f, 0.5f, 0.65f, 0.8f}) {
            const auto uv = uv_of(inner) * (1.0f - t) + uv_of(outer) * t;
            lips += texel_at(uv[0], uv[1]).a;
            ++samples;
        }
    lips /= samples;
    const double cheek = texel_of(front_vertex(45, -35)).a;
    const double nose = texel_of(front_vertex(0, -25)).a;
    const double crown = texel_of(f.feature_points[fap::feature_point_index("11.4")].vertex).a;
    EXPECT_NEAR(cheek, 1.0, 0.02);
    EXPECT_NEAR(crown, 1.0, 0.02);
    EXPECT_LT(lips, cheek - 0.07) << "the lips glossier than the cheek (0.85, broken up towards 1)";
    // The T-zone scale is 0.88 (face.json roughness); this point of the
    // nose takes 0.4 of it.
    EXPECT_LT(nose, cheek - 0.02);
}

// The bust is dressed (face.json shirt): the shoulders are dark cloth, dark
// enough that the renderer lights it as it lights hair (below skin.json's
// hair mean_luminance[0], linear 0.06), with no fine noise; the neck above
// the collar is skin, shaded just above the collar's edge.
TEST(FaceTexture, ShirtCoversTheShouldersAndTheNeckEndsAtItsCollar) {
    const Face& f = painted_face();
    auto linear = [](double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); };
    std::vector<double> cloth;
    for (int v = 0; v < f.vertex_count(); ++v) {
        if (f.parts[v] != VertexPart::Skin) continue;
        const auto p = f.mesh.point(TriMesh::VertexHandle(v));
        if (p[1] > -165.0 || std::abs(p[0]) < 80.0) continue;  // the shoulders, beside the neck
        const Texel t = texel_of(v);
        cloth.push_back(0.2126 * linear(t.r) + 0.7152 * linear(t.g) + 0.0722 * linear(t.b));
        EXPECT_GE(t.b, t.r) << "a navy-charcoal cloth, not skin, at vertex " << v;
    }
    ASSERT_GT(cloth.size(), 50u);
    double mean = 0.0;
    for (double c : cloth) mean += c;
    mean /= static_cast<double>(cloth.size());
    EXPECT_LT(*std::max_element(cloth.begin(), cloth.end()), 0.06) << "darker than the hair mask's threshold";
    EXPECT_GT(mean, 0.02) << "cloth, not a black void";
    for (double c : cloth) EXPECT_NEAR(c, mean, 0.35 * mean) << "low-contrast folds, no noise";
    // Down the neck's front: skin well above the neckline (y -150 in
    // front), then cloth from the collar on, with no skin showing again.
    const std::vector<double> down = luminance_between(0.0, -125.0, -190.0, 80);
    EXPECT_GT(down.front(), 0.45);
    const auto first_cloth = std::find_if(down.begin(), down.end(), [](double l) { return l < 0.3; });
    ASSERT_NE(first_cloth, down.end()) << "no collar down the neck's front";
    for (auto it = first_cloth; it != down.end(); ++it) EXPECT_LT(*it, 0.3);
}

// The mouth's inside (face_texture.cpp Painter::tile): the teeth are not one
// even white strip (observers: 'a bright uniform white strip') but ivory,
// darker from the incisors back along the arch, and the cavity's back is a
// dark red, not black (the occlusion bake darkens it further; at a third of
// face.json colours.mouth it rendered as a void, and at 0.6 of it the open
// mouth read as a shallow red box: the back is 0.42 of it now).
TEST(FaceTexture, TeethDarkenAlongTheArchAndTheCavityIsRed) {
    const double kTile = 0.25;
    // The upper arch's labial faces, mid-crown (0.4..0.75 of the way from
    // the gum to the edge), at the vertices' own UVs (the tile is painted
    // only under its triangles; default_face.cpp gives each crown the
    // columns past its distal gap): the central incisors' (4.3..7.3 mm along
    // the arch) against the back teeth's (past 30 mm).
    const Face& f = painted_face();
    Texel incisor{0, 0, 0, 0}, molar{0, 0, 0, 0};
    int n_incisor = 0, n_molar = 0;
    for (int v = 0; v < f.vertex_count(); ++v) {
        const auto t = f.mesh.texcoord2D(TriMesh::VertexHandle(v));
        const double lu = t[0] / kTile - 2.0, lv = t[1] / kTile;
        if (lu < 0.0 || lu >= 1.0 || lv < 0.5 || lv > 1.0) continue;
        const double front = ((lv - 0.5) - 0.02) / 0.46 * 3.0;  // 0 gum .. 1 edge
        if (front < 0.4 || front > 0.75) continue;
        const double s = std::abs(27.0 * ((lu - 0.02) / 0.96 - 0.5) * 3.14159265 * 0.92);
        Texel* sum = s < 8.0 ? &incisor : s > 30.0 ? &molar : nullptr;
        if (!sum) continue;
        const Texel c = texel_at(t[0], t[1]);
        sum->r += c.r, sum->g += c.g, sum->b += c.b;
        ++(s < 8.0 ? n_incisor : n_molar);
    }
    ASSERT_GT(n_incisor, 0);
    ASSERT_GT(n_molar, 0);
    incisor = {incisor.r / n_incisor, incisor.g / n_incisor, incisor.b / n_incisor, 1};
    molar = {molar.r / n_molar, molar.g / n_molar, molar.b / n_molar, 1};
    EXPECT_LT(incisor.luminance(), 0.75) << "near-white, not ivory";
    EXPECT_LT(incisor.b, incisor.r - 0.08) << "ivory is warm";
    EXPECT_LT(molar.luminance(), 0.88 * incisor.luminance()) << molar.luminance() << " vs " << incisor.luminance();
    const Texel back = texel_at(1.5 * kTile, 0.5 * kTile);
    EXPECT_GT(back.r, 0.22) << back.r;
    EXPECT_GT(back.r, 2.0 * back.g) << back.r << " vs " << back.g;
}

// The tongue's tile (face_texture.cpp Painter::tile; polar: the tip at the
// centre, r = the angle from the tip over pi, the dorsum in its top half):
// a shallow median groove down the dorsum, darker than the dorsum 4 mm
// beside it, and the front of the dorsum lighter than its back (the
// occlusion bake darkens the back further).
TEST(FaceTexture, TongueHasAMedianGrooveAndIsLighterAtTheFront) {
    const double kTile = 0.25;
    auto at = [&](double r, double beta) {
        return texel_at(3.0 * kTile + kTile * (0.5 + 0.48 * r * std::cos(beta)), kTile * (0.5 + 0.48 * r * std::sin(beta)));
    };
    const double half_pi = 0.5 * 3.14159265;
    double groove = 0.0, beside = 0.0, front = 0.0, back = 0.0;
    int n = 0;
    for (double r = 0.35; r <= 0.65; r += 0.03, ++n) {
        const double off = std::asin(std::min(4.0 / (17.0 * std::sin(3.14159265 * r)), 1.0));  // 4 mm aside
        groove += at(r, half_pi).luminance();
        beside += 0.5 * (at(r, half_pi - off).luminance() + at(r, half_pi + off).luminance());
    }
    for (double k = 0.0; k < 5.0; ++k) {
        front += at(0.15 + 0.01 * k, half_pi - 0.4).luminance();
        back += at(0.8 + 0.01 * k, half_pi - 0.4).luminance();
    }
    // Measured: groove 0.75 of beside, back 0.53 of front.
    std::printf("tongue: groove %.2f of beside, back %.2f of front\n", groove / beside, back / front);
    EXPECT_LT(groove, 0.88 * beside) << groove / n << " vs " << beside / n;
    EXPECT_LT(back, 0.8 * front) << back / 5 << " vs " << front / 5;
    const Texel tip = at(0.15, half_pi - 0.4);
    EXPECT_GT(tip.r, 1.6 * tip.g) << "the tongue is pink-red";
}

// Pores (face.json albedo.pores): pits darker than the skin round them,
// most on the nose, fewer on the cheeks beside it, none to see on the lids'
// thin skin. Counted as the share of texels round a point darker than the
// patch's median by a pit's contrast; the flush, blotches and tones vary
// over millimetres, far wider than a pit.
TEST(FaceTexture, PoresAreDarkPitsMostOnTheNoseAndNoneOnTheLids) {
    const Face& f = painted_face();
    auto pit_share = [&](double x, double y) {
        const auto uv = f.mesh.texcoord2D(TriMesh::VertexHandle(front_vertex(x, y)));
        const Image& img = f.base_colour;
        const int cx = static_cast<int>(uv[0] * img.width), cy = static_cast<int>((1.0 - uv[1]) * img.height);
        std::vector<double> lum;
        constexpr int kR = 8;  // texels: about 3 mm
        for (int dy = -kR; dy <= kR; ++dy)
            for (int dx = -kR; dx <= kR; ++dx) {
                if (dx * dx + dy * dy > kR * kR) continue;
                const double u = (cx + dx + 0.5) / img.width, v = 1.0 - (cy + dy + 0.5) / img.height;
                lum.push_back(texel_at(u, v).luminance());
            }
        std::vector<double> sorted = lum;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        const double median = sorted[sorted.size() / 2];
        const auto dark = std::count_if(lum.begin(), lum.end(), [&](double l) { return l < 0.93 * median; });
        return static_cast<double>(dark) / static_cast<double>(lum.size());
    };
    const double nose = pit_share(0.0, -25.0), cheek = pit_share(30.0, -24.0), upper_lid = pit_share(31.0, 9.0),
                 forehead = pit_share(12.0, 45.0);
    std::printf("pit share: nose %.3f cheek %.3f forehead %.3f upper lid %.3f\n", nose, cheek, forehead, upper_lid);
    EXPECT_GT(nose, 0.04) << "pores to see on the nose";
    EXPECT_GT(cheek, 0.01) << "and on the cheeks";
    EXPECT_GT(nose, 1.5 * cheek);
    EXPECT_LT(upper_lid, 0.25 * nose) << "the lids' pores are finer than a texel";
}

// The lids' margins (face.json eyes.lash_line): at 512 px the lash strands
// draw as dots, so the upper lash line is painted. Up the upper lid from its
// margin the skin is dark at the margin (the lashes' roots) and lighter
// above; the dark line is heavier (darker times wider) towards the outer
// corner than mid-lid; the lower margin is a pale pink, wet line, much
// lighter than the lash line (a dark or deep red rim round the whole eye
// read as eyeliner, a pink one as a painted rim).
TEST(FaceTexture, UpperLashLineIsDarkAndHeavierOutwardsAndTheLowerMarginPale) {
    const Face& f = painted_face();
    ASSERT_FALSE(f.eyeballs.empty());
    const Eyeball& eye = f.eyeballs[0];
    // A frontal point s of the way along a margin (0 inner, 1 outer corner).
    auto along = [&](const std::vector<int>& margin, double s) {
        const double k = s * static_cast<double>(margin.size() - 1);
        const std::size_t i = std::min(static_cast<std::size_t>(k), margin.size() - 2);
        const auto a = f.mesh.point(TriMesh::VertexHandle(margin[i])), b = f.mesh.point(TriMesh::VertexHandle(margin[i + 1]));
        const double t = k - static_cast<double>(i);
        return std::pair{a[0] + (b[0] - a[0]) * t, a[1] + (b[1] - a[1]) * t};
    };
    struct Line {
        double darkest, top, lid;
    };
    // Luminance as a frontal camera sees it, 0.1 mm a step from the margin
    // 4 mm up the lid: the lid's skin is the brightest of 2.8-3.6 mm up
    // (above the line, under the crease); the line's top is where the
    // luminance first passes halfway from the line's darkest to the lid's.
    auto upper_line = [&](double s) {
        const auto [x, y] = along(eye.upper_margin, s);
        std::vector<double> l;
        for (int k = 0; k <= 40; ++k) l.push_back(seen_at(x, y + 0.1 * k).luminance());
        Line line{1.0, 0.0, 0.0};
        for (int k = 28; k <= 36; ++k) line.lid = std::max(line.lid, l[k]);
        for (int k = 0; k <= 20; ++k) line.darkest = std::min(line.darkest, l[k]);
        for (int k = 0; k <= 28 && l[k] < 0.5 * (line.darkest + line.lid); ++k) line.top = 0.1 * (k + 1);
        return line;
    };
    // Each the mean over a few mm of lid: the line's top is ragged.
    auto mean_line = [&](double s0, double s1) {
        Line mean{0.0, 0.0, 0.0};
        constexpr int kN = 6;
        for (int k = 0; k < kN; ++k) {
            const Line one = upper_line(s0 + (s1 - s0) * k / (kN - 1));
            mean.darkest += one.darkest / kN;
            mean.top += one.top / kN;
            mean.lid += one.lid / kN;
        }
        return mean;
    };
    const Line mid = mean_line(0.35, 0.55), outer = mean_line(0.75, 0.9);
    std::printf("upper lash line: mid darkest %.3f top %.2f mm lid %.3f; outer darkest %.3f top %.2f mm lid %.3f\n",
                mid.darkest, mid.top, mid.lid, outer.darkest, outer.top, outer.lid);
    for (const Line& line : {mid, outer}) EXPECT_LT(line.darkest, 0.5 * line.lid) << "the lash line is dark against the lid";
    EXPECT_GT(outer.top, mid.top + 0.25) << "the line thickens towards the outer corner";
    const auto [lx, ly] = along(eye.lower_margin, 0.5);
    Texel lower{0.0, 0.0, 0.0, 1.0};
    for (int k = 0; k <= 10; ++k) {
        const Texel t = seen_at(lx, ly - 0.1 * k);
        if (t.luminance() > lower.luminance()) lower = t;
    }
    std::printf("lower margin: rgb %.3f %.3f %.3f alpha %.3f\n", lower.r, lower.g, lower.b, lower.a);
    EXPECT_GT(lower.luminance(), mid.darkest + 0.25) << "the lower margin is pale, not a dark rim";
    EXPECT_GT(lower.r, 1.15 * lower.g) << "and pink";
    EXPECT_LT(lower.a, 0.8) << "and wet (its roughness scale)";
}

}  // namespace
}  // namespace emoface::expression
