// emoface export --out head.glb [--face ...] [ANIMATION | --mix MIX]: the face
// as a glTF 2.0 binary for Blender, game engines and the web (issue 14).
//
// Draws nothing, so it lives in apps (not cmd_r_*) and needs no GL: the
// writer is Debian's tinygltf, the geometry the rig's own (FaceRig::deform).
//
// What goes in:
//  - one mesh (every part: skin, eyes, mouth interior, lashes) with normals,
//    base-colour UVs and one material whose base colour is the face's
//    texture, embedded as PNG;
//  - morph targets, named in mesh.extras.targetNames:
//      FAPnn_<name> for every low-level FAP with a non-rigid motion: the
//        rig's point field, lids, slides, lashes and pupils at the FAP's
//        reference value `fapScale` (mesh.extras), so a FAP value v is the
//        weight v / fapScale. The point field is linear in the FAPs, so
//        these are exact there; the lids' slide over the eyeballs and the
//        lashes' turn are linearised about neutral (the error this leaves:
//        README, "glTF");
//      the jaw, eyes and head as skin joints: the rig blends them into each
//        vertex with a weight (blend_rigid), which is linear blend skinning;
//      AUn, the six emotions, the 14 visemes and the 52 ARKit shapes (ARKit's
//        own names): each the sum of its FAPs' targets, so an engine that
//        drives ARKit shapes or AUs drives this face;
//  - with an animation: its frames as one glTF animation of the morph
//    weights (the FAP targets) and the joints' rotations and translations
//    (RigFrame) at the file's own times, FAPs clamped to the
//    face's ranges as the rig clamps them.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include <tiny_gltf.h>

#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "cli_checks.h"
#include "command.h"
#include "emoface/common/error.h"
#include "emoface/expression/capture.h"
#include "emoface/expression/default_face.h"
#include "emoface/expression/face_io.h"
#include "emoface/expression/face_state.h"
#include "emoface/expression/profiles.h"
#include "emoface/expression/rig.h"
#include "emoface/fap/fap_table.h"

namespace {

namespace ex = emoface::expression;
using emoface::InputError;
using emoface::fail;

struct ExportArgs {
    std::string out, face = "default", fdp, animation, mix, data = EMOFACE_DATA_DIR;
    double face_resolution = 1.0;
    double fap_step = 0;  // 0: per FAP, from its range
};

bool ends_with(const std::string& s, const std::string& e) {
    return s.size() >= e.size() && s.compare(s.size() - e.size(), e.size(), e) == 0;
}

ex::Face load_face(const ExportArgs& a) {
    if (a.face == "default") {
        if (!std::filesystem::is_directory(a.data + "/face"))
            fail<InputError>("export: data folder {}: no face/ there (point --data at the project's data/)", a.data);
        ex::DefaultFaceOptions fo;
        fo.resolution_scale = a.face_resolution;
        return ex::make_default_face(a.data + "/face", fo);
    }
    std::error_code ec;
    if (!std::filesystem::exists(a.face, ec))
        fail<InputError>("export: --face {}: no such file (expected default, FILE.wfm or FILE.obj)", a.face);
    if (ends_with(a.face, ".wfm")) return ex::load_candide3(a.face);
    if (ends_with(a.face, ".obj")) {
        const std::string fdp = a.fdp.empty() ? a.face.substr(0, a.face.size() - 4) + ".fdp.json" : a.fdp;
        if (!std::filesystem::exists(fdp, ec))
            fail<InputError>("export: --face {}: give its feature points with --fdp FILE.json (looked for {})", a.face,
                             fdp);
        return ex::load_obj_with_fdp(a.face, fdp);
    }
    fail<InputError>("export: --face {}: expected default, FILE.wfm or FILE.obj", a.face);
}

// Appends `bytes` to buffer 0 (4-byte aligned) as a buffer view; its index.
int add_view(tinygltf::Model& m, const void* bytes, std::size_t size, int target = 0) {
    auto& buf = m.buffers[0].data;
    while (buf.size() % 4) buf.push_back(0);
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buf.size();
    v.byteLength = size;
    if (target) v.target = target;
    buf.insert(buf.end(), static_cast<const unsigned char*>(bytes), static_cast<const unsigned char*>(bytes) + size);
    m.bufferViews.push_back(v);
    return static_cast<int>(m.bufferViews.size()) - 1;
}

int add_accessor(tinygltf::Model& m, const std::vector<float>& data, int type, int components, bool bounds,
                 int target = TINYGLTF_TARGET_ARRAY_BUFFER) {
    tinygltf::Accessor acc;
    acc.bufferView = add_view(m, data.data(), data.size() * sizeof(float), target);
    acc.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    acc.type = type;
    acc.count = data.size() / components;
    if (bounds) {
        acc.minValues.assign(components, 1e30);
        acc.maxValues.assign(components, -1e30);
        for (std::size_t i = 0; i < data.size(); ++i) {
            const int c = static_cast<int>(i % components);
            // glTF bounds are the float values themselves.
            acc.minValues[c] = std::min(acc.minValues[c], static_cast<double>(data[i]));
            acc.maxValues[c] = std::max(acc.maxValues[c], static_cast<double>(data[i]));
        }
    }
    m.accessors.push_back(acc);
    return static_cast<int>(m.accessors.size()) - 1;
}

// Minimal zlib-free PNG: stored (uncompressed) deflate blocks, so the base
// colour travels without another library (viewers decode it as any PNG).
std::vector<unsigned char> encode_png(const ex::Image& img) {
    auto crc32 = [](const unsigned char* p, std::size_t n, std::uint32_t c = 0xffffffffu) {
        for (std::size_t i = 0; i < n; ++i) {
            c ^= p[i];
            for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
        }
        return c;
    };
    std::vector<unsigned char> raw;
    const std::size_t row = static_cast<std::size_t>(img.width) * 4;
    for (int y = 0; y < img.height; ++y) {
        raw.push_back(0);
        raw.insert(raw.end(), img.rgba.begin() + y * row, img.rgba.begin() + (y + 1) * row);
    }
    std::vector<unsigned char> z{0x78, 0x01};
    std::uint32_t a = 1, b = 0;
    for (unsigned char c : raw) {
        a = (a + c) % 65521;
        b = (b + a) % 65521;
    }
    for (std::size_t i = 0; i < raw.size() || i == 0; i += 65535) {
        const std::size_t n = std::min<std::size_t>(65535, raw.size() - i);
        z.push_back(i + n >= raw.size() ? 1 : 0);
        z.push_back(n & 0xff);
        z.push_back(n >> 8);
        z.push_back(~n & 0xff);
        z.push_back((~n >> 8) & 0xff);
        z.insert(z.end(), raw.begin() + i, raw.begin() + i + n);
        if (raw.empty()) break;
    }
    const std::uint32_t adler = (b << 16) | a;
    for (int s = 24; s >= 0; s -= 8) z.push_back((adler >> s) & 0xff);
    std::vector<unsigned char> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    auto chunk = [&](const char* type, const std::vector<unsigned char>& data) {
        const std::uint32_t n = static_cast<std::uint32_t>(data.size());
        for (int s = 24; s >= 0; s -= 8) png.push_back((n >> s) & 0xff);
        std::vector<unsigned char> td(type, type + 4);
        td.insert(td.end(), data.begin(), data.end());
        png.insert(png.end(), td.begin(), td.end());
        const std::uint32_t c = ~crc32(td.data(), td.size());
        for (int s = 24; s >= 0; s -= 8) png.push_back((c >> s) & 0xff);
    };
    std::vector<unsigned char> ihdr;
    for (std::uint32_t v : {static_cast<std::uint32_t>(img.width), static_cast<std::uint32_t>(img.height)})
        for (int s = 24; s >= 0; s -= 8) ihdr.push_back((v >> s) & 0xff);
    ihdr.insert(ihdr.end(), {8, 6, 0, 0, 0});
    chunk("IHDR", ihdr);
    chunk("IDAT", z);
    chunk("IEND", {});
    return png;
}

// The reference value of FAP n for its target: the larger end of its range
// (a value the face shows), 200 units where the range is unbounded.
double fap_scale(const ex::FapRanges& r, int n, double step) {
    if (step > 0) return step;
    const double s = std::max(std::abs(r.min(n)), std::abs(r.max(n)));
    return std::isfinite(s) && s > 0 ? s : 200.0;
}

void export_gltf(const ExportArgs& a) {
    if (!ends_with(a.out, ".glb")) fail<InputError>("export: --out {}: expected a file ending in .glb", a.out);
    if (!a.animation.empty() && !a.mix.empty())
        fail<InputError>("export: give an animation file or --mix, not both");
    emoface::apps::check_in_range("export", "--face-resolution", a.face_resolution, 0.1, 2.0);
    emoface::apps::OutputFile out(a.out, "export", "--out");

    const ex::Face face = load_face(a);
    ex::RigOptions ro;
    ro.ranges = ex::load_fap_ranges(a.data + "/expression/fap_ranges.json");
    const ex::FaceRig rig(face, ro);
    const auto emotions = ex::load_emotion_profiles(a.data + "/expression/emotions.json");
    const auto visemes = ex::load_viseme_profiles(a.data + "/expression/visemes.json");
    const ex::ArkitShapes arkit =
        ex::load_arkit_shapes(a.data + "/expression/arkit.json", emotions.action_units);

    // The animation (or mix) first: a bad file fails before the slow targets.
    std::vector<ex::FapValues> frames;
    std::vector<double> times;
    if (!a.animation.empty()) {
        const ex::Animation anim = ex::read_animation_file(a.animation, a.data);
        if (anim.stream.frames.empty()) fail<InputError>("export: {}: the file has no frames", a.animation);
        for (std::size_t k = 0; k < anim.stream.frames.size(); ++k) {
            frames.push_back(ex::face_state(anim.stream.resolved(k), emotions, &visemes).faps);
            times.push_back(anim.stream.frame_time(k));
        }
    }
    ex::FapValues still{};
    if (!a.mix.empty()) still = ex::face_state(ex::parse_emotion_mix(a.mix), emotions).faps;

    const int nv = face.vertex_count();
    const ex::RigView view = rig.view();
    const ex::DeformedFace neutral = rig.deform(ex::FapValues{});
    std::vector<float> base(3 * nv);
    for (int v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) base[3 * v + c] = neutral.positions[v][c];
    const double es0 = face.fapu.es * 1024;

    // The rig's non-rigid stages (point field, lids, slides, lashes, pupils)
    // for a frame: what the morph targets carry; the jaw, eyes and head are
    // the skin's joints.
    auto morph_stage = [&](const ex::FapValues& faps, std::vector<float>& p) {
        ex::RigFrame f = rig.frame(faps);
        f.jaw = f.head = false;
        for (auto& e : f.eyes) {
            std::fill(std::begin(e.r), std::end(e.r), 0.0);
            e.r[0] = e.r[4] = e.r[8] = 1.0;
            std::fill(std::begin(e.t), std::end(e.t), 0.0);
        }
        p.resize(3 * nv);
        for (int v = 0; v < nv; ++v) {
            const auto q = ex::rig_kernel::position(view, f, v);
            p[3 * v] = q.x, p[3 * v + 1] = q.y, p[3 * v + 2] = q.z;
        }
    };

    // Composite targets: their profile's FAPs. Each is the sum of its FAPs'
    // whole motion (rotations linearised), so JawOpen opens the jaw.
    std::vector<std::string> composite_names;
    std::vector<ex::FapValues> composite_faps;
    for (const ex::ActionUnit& au : emotions.action_units.units) {
        composite_names.push_back(fmt::format("AU{}", au.number));
        composite_faps.push_back(au.faps);
    }
    for (ex::Emotion e : ex::kEmotions) {
        composite_names.push_back(ex::emotion_name(e));
        composite_faps.push_back(emotions[e]);
    }
    for (int v = 1; v < ex::kVisemeCount; ++v) {
        composite_names.push_back(fmt::format("viseme_{}", emoface::fap::viseme_name(v)));
        composite_faps.push_back(visemes.profiles[v]);
    }
    const auto& shape_names = ex::arkit_shape_names();
    for (std::size_t s = 0; s < shape_names.size() && s < arkit.faps.size(); ++s) {
        composite_names.push_back(shape_names[s]);
        composite_faps.push_back(arkit.faps[s]);
    }
    std::vector<std::vector<float>> composites(composite_names.size(), std::vector<float>(3 * nv, 0.0f));

    // One target per low-level FAP whose non-rigid motion is not nil: its
    // motion at the reference value fapScale (a central difference where
    // both signs are in range, else one-sided). The other lip contour is
    // given a negligible value so the rig does not copy this one onto it
    // (FaceRig moves a contour the frame leaves at 0 with the other).
    std::vector<std::string> names;
    std::vector<std::vector<float>> deltas;
    std::vector<double> scale_of_fap(emoface::fap::kFapCount + 1, 0.0);
    std::vector<int> target_of_fap(emoface::fap::kFapCount + 1, -1);
    std::vector<float> sp, sm;
    for (int n = 3; n <= emoface::fap::kFapCount; ++n) {
        if (!rig.has_effect(n)) continue;
        const double s = fap_scale(ro.ranges, n, a.fap_step);
        const double hi = std::min(s, ro.ranges.max(n)), lo = std::max(-s, ro.ranges.min(n));
        if (hi - lo <= 0) continue;
        scale_of_fap[n] = s;
        ex::FapValues plus{}, minus{};
        plus[n - 1] = hi;
        minus[n - 1] = lo;
        const int other = n >= 4 && n <= 13 ? n + 47 : n >= 51 && n <= 60 ? n - 47 : 0;
        if (other) plus[other - 1] = minus[other - 1] = 1e-9;
        const double k = s / (hi - lo);
        // The whole motion, for the composites.
        const ex::DeformedFace dp = rig.deform(plus), dm = rig.deform(minus);
        for (std::size_t c = 0; c < composites.size(); ++c) {
            const double w = composite_faps[c][n - 1] / s;
            if (w == 0) continue;
            for (int v = 0; v < nv; ++v)
                for (int j = 0; j < 3; ++j)
                    composites[c][3 * v + j] += static_cast<float>(w * k * (dp.positions[v][j] - dm.positions[v][j]));
        }
        morph_stage(plus, sp);
        morph_stage(minus, sm);
        std::vector<float> d(3 * nv);
        double largest = 0;
        for (int i = 0; i < 3 * nv; ++i) {
            d[i] = static_cast<float>(k * (double(sp[i]) - sm[i]));
            largest = std::max(largest, std::abs(double(d[i])));
        }
        if (largest < 1e-6 * es0) continue;  // a purely rigid FAP: the joints carry it
        target_of_fap[n] = static_cast<int>(names.size());
        names.push_back(fmt::format("FAP{}_{}", n, emoface::fap::fap_info(n).name));
        deltas.push_back(std::move(d));
    }
    const std::size_t fap_targets = names.size();
    for (std::size_t c = 0; c < composites.size(); ++c) {
        names.push_back(composite_names[c]);
        deltas.push_back(std::move(composites[c]));
    }

    // The weights of a frame: its FAPs as the rig takes them (clamped; a lip
    // contour left at 0 moves with the other).
    auto weights_of = [&](const ex::FapValues& raw) {
        const ex::FapValues f = ex::lip_contours_together(ro.ranges.clamp(raw));
        std::vector<float> w(names.size(), 0.0f);
        for (int n = 3; n <= emoface::fap::kFapCount; ++n)
            if (target_of_fap[n] >= 0) w[target_of_fap[n]] = static_cast<float>(f[n - 1] / scale_of_fap[n]);
        return w;
    };

    tinygltf::Model m;
    m.asset.version = "2.0";
    m.asset.generator = "emoface export";
    m.buffers.resize(1);

    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.attributes["POSITION"] = add_accessor(m, base, TINYGLTF_TYPE_VEC3, 3, true);
    {
        ex::TriMesh mesh = face.mesh;
        mesh.request_face_normals();
        mesh.request_vertex_normals();
        mesh.update_normals();
        std::vector<float> n(3 * nv);
        for (int v = 0; v < nv; ++v) {
            auto nn = mesh.normal(ex::TriMesh::VertexHandle(v));
            const float len = std::sqrt(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2]);
            for (int c = 0; c < 3; ++c) n[3 * v + c] = len > 0 ? nn[c] / len : (c == 2 ? 1.0f : 0.0f);
        }
        prim.attributes["NORMAL"] = add_accessor(m, n, TINYGLTF_TYPE_VEC3, 3, false);
        if (face.mesh.has_vertex_texcoords2D()) {
            std::vector<float> uv(2 * nv);
            for (int v = 0; v < nv; ++v) {
                const auto t = face.mesh.texcoord2D(ex::TriMesh::VertexHandle(v));
                uv[2 * v] = t[0];
                uv[2 * v + 1] = 1.0f - t[1];  // glTF's v runs down the image
            }
            prim.attributes["TEXCOORD_0"] = add_accessor(m, uv, TINYGLTF_TYPE_VEC2, 2, false);
        }
        std::vector<std::uint32_t> idx;
        for (auto f : face.mesh.faces())
            for (auto v : face.mesh.fv_range(f)) idx.push_back(static_cast<std::uint32_t>(v.idx()));
        tinygltf::Accessor acc;
        acc.bufferView = add_view(m, idx.data(), idx.size() * 4, TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
        acc.type = TINYGLTF_TYPE_SCALAR;
        acc.count = idx.size();
        m.accessors.push_back(acc);
        prim.indices = static_cast<int>(m.accessors.size()) - 1;
    }
    for (const auto& d : deltas) {
        std::vector<float> f(d.begin(), d.end());
        prim.targets.push_back({{"POSITION", add_accessor(m, f, TINYGLTF_TYPE_VEC3, 3, true)}});
    }

    // Skinning: the rig blends the jaw and the head into each vertex with its
    // own weight (rig_kernel.h blend_rigid: p + w (M p - p)), which is linear
    // blend skinning with an unmoved joint; the jaw's blend inside the
    // head's makes four joints (root, jaw, head, head x jaw), an eyeball two
    // (eye, head x eye).
    const int eyes = static_cast<int>(face.eyeballs.size());
    const int j_jaw = 1, j_eye = 2, j_head = 2 + eyes, j_head_jaw = 3 + eyes, j_head_eye = 4 + eyes;
    {
        std::vector<std::uint16_t> joints(4 * nv);
        std::vector<float> jw(4 * nv, 0.0f);
        for (int v = 0; v < nv; ++v) {
            const double wh = view.head_weight ? view.head_weight[v] : 0.0;
            const int e = view.eye_of ? view.eye_of[v] : -1;
            std::uint16_t* j = &joints[4 * v];
            float* w = &jw[4 * v];
            if (e >= 0 && e < eyes) {
                j[0] = j_eye + e, j[1] = j_head_eye + e, j[2] = 0, j[3] = j_jaw;
                w[0] = static_cast<float>(1 - wh), w[1] = static_cast<float>(wh);
            } else {
                const double wj = view.jaw_weight ? view.jaw_weight[v] : 0.0;
                j[0] = 0, j[1] = j_jaw, j[2] = j_head, j[3] = j_head_jaw;
                w[0] = static_cast<float>((1 - wh) * (1 - wj)), w[1] = static_cast<float>((1 - wh) * wj);
                w[2] = static_cast<float>(wh * (1 - wj)), w[3] = static_cast<float>(wh * wj);
            }
        }
        // A joint a vertex does not use is joint 0 (the validator's rule).
        for (int i = 0; i < 4 * nv; ++i)
            if (jw[i] == 0.0f) joints[i] = 0;
        tinygltf::Accessor acc;
        acc.bufferView = add_view(m, joints.data(), joints.size() * 2, TINYGLTF_TARGET_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        acc.type = TINYGLTF_TYPE_VEC4;
        acc.count = nv;
        m.accessors.push_back(acc);
        prim.attributes["JOINTS_0"] = static_cast<int>(m.accessors.size()) - 1;
        prim.attributes["WEIGHTS_0"] = add_accessor(m, jw, TINYGLTF_TYPE_VEC4, 4, false);
    }

    tinygltf::Material mat;
    mat.name = "face";
    mat.pbrMetallicRoughness.metallicFactor = 0.0;
    mat.pbrMetallicRoughness.roughnessFactor = 0.6;
    mat.doubleSided = true;
    if (!face.base_colour.empty() && prim.attributes.count("TEXCOORD_0")) {
        const std::vector<unsigned char> png = encode_png(face.base_colour);
        tinygltf::Image img;
        img.name = "base_colour";
        img.mimeType = "image/png";
        img.bufferView = add_view(m, png.data(), png.size());
        m.images.push_back(img);
        tinygltf::Texture tex;
        tex.source = 0;
        m.textures.push_back(tex);
        mat.pbrMetallicRoughness.baseColorTexture.index = 0;
    }
    m.materials.push_back(mat);
    prim.material = 0;

    tinygltf::Mesh mesh;
    mesh.name = face.name.empty() ? "face" : face.name;
    mesh.primitives.push_back(prim);
    {
        const std::vector<float> w = weights_of(still);
        mesh.weights.assign(w.begin(), w.end());
        tinygltf::Value::Array tn, sc;
        for (const auto& n : names) tn.emplace_back(n);
        tinygltf::Value::Object fs;
        for (int n = 3; n <= emoface::fap::kFapCount; ++n)
            if (target_of_fap[n] >= 0) fs[std::to_string(n)] = tinygltf::Value(scale_of_fap[n]);
        tinygltf::Value::Object extras;
        extras["targetNames"] = tinygltf::Value(tn);
        extras["fapScale"] = tinygltf::Value(fs);
        extras["about"] = tinygltf::Value(std::string(
            "FAPnn_* targets: the rig's motion at FAP value fapScale[n] (weight = FAP value / fapScale); AU, emotion, "
            "viseme and ARKit targets are sums of the FAP targets with their profile's values"));
        mesh.extras = tinygltf::Value(extras);
    }
    m.meshes.push_back(mesh);

    // Nodes: 0 the skinned mesh; 1 the skeleton's root (millimetres of the
    // default face to glTF's metres), joint 0; under it the jaw, the eyes and
    // the head, and under the head its copies of the jaw and eyes.
    auto add_node = [&](const std::string& name) {
        tinygltf::Node n;
        n.name = name;
        m.nodes.push_back(n);
        return static_cast<int>(m.nodes.size()) - 1;
    };
    const int n_mesh = add_node(mesh.name), n_root = add_node("skeleton");
    m.nodes[n_mesh].mesh = 0;
    m.nodes[n_mesh].skin = 0;
    if (a.face == "default") m.nodes[n_root].scale = {0.001, 0.001, 0.001};
    std::vector<int> joint_nodes{n_root};
    joint_nodes.push_back(add_node("jaw"));
    for (int e = 0; e < eyes; ++e) joint_nodes.push_back(add_node(e == 0 ? "eye_left" : e == 1 ? "eye_right" : "eye"));
    joint_nodes.push_back(add_node("head"));
    joint_nodes.push_back(add_node("head_jaw"));
    for (int e = 0; e < eyes; ++e)
        joint_nodes.push_back(add_node(e == 0 ? "head_eye_left" : e == 1 ? "head_eye_right" : "head_eye"));
    for (int j = 1; j <= j_head; ++j) m.nodes[n_root].children.push_back(joint_nodes[j]);
    for (int j = j_head_jaw; j < static_cast<int>(joint_nodes.size()); ++j)
        m.nodes[joint_nodes[j_head]].children.push_back(joint_nodes[j]);
    tinygltf::Skin skin;
    skin.name = "rig";
    skin.skeleton = n_root;
    skin.joints = joint_nodes;
    m.skins.push_back(skin);
    tinygltf::Scene scene;
    scene.nodes = {n_mesh, n_root};
    m.scenes.push_back(scene);
    m.defaultScene = 0;

    // A rigid motion R (p - pivot) + pivot + t as a node's rotation and translation.
    struct Pose {
        glm::dquat r{1, 0, 0, 0};
        glm::dvec3 t{0.0};
    };
    auto rigid = [](bool on, const double* r9, const double* pivot, const double* t) {
        Pose p;
        if (!on) return p;
        const glm::dmat3 r = glm::make_mat3(r9);
        const glm::dvec3 c = glm::make_vec3(pivot);
        p.r = glm::normalize(glm::quat_cast(r));
        p.t = c + (t ? glm::make_vec3(t) : glm::dvec3(0.0)) - r * c;
        return p;
    };
    // Each moving joint's pose in a frame; the head's copies share them.
    auto poses = [&](const ex::FapValues& faps) {
        const ex::RigFrame f = rig.frame(faps);
        std::vector<Pose> p(joint_nodes.size());
        p[j_jaw] = p[j_head_jaw] = rigid(f.jaw, f.jaw_r, f.jaw_pivot, f.jaw_t);
        for (int e = 0; e < eyes; ++e)
            p[j_eye + e] = p[j_head_eye + e] = rigid(f.eyes[e].on, f.eyes[e].r, view.eye_centre[e], f.eyes[e].t);
        p[j_head] = rigid(f.head, f.head_r, f.head_pivot, nullptr);
        return p;
    };
    {
        const std::vector<Pose> rest = poses(still);
        for (std::size_t j = 1; j < joint_nodes.size(); ++j) {
            auto& n = m.nodes[joint_nodes[j]];
            n.rotation = {rest[j].r.x, rest[j].r.y, rest[j].r.z, rest[j].r.w};
            n.translation = {rest[j].t.x, rest[j].t.y, rest[j].t.z};
        }
    }

    if (!frames.empty()) {
        std::vector<float> t, w;
        std::vector<std::vector<float>> rot(joint_nodes.size()), tra(joint_nodes.size());
        for (std::size_t k = 0; k < frames.size(); ++k) {
            t.push_back(static_cast<float>(times[k]));
            const std::vector<float> wk = weights_of(frames[k]);
            w.insert(w.end(), wk.begin(), wk.end());
            const std::vector<Pose> pk = poses(frames[k]);
            for (std::size_t j = 1; j < joint_nodes.size(); ++j) {
                rot[j].insert(rot[j].end(), {float(pk[j].r.x), float(pk[j].r.y), float(pk[j].r.z), float(pk[j].r.w)});
                tra[j].insert(tra[j].end(), {float(pk[j].t.x), float(pk[j].t.y), float(pk[j].t.z)});
            }
        }
        tinygltf::Animation anim;
        anim.name = std::filesystem::path(a.animation).filename().string();
        const int input = add_accessor(m, t, TINYGLTF_TYPE_SCALAR, 1, true, 0);
        auto channel = [&](int output, int node, const std::string& path) {
            tinygltf::AnimationSampler s;
            s.input = input;
            s.output = output;
            s.interpolation = "LINEAR";
            anim.samplers.push_back(s);
            tinygltf::AnimationChannel ch;
            ch.sampler = static_cast<int>(anim.samplers.size()) - 1;
            ch.target_node = node;
            ch.target_path = path;
            anim.channels.push_back(ch);
        };
        channel(add_accessor(m, w, TINYGLTF_TYPE_SCALAR, 1, false, 0), n_mesh, "weights");
        for (std::size_t j = 1; j < joint_nodes.size(); ++j) {
            channel(add_accessor(m, rot[j], TINYGLTF_TYPE_VEC4, 4, false, 0), joint_nodes[j], "rotation");
            channel(add_accessor(m, tra[j], TINYGLTF_TYPE_VEC3, 3, false, 0), joint_nodes[j], "translation");
        }
        m.animations.push_back(anim);
    }
    m.buffers[0].name = "data";
    while (m.buffers[0].data.size() % 4) m.buffers[0].data.push_back(0);

    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&m, out.path(), true, true, false, true))
        fail<emoface::InputError>("export: cannot write {}", a.out);
    out.commit();
    fmt::print("{} -> {} ({} vertices, {} morph targets ({} FAPs), {} animation frames)\n",
               a.animation.empty() ? (a.mix.empty() ? "neutral" : a.mix) : a.animation, a.out, nv, names.size(),
               fap_targets, frames.size());
}

void add_export_command(CLI::App& root) {
    auto a = std::make_shared<ExportArgs>();
    auto* sub = root.add_subcommand(
        "export", "Write the face as glTF 2.0 (.glb) with morph targets (FAPs, AUs, emotions, visemes, ARKit shapes) "
                  "and an animation file's frames as a glTF animation");
    sub->add_option("animation", a->animation, "Animation file (FAP, OpenFace or ARKit CSV) to export as an animation");
    sub->add_option("--out", a->out, "The .glb file to write")->required();
    sub->add_option("--face", a->face, "default, FILE.wfm (Candide-3) or FILE.obj (with --fdp)")->capture_default_str();
    sub->add_option("--fdp", a->fdp, "Feature points of an .obj face");
    sub->add_option("--mix", a->mix, "A still expression, e.g. \"0.7 joy + 0.3 AU4\": the mesh's default weights");
    sub->add_option("--face-resolution", a->face_resolution, "The default face's mesh resolution (0.1..2)")
        ->capture_default_str();
    sub->add_option("--data", a->data, "The project's data folder")->capture_default_str();
    sub->callback([a] { export_gltf(*a); });
}

}  // namespace

EMOFACE_COMMAND(add_export_command)
