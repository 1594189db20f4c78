// `emoface export` end to end (issue 14, glTF): the built binary writes .glb
// files; tinygltf reads them back; the Khronos glTF Validator (npm
// gltf-validator, through scripts/gltf_validate.js) checks them; the mesh +
// morph targets + animation weights, evaluated as a glTF viewer does, are
// compared with the rig itself at frames of the real FAP files; bad input is
// one line, exit 2, no file.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <tiny_gltf.h>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/mat4x4.hpp>

#include "emoface/expression/capture.h"
#include "emoface/expression/default_face.h"
#include "emoface/expression/face_state.h"
#include "emoface/expression/profiles.h"
#include "emoface/expression/rig.h"
#include "emoface/expression/wrinkle_map.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
namespace ex = emoface::expression;
using emoface::testing::args_with;
using emoface::testing::CommandResult;
using emoface::testing::run_emoface;

const std::string kData = EMOFACE_DATA_DIR;
const std::string kRealFap = std::string(EMOFACE_REALDATA_DIR) + "/fap";
// A coarser mesh keeps the test fast; the rig and the export are the same code at any resolution.
const std::string kResolution = "0.5";
// So does a small base colour: painting face.json's 2048 x 2048 image (and
// compressing it to PNG) was most of each export's time. One export, the
// validator's acceptance case, keeps every default.
const std::string kTextureSize = "64";

// A float accessor's values, dense or sparse (zeros, or its buffer view,
// with the sparse entries written over them).
std::vector<float> floats(const tinygltf::Model& m, int accessor) {
    const tinygltf::Accessor& a = m.accessors.at(accessor);
    const int comps = a.type == TINYGLTF_TYPE_VEC4 ? 4 : a.type == TINYGLTF_TYPE_VEC3 ? 3 : a.type == TINYGLTF_TYPE_VEC2 ? 2 : 1;
    std::vector<float> out(a.count * comps, 0.0f);
    auto bytes = [&](int view, std::size_t offset) {
        const tinygltf::BufferView& v = m.bufferViews.at(view);
        return m.buffers.at(v.buffer).data.data() + v.byteOffset + offset;
    };
    if (a.bufferView >= 0) std::memcpy(out.data(), bytes(a.bufferView, a.byteOffset), out.size() * 4);
    if (a.sparse.isSparse) {
        const unsigned char* idx = bytes(a.sparse.indices.bufferView, a.sparse.indices.byteOffset);
        const auto* values = reinterpret_cast<const float*>(bytes(a.sparse.values.bufferView, a.sparse.values.byteOffset));
        for (int i = 0; i < a.sparse.count; ++i) {
            std::uint32_t k = 0;
            if (a.sparse.indices.componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT) {
                std::uint16_t s;
                std::memcpy(&s, idx + 2 * i, 2);
                k = s;
            } else {
                std::memcpy(&k, idx + 4 * i, 4);
            }
            EXPECT_LT(k, a.count);
            if (k < a.count) std::copy_n(values + comps * i, comps, out.begin() + comps * k);
        }
    }
    return out;
}

tinygltf::Model load_glb(const std::string& path) {
    tinygltf::Model m;
    tinygltf::TinyGLTF loader;
    std::string err, warn;
    EXPECT_TRUE(loader.LoadBinaryFromFile(&m, &err, &warn, path)) << err;
    return m;
}

std::vector<std::string> target_names(const tinygltf::Model& m) {
    std::vector<std::string> names;
    const tinygltf::Value& tn = m.meshes.at(0).extras.Get("targetNames");
    for (std::size_t i = 0; i < tn.ArrayLen(); ++i) names.push_back(tn.Get(static_cast<int>(i)).Get<std::string>());
    return names;
}

// Runs scripts/gltf_validate.js over the files (one node, one validator
// load); "" when node or the validator is absent.
std::string validate(const std::vector<std::string>& glbs, int& status) {
    std::string files;
    for (const std::string& g : glbs) files += " '" + g + "'";
    const std::string cmd = fmt::format("node {}/../scripts/gltf_validate.js{} 2>&1", kData, files);
    FILE* p = popen(cmd.c_str(), "r");
    if (!p) return "";
    std::string out;
    char buf[4096];
    while (std::size_t n = std::fread(buf, 1, sizeof buf, p)) out.append(buf, n);
    status = WEXITSTATUS(pclose(p));
    return out;
}

// The world position of every vertex at animation sample k, as a glTF
// viewer computes it: base + sum of weight x target, then linear blend
// skinning with the joints' global transforms (no inverse bind matrices:
// identity), divided by the skeleton root's scale (back into the face's units).
std::vector<glm::dvec3> evaluate(const tinygltf::Model& m, std::size_t k) {
    const tinygltf::Primitive& prim = m.meshes.at(0).primitives.at(0);
    const std::vector<float> base = floats(m, prim.attributes.at("POSITION"));
    const std::size_t nv = base.size() / 3;
    std::vector<double> morphed(base.begin(), base.end());
    std::vector<std::vector<float>> local_t(m.nodes.size()), local_r(m.nodes.size());
    std::vector<float> weights(prim.targets.size(), 0.0f);
    for (std::size_t i = 0; i < weights.size(); ++i) weights[i] = static_cast<float>(m.meshes[0].weights.at(i));
    for (const auto& ch : m.animations.at(0).channels) {
        const std::vector<float> out = floats(m, m.animations[0].samplers.at(ch.sampler).output);
        const std::size_t n = ch.target_path == "weights" ? weights.size() : ch.target_path == "rotation" ? 4 : 3;
        std::vector<float> v(out.begin() + k * n, out.begin() + (k + 1) * n);
        if (ch.target_path == "weights") weights = v;
        else if (ch.target_path == "rotation") local_r[ch.target_node] = v;
        else local_t[ch.target_node] = v;
    }
    for (std::size_t t = 0; t < prim.targets.size(); ++t) {
        if (weights[t] == 0) continue;
        const std::vector<float> d = floats(m, prim.targets[t].at("POSITION"));
        for (std::size_t i = 0; i < d.size(); ++i) morphed[i] += double(weights[t]) * d[i];
    }
    std::vector<int> parent(m.nodes.size(), -1);
    for (std::size_t n = 0; n < m.nodes.size(); ++n)
        for (int c : m.nodes[n].children) parent[c] = static_cast<int>(n);
    auto local = [&](int n) {
        const tinygltf::Node& node = m.nodes[n];
        glm::dvec3 t(0.0), s(1.0);
        glm::dquat r(1, 0, 0, 0);
        if (!node.translation.empty()) t = {node.translation[0], node.translation[1], node.translation[2]};
        if (!node.rotation.empty()) r = glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]);
        if (!node.scale.empty()) s = {node.scale[0], node.scale[1], node.scale[2]};
        if (!local_t[n].empty()) t = {local_t[n][0], local_t[n][1], local_t[n][2]};
        if (!local_r[n].empty()) r = glm::dquat(local_r[n][3], local_r[n][0], local_r[n][1], local_r[n][2]);
        return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
    };
    auto global = [&](int n) {
        glm::dmat4 g(1.0);
        for (; n >= 0; n = parent[n]) g = local(n) * g;
        return g;
    };
    const tinygltf::Skin& skin = m.skins.at(0);
    std::vector<glm::dmat4> joint(skin.joints.size());
    for (std::size_t j = 0; j < joint.size(); ++j) joint[j] = global(skin.joints[j]);
    const double unit = m.nodes.at(skin.joints[0]).scale.empty() ? 1.0 : m.nodes[skin.joints[0]].scale[0];
    const tinygltf::Accessor& ja = m.accessors.at(prim.attributes.at("JOINTS_0"));
    const tinygltf::BufferView& jv = m.bufferViews.at(ja.bufferView);
    std::vector<std::uint16_t> js(4 * nv);
    std::memcpy(js.data(), m.buffers[jv.buffer].data.data() + jv.byteOffset + ja.byteOffset, js.size() * 2);
    const std::vector<float> ws = floats(m, prim.attributes.at("WEIGHTS_0"));
    std::vector<glm::dvec3> out(nv);
    for (std::size_t v = 0; v < nv; ++v) {
        const glm::dvec4 p(morphed[3 * v], morphed[3 * v + 1], morphed[3 * v + 2], 1.0);
        glm::dvec4 q(0.0);
        for (int i = 0; i < 4; ++i) q += double(ws[4 * v + i]) * (joint[js[4 * v + i]] * p);
        out[v] = glm::dvec3(q) / unit;
    }
    return out;
}

class ExportCli : public ::testing::Test {
protected:
    std::string path(const std::string& name) const { return scratch_.path(name); }
    emoface::testing::ScratchDir scratch_;
};

TEST_F(ExportCli, TargetsAreNamedAndTheAnimationHasTheFileTimes) {
    const std::string out = path("tour.glb");
    CommandResult r = run_emoface({"export", kData + "/fap/tour.fap", "--out", out, "--face-resolution", kResolution,
                                   "--texture-size", kTextureSize, "--no-wrinkles"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const tinygltf::Model m = load_glb(out);
    ASSERT_EQ(m.meshes.size(), 1u);
    const tinygltf::Primitive& prim = m.meshes[0].primitives.at(0);
    const std::vector<std::string> names = target_names(m);
    ASSERT_EQ(names.size(), prim.targets.size());
    ASSERT_EQ(m.meshes[0].weights.size(), names.size());
    for (const char* n : {"FAP4_lower_t_midlip", "FAP31_raise_l_i_eyebrow", "AU12", "joy", "surprise", "JawOpen",
                          "EyeBlinkLeft", "TongueOut", "MouthSmileRight"})
        EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    EXPECT_EQ(std::count_if(names.begin(), names.end(), [](const std::string& s) { return s.rfind("viseme_", 0) == 0; }),
              14);
    const auto base_colour =
        std::find_if(m.images.begin(), m.images.end(), [](const tinygltf::Image& i) { return i.name == "base_colour"; });
    ASSERT_NE(base_colour, m.images.end());  // the base colour, embedded, at the size asked
    EXPECT_EQ(std::count_if(m.images.begin(), m.images.end(), [](const tinygltf::Image& i) { return i.name == "base_colour"; }),
              1);
    EXPECT_EQ(base_colour->width, std::stoi(kTextureSize));
    EXPECT_EQ(base_colour->height, std::stoi(kTextureSize));
    ASSERT_EQ(m.animations.size(), 1u);
    const std::vector<float> t = floats(m, m.animations[0].samplers[0].input);
    const std::vector<float> w = floats(m, m.animations[0].samplers[0].output);
    ASSERT_EQ(w.size(), t.size() * names.size());
    const ex::Animation anim = ex::read_animation_file(kData + "/fap/tour.fap", kData);
    ASSERT_EQ(t.size(), anim.stream.frames.size());
    EXPECT_NEAR(t.back(), anim.stream.frame_time(t.size() - 1), 1e-5);
}

TEST_F(ExportCli, TheValidatorFindsNoErrors) {
    // The .glb each writes, then its arguments.
    const std::vector<std::string> small = {"--face-resolution", kResolution, "--texture-size", kTextureSize,
                                            "--wrinkle-size", "256"};
    std::vector<std::pair<std::string, std::vector<std::string>>> cases = {
        {path("neutral.glb"), small},
        {path("mix.glb"), args_with({"--mix", "0.7 joy + 0.3 AU4"}, small)},
        {path("tour.glb"), args_with({kData + "/fap/tour.fap"}, small)}};
    if (fs::exists(kRealFap + "/xface_joy.fap"))  // the acceptance: every default (full resolution, texture, keys)
        cases.push_back({path("joy.glb"), {kRealFap + "/xface_joy.fap"}});
    std::vector<std::string> glbs;
    for (auto& [glb, args] : cases) {
        args.insert(args.begin(), {"export", "--out", glb});
        CommandResult r = run_emoface(args);
        ASSERT_EQ(r.exit_code, 0) << r.err;
        glbs.push_back(glb);
    }
    int status = -1;
    const std::string report = validate(glbs, status);
    if (status == 127 || status == 3 || report.empty())
        GTEST_SKIP() << "node or the npm package gltf-validator is absent (scripts/deps installs them): " << report;
    EXPECT_EQ(status, 0) << report;
    for (const std::string& glb : glbs) EXPECT_NE(report.find(glb + ": 0 errors"), std::string::npos) << report;
}

// The glTF mesh, its targets and the animation's weights, evaluated as a
// viewer does (position + sum of weight x target), against the rig at frames
// of the real FAP files.
TEST_F(ExportCli, ReproducesTheRigOnRealFapFiles) {
    if (!fs::is_directory(kRealFap)) GTEST_SKIP() << kRealFap << " is absent: no real FAP files to compare with";
    ex::DefaultFaceOptions fo;
    fo.resolution_scale = std::stod(kResolution);
    fo.texture_size = 16;  // the mesh is what is compared
    const ex::Face face = ex::make_default_face(kData + "/face", fo);
    ex::RigOptions ro;
    ro.ranges = ex::load_fap_ranges(kData + "/expression/fap_ranges.json");
    const ex::FaceRig rig(face, ro);
    const auto emotions = ex::load_emotion_profiles(kData + "/expression/emotions.json");
    const auto visemes = ex::load_viseme_profiles(kData + "/expression/visemes.json");
    const double es0 = face.fapu.es * 1024;

    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(kRealFap))
        if (e.path().extension() == ".fap") files.push_back(e.path());
    std::sort(files.begin(), files.end());
    ASSERT_FALSE(files.empty());
    for (const fs::path& file : files) {
        const ex::Animation anim = ex::read_animation_file(file.string(), kData);
        if (anim.stream.frames.empty()) continue;
        const std::string out = path(file.stem().string() + ".glb");
        CommandResult r =
            run_emoface({"export", file.string(), "--out", out, "--face-resolution", kResolution, "--texture-size",
                         kTextureSize, "--no-wrinkles"});
        ASSERT_EQ(r.exit_code, 0) << r.err;
        const tinygltf::Model m = load_glb(out);
        const std::size_t nf = anim.stream.frames.size();
        ASSERT_EQ(floats(m, m.animations.at(0).samplers.at(0).input).size(), nf);
        double worst = 0;
        std::size_t worst_frame = 0;
        for (std::size_t k = 0; k < nf; k += std::max<std::size_t>(1, nf / 12)) {
            const ex::DeformedFace d = rig.deform(ex::face_state(anim.stream.resolved(k), emotions, &visemes).faps);
            const std::vector<glm::dvec3> p = evaluate(m, k);
            for (int v = 0; v < face.vertex_count(); ++v) {
                const double e = glm::length(p[v] - glm::dvec3(d.positions[v][0], d.positions[v][1], d.positions[v][2]));
                if (e > worst) worst = e, worst_frame = k;
            }
        }
        std::printf("%s: worst vertex %.4f ES0 (frame %zu)\n", file.filename().c_str(), worst / es0, worst_frame);
        EXPECT_LT(worst / es0, 0.02) << file << " frame " << worst_frame;
    }
}

// Each part of the face has its own material (its own primitive over the
// shared vertices), the wet ones glossier than skin; together they hold every
// triangle once.
TEST_F(ExportCli, PartsHaveTheirOwnMaterials) {
    const std::string out = path("parts.glb");
    CommandResult r = run_emoface(
        {"export", "--out", out, "--face-resolution", kResolution, "--texture-size", kTextureSize, "--no-wrinkles"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const tinygltf::Model m = load_glb(out);
    std::map<std::string, double> roughness;
    std::size_t indices = 0;
    for (const tinygltf::Primitive& p : m.meshes.at(0).primitives) {
        const tinygltf::Material& mat = m.materials.at(p.material);
        roughness[mat.name] = mat.pbrMetallicRoughness.roughnessFactor;
        EXPECT_GT(m.accessors.at(p.indices).count, 0u) << mat.name;
        indices += m.accessors[p.indices].count;
        EXPECT_EQ(p.attributes.at("POSITION"), m.meshes[0].primitives[0].attributes.at("POSITION"));
        EXPECT_EQ(p.targets.size(), m.meshes[0].primitives[0].targets.size());
        EXPECT_EQ(mat.pbrMetallicRoughness.baseColorTexture.index, 0) << mat.name;
    }
    for (const char* part : {"skin", "eyes", "teeth", "mouth", "lashes"}) EXPECT_EQ(roughness.count(part), 1u) << part;
    EXPECT_LT(roughness["eyes"], roughness["teeth"]);
    EXPECT_LT(roughness["teeth"], roughness["skin"]);
    EXPECT_LT(roughness["mouth"], roughness["skin"]);
    ex::DefaultFaceOptions fo;
    fo.resolution_scale = std::stod(kResolution);
    fo.texture_size = 16;  // only its triangles are counted
    EXPECT_EQ(indices, 3 * ex::make_default_face(kData + "/face", fo).mesh.n_faces());
}

// The wrinkle key maps go along: one per wrinkling AU and side, each a PNG
// that decodes at the size asked, naming the AU morph target that drives it
// and carrying its layout; the neutral map is the skin's normal texture on
// the second UV set; the animation carries each key's weight per frame.
TEST_F(ExportCli, WrinkleKeysGoAlongWithTheirAuTargets) {
    const std::string out = path("wrinkles.glb");
    CommandResult r = run_emoface({"export", kData + "/fap/tour.fap", "--out", out, "--face-resolution", kResolution,
                                   "--texture-size", kTextureSize, "--wrinkle-size", "256"});
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const tinygltf::Model m = load_glb(out);
    const tinygltf::Value& extras = m.meshes.at(0).extras;
    if (!extras.Has("wrinkles")) {
        // Only a build without render/ (no drawing commands) leaves them out.
        ASSERT_FALSE(EMOFACE_DRAWS) << "a build with render/ exported no wrinkle keys";
        GTEST_SKIP() << "this build has no render module, whose key plan makes the wrinkle maps";
    }
    const tinygltf::Value& w = extras.Get("wrinkles");
    const std::vector<std::string> names = target_names(m);
    std::set<int> aus_of_keys;
    const tinygltf::Value& keys = w.Get("keys");
    for (std::size_t i = 0; i < keys.ArrayLen(); ++i) {
        const tinygltf::Value& k = keys.Get(static_cast<int>(i));
        const std::string name = k.Get("name").Get<std::string>();
        const int target = k.Get("target").GetNumberAsInt();
        ASSERT_GE(target, 0) << name;
        ASSERT_LT(target, static_cast<int>(names.size())) << name;
        EXPECT_TRUE(name == names[target] || name == names[target] + "L" || name == names[target] + "R")
            << name << " drives " << names[target];
        aus_of_keys.insert(std::stoi(names[target].substr(2)));
        const tinygltf::Image& img = m.images.at(m.textures.at(k.Get("texture").GetNumberAsInt()).source);
        EXPECT_EQ(img.mimeType, "image/png");
        EXPECT_EQ(img.width, 256) << name;  // tinygltf decoded it
        EXPECT_EQ(img.height, 256) << name;
        EXPECT_EQ(img.image.size(), 256u * 256u * img.component) << name;
        EXPECT_GT(k.Get("layout").Get("3.5").ArrayLen(), 0u) << name;
    }
    std::set<int> wrinkling;
    for (const auto& au : ex::load_wrinkle_spec(kData + "/expression/wrinkles.json").action_units) wrinkling.insert(au.au);
    EXPECT_EQ(aus_of_keys, wrinkling);
    EXPECT_GE(keys.ArrayLen(), wrinkling.size());
    EXPECT_GT(w.Get("featureLines").ArrayLen(), 0u);
    const tinygltf::Primitive& prim = m.meshes[0].primitives.at(0);
    EXPECT_EQ(prim.attributes.count("TEXCOORD_1"), 1u);
    const tinygltf::Material& skin = m.materials.at(prim.material);
    EXPECT_EQ(skin.name, "skin");
    EXPECT_EQ(skin.normalTexture.index, w.Get("neutralTexture").GetNumberAsInt());
    EXPECT_EQ(skin.normalTexture.texCoord, 1);
    const tinygltf::Animation& anim = m.animations.at(0);
    const std::vector<float> kw = floats(m, anim.extras.Get("wrinkleWeights").GetNumberAsInt());
    const std::vector<float> t = floats(m, anim.samplers.at(0).input);
    ASSERT_EQ(kw.size(), t.size() * keys.ArrayLen());
    EXPECT_GT(*std::max_element(kw.begin(), kw.end()), 0.5f);  // the tour shows its AUs
}

TEST_F(ExportCli, BadInputIsOneLineExitTwoAndNoFile) {
    // The animation and the mix are read after the face is built: a small one.
    const std::vector<std::string> small = {"--face-resolution", kResolution, "--texture-size", kTextureSize};
    const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
        {{"export", "--out", path("a.gltf")}, "expected a file ending in .glb"},
        {args_with({"export", path("missing.fap"), "--out", path("b.glb")}, small), "missing.fap"},
        {{"export", kData + "/fap/tour.fap", "--mix", "joy", "--out", path("c.glb")}, "not both"},
        {{"export", "--face", path("nope.obj"), "--out", path("d.glb")}, "no such file"},
        {args_with({"export", "--mix", "0.5 glee", "--out", path("e.glb")}, small), "glee"},
        {{"export", "--wrinkle-size", "100", "--out", path("f.glb")}, "--wrinkle-size 100: expected 256..4096"},
        {{"export", "--texture-size", "5", "--out", path("g.glb")}, "--texture-size 5: expected 64..8192 (0: face.json's)"},
    };
    for (const auto& [args, says] : cases) {
        CommandResult r = run_emoface(args);
        EXPECT_EQ(r.exit_code, 2) << args[1] << ": " << r.err;
        EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
        for (const std::string& a : args)
            if (a.size() > 4 && (a.rfind(".glb") == a.size() - 4 || a.rfind(".gltf") == a.size() - 5))
                EXPECT_FALSE(fs::exists(a)) << a;
    }
}

}  // namespace
