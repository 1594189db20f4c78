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
#include "gltf_buffers.h"
#include "gltf_correctives.h"
#include "gltf_parts.h"
#include "gltf_wrinkles.h"
#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
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
namespace gltf = emoface::apps::gltf;

struct ExportArgs {
    std::string out, face = "default", fdp, animation, mix, data = EMOFACE_DATA_DIR;
    double face_resolution = 1.0;
    double fap_step = 0;  // 0: per FAP, from its range
    int wrinkle_size = 512;
    int texture_size = 0;  // 0: face.json's
    bool no_wrinkles = false;
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
        fo.texture_size = a.texture_size;
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

// The reference value of FAP n for its target: the larger end of its range
// (a value the face shows), 200 units where the range is unbounded.
double fap_scale(const ex::FapRanges& r, int n, double step) {
    if (step > 0) return step;
    const double s = std::max(std::abs(r.min(n)), std::abs(r.max(n)));
    return std::isfinite(s) && s > 0 ? s : 200.0;
}

// The correctives' aim: every vertex of every exported pose within this many
// ES0 of the rig (issue 14 asks 0.02), at most kMaxCorrectives of them; the
// vertices never further off than kCorrectiveNegligible ES0 are left out.
constexpr double kCorrectiveTolerance = 0.004;
constexpr double kCorrectiveNegligible = 0.0004;
constexpr int kMaxCorrectives = 128;
// A target's vertex that moves less than this many ES0 (a hundredth of a
// millimetre on the default face) is not stored.
constexpr double kUnmoved = 1e-4;

void export_gltf(const ExportArgs& a) {
    if (!ends_with(a.out, ".glb")) fail<InputError>("export: --out {}: expected a file ending in .glb", a.out);
    if (!a.animation.empty() && !a.mix.empty())
        fail<InputError>("export: give an animation file or --mix, not both");
    emoface::apps::check_in_range("export", "--face-resolution", a.face_resolution, 0.1, 2.0);
    emoface::apps::check_in_range("export", "--wrinkle-size", a.wrinkle_size, 256, 4096);
    if (a.texture_size != 0)
        emoface::apps::check_in_range("export", "--texture-size", a.texture_size, 64, 8192, " (0: face.json's)");
    const bool wrinkles = !a.no_wrinkles && gltf::wrinkles_available();
    emoface::apps::OutputFile out(a.out, "export", "--out");

    const ex::Face face = load_face(a);
    ex::RigOptions ro;
    ro.ranges = ex::load_fap_ranges(a.data + "/expression/fap_ranges.json");
    // Owned, so the wrinkle key maker can borrow it.
    auto rig_owner = std::make_unique<ex::FaceRig>(face, ro);
    const ex::FaceRig& rig = *rig_owner;
    const auto emotions = ex::load_emotion_profiles(a.data + "/expression/emotions.json");
    const auto visemes = ex::load_viseme_profiles(a.data + "/expression/visemes.json");
    const ex::ArkitShapes arkit =
        ex::load_arkit_shapes(a.data + "/expression/arkit.json", emotions.action_units);

    // The animation (or mix) first: a bad file fails before the slow targets.
    std::vector<ex::FapValues> frames;
    std::vector<ex::FaceState> states;
    std::vector<double> times;
    if (!a.animation.empty()) {
        const ex::Animation anim = ex::read_animation_file(a.animation, a.data);
        if (anim.stream.frames.empty()) fail<InputError>("export: {}: the file has no frames", a.animation);
        for (std::size_t k = 0; k < anim.stream.frames.size(); ++k) {
            states.push_back(ex::face_state(anim.stream.resolved(k), emotions, &visemes));
            frames.push_back(states.back().faps);
            times.push_back(anim.stream.frame_time(k));
        }
    }
    ex::FapValues still{};
    ex::FaceState still_state;
    if (!a.mix.empty()) {
        still_state = ex::face_state(ex::parse_emotion_mix(a.mix), emotions);
        still = still_state.faps;
    }

    const int nv = face.vertex_count();
    const ex::RigView view = rig.view();
    const ex::DeformedFace neutral = rig.deform(ex::FapValues{});
    std::vector<float> base(3 * nv);
    for (int v = 0; v < nv; ++v)
        for (int c = 0; c < 3; ++c) base[3 * v + c] = neutral.positions[v][c];
    const double es0 = face.fapu.es * 1024;
    // A vertex a target moves less than this is stored as unmoved.
    const float unmoved = static_cast<float>(kUnmoved * es0);

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
        emoface::parallel_for(nv, 4096, [&](int begin, int end) {
            for (int v = begin; v < end; ++v) {
                const auto q = ex::rig_kernel::position(view, f, v);
                p[3 * v] = q.x, p[3 * v + 1] = q.y, p[3 * v + 2] = q.z;
            }
        });
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
        // The kernels' far tails are left out of the stored target (the
        // correctives take up what that leaves at the exported frames).
        for (int v = 0; v < nv; ++v)
            if (std::max({std::abs(d[3 * v]), std::abs(d[3 * v + 1]), std::abs(d[3 * v + 2])}) <= unmoved)
                d[3 * v] = d[3 * v + 1] = d[3 * v + 2] = 0.0f;
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

    // Correctives: what the FAP targets leave of the rig's motion at the
    // exported poses (gltf_correctives.h says what and why), so that the
    // file reproduces the rig at every frame.
    const std::vector<ex::FapValues> poses = frames.empty() ? std::vector<ex::FapValues>{still} : frames;
    gltf::Correctives correctives;
    {
        struct Moved {
            int v;
            float d[3];
        };
        std::vector<std::vector<Moved>> moved(fap_targets);
        for (std::size_t t = 0; t < fap_targets; ++t)
            for (int v = 0; v < nv; ++v) {
                const float* d = &deltas[t][3 * v];
                if (d[0] != 0 || d[1] != 0 || d[2] != 0) moved[t].push_back({v, {d[0], d[1], d[2]}});
            }
        // A vertex off by less than this in every pose is left as it is.
        const float negligible = static_cast<float>(kCorrectiveNegligible * es0);
        std::vector<std::vector<std::pair<int, std::array<float, 3>>>> off(poses.size());
        std::vector<char> active(nv, 0);
        std::vector<float> exact;
        for (std::size_t k = 0; k < poses.size(); ++k) {
            morph_stage(poses[k], exact);
            for (int i = 0; i < 3 * nv; ++i) exact[i] -= base[i];
            const std::vector<float> w = weights_of(poses[k]);
            for (std::size_t t = 0; t < fap_targets; ++t)
                if (w[t] != 0)
                    for (const Moved& mv : moved[t])
                        for (int c = 0; c < 3; ++c) exact[3 * mv.v + c] -= w[t] * mv.d[c];
            for (int v = 0; v < nv; ++v) {
                const float* r = &exact[3 * v];
                if (std::max({std::abs(r[0]), std::abs(r[1]), std::abs(r[2])}) <= negligible) continue;
                off[k].push_back({v, {r[0], r[1], r[2]}});
                active[v] = 1;
            }
        }
        std::vector<int> vertices, row_of(nv, -1);
        for (int v = 0; v < nv; ++v)
            if (active[v]) row_of[v] = static_cast<int>(vertices.size()), vertices.push_back(v);
        std::vector<std::vector<float>> remainders(poses.size(), std::vector<float>(3 * vertices.size(), 0.0f));
        for (std::size_t k = 0; k < poses.size(); ++k) {
            for (const auto& [v, r] : off[k]) std::copy(r.begin(), r.end(), &remainders[k][3 * row_of[v]]);
            std::vector<std::pair<int, std::array<float, 3>>>().swap(off[k]);
        }
        correctives = gltf::fit_correctives(vertices, std::move(remainders), nv, kCorrectiveTolerance * es0,
                                            kMaxCorrectives);
    }
    const std::size_t first_corrective = names.size();
    for (std::size_t c = 0; c < correctives.targets.size(); ++c) {
        names.push_back(fmt::format("corrective_{}", c + 1));
        deltas.push_back(std::move(correctives.targets[c]));
    }
    // A pose's weights: its FAPs' and its correctives'.
    auto pose_weights = [&](std::size_t k) {
        std::vector<float> w = weights_of(poses[k]);
        const std::vector<float>& c = correctives.weights[k];
        std::copy(c.begin(), c.end(), w.begin() + first_corrective);
        return w;
    };

    tinygltf::Model m;
    m.asset.version = "2.0";
    m.asset.generator = "emoface export";
    m.buffers.resize(1);

    tinygltf::Primitive prim;
    prim.mode = TINYGLTF_MODE_TRIANGLES;
    prim.attributes["POSITION"] = gltf::add_floats(m, base, TINYGLTF_TYPE_VEC3, 3, true);
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
        prim.attributes["NORMAL"] = gltf::add_floats(m, n, TINYGLTF_TYPE_VEC3, 3, false);
        if (face.mesh.has_vertex_texcoords2D()) {
            std::vector<float> uv(2 * nv);
            for (int v = 0; v < nv; ++v) {
                const auto t = face.mesh.texcoord2D(ex::TriMesh::VertexHandle(v));
                uv[2 * v] = t[0];
                uv[2 * v + 1] = 1.0f - t[1];  // glTF's v runs down the image
            }
            prim.attributes["TEXCOORD_0"] = gltf::add_floats(m, uv, TINYGLTF_TYPE_VEC2, 2, false);
        }
        if (wrinkles) {
            // The wrinkle maps' UV set: the neutral face projected frontally
            // into its texture box (v down, as glTF's).
            std::vector<float> uv(2 * nv);
            for (int v = 0; v < nv; ++v) {
                const glm::vec2 t = ex::project_to_texture(glm::vec3(base[3 * v], base[3 * v + 1], base[3 * v + 2]),
                                                           face.texture_box);
                uv[2 * v] = t.x;
                uv[2 * v + 1] = t.y;
            }
            prim.attributes["TEXCOORD_1"] = gltf::add_floats(m, uv, TINYGLTF_TYPE_VEC2, 2, false);
            // The skin's normal texture is sampled in this set: its tangents.
            prim.attributes["TANGENT"] =
                gltf::add_floats(m, gltf::wrinkle_tangents(mesh, uv), TINYGLTF_TYPE_VEC4, 4, false);
        }
    }
    // Sparse: a target stores only the vertices it moves (most move a small
    // region).
    for (const auto& d : deltas) prim.targets.push_back({{"POSITION", gltf::add_sparse_vec3(m, d, unmoved)}});

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
        acc.bufferView = gltf::add_view(m, joints.data(), joints.size() * 2, TINYGLTF_TARGET_ARRAY_BUFFER);
        acc.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
        acc.type = TINYGLTF_TYPE_VEC4;
        acc.count = nv;
        m.accessors.push_back(acc);
        prim.attributes["JOINTS_0"] = static_cast<int>(m.accessors.size()) - 1;
        prim.attributes["WEIGHTS_0"] = gltf::add_floats(m, jw, TINYGLTF_TYPE_VEC4, 4, false);
    }

    // The wrinkle keys (textures; layouts and AU targets in extras).
    gltf::WrinkleExport wrinkle_keys;
    if (wrinkles) {
        std::vector<ex::FaceState> exported = states;
        if (exported.empty()) exported.push_back(still_state);
        wrinkle_keys = gltf::add_wrinkle_keys(m, face, rig_owner, emotions, a.data, a.wrinkle_size, names, exported);
    }

    // One material per part, sharing the base colour; one primitive each,
    // sharing the vertices and targets.
    int base_colour = -1;
    if (!face.base_colour.empty() && prim.attributes.count("TEXCOORD_0"))
        base_colour = gltf::add_texture(m, gltf::add_png(m, "base_colour", face.base_colour.width,
                                                         face.base_colour.height, face.base_colour.rgba.data()));
    tinygltf::Mesh mesh;
    for (const gltf::PartMaterial& part : gltf::split_into_parts(face, view)) {
        tinygltf::Material mat;
        mat.name = part.name;
        mat.pbrMetallicRoughness.metallicFactor = 0.0;
        mat.pbrMetallicRoughness.roughnessFactor = part.roughness;
        mat.doubleSided = true;
        if (base_colour >= 0) mat.pbrMetallicRoughness.baseColorTexture.index = base_colour;
        if (part.name == "skin" && wrinkle_keys.neutral_texture >= 0) {
            mat.normalTexture.index = wrinkle_keys.neutral_texture;
            mat.normalTexture.texCoord = 1;
        }
        tinygltf::Value::Object me;
        me["roughness"] = tinygltf::Value(std::string(part.why));
        mat.extras = tinygltf::Value(me);
        m.materials.push_back(mat);
        tinygltf::Primitive p = prim;
        p.indices = gltf::add_indices(m, part.triangles, nv);
        p.material = static_cast<int>(m.materials.size()) - 1;
        mesh.primitives.push_back(p);
    }

    mesh.name = face.name.empty() ? "face" : face.name;
    {
        const std::vector<float> w = frames.empty() ? pose_weights(0) : weights_of(still);
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
            "viseme and ARKit targets are sums of the FAP targets with their profile's values; corrective_* "
            "targets carry what the FAP targets leave of the rig's motion at the exported frames (the lids' slide "
            "over the eyeballs, the lashes' turn, the pupils' dilation), weighted by the animation"));
        if (wrinkles) extras["wrinkles"] = wrinkle_keys.extras;
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
    auto joint_poses = [&](const ex::FapValues& faps) {
        const ex::RigFrame f = rig.frame(faps);
        std::vector<Pose> p(joint_nodes.size());
        p[j_jaw] = p[j_head_jaw] = rigid(f.jaw, f.jaw_r, f.jaw_pivot, f.jaw_t);
        for (int e = 0; e < eyes; ++e)
            p[j_eye + e] = p[j_head_eye + e] = rigid(f.eyes[e].on, f.eyes[e].r, view.eye_centre[e], f.eyes[e].t);
        p[j_head] = rigid(f.head, f.head_r, f.head_pivot, nullptr);
        return p;
    };
    {
        const std::vector<Pose> rest = joint_poses(still);
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
            const std::vector<float> wk = pose_weights(k);
            w.insert(w.end(), wk.begin(), wk.end());
            const std::vector<Pose> pk = joint_poses(frames[k]);
            for (std::size_t j = 1; j < joint_nodes.size(); ++j) {
                rot[j].insert(rot[j].end(), {float(pk[j].r.x), float(pk[j].r.y), float(pk[j].r.z), float(pk[j].r.w)});
                tra[j].insert(tra[j].end(), {float(pk[j].t.x), float(pk[j].t.y), float(pk[j].t.z)});
            }
        }
        tinygltf::Animation anim;
        anim.name = std::filesystem::path(a.animation).filename().string();
        const int input = gltf::add_floats(m, t, TINYGLTF_TYPE_SCALAR, 1, true, 0);
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
        channel(gltf::add_floats(m, w, TINYGLTF_TYPE_SCALAR, 1, false, 0), n_mesh, "weights");
        for (std::size_t j = 1; j < joint_nodes.size(); ++j) {
            channel(gltf::add_floats(m, rot[j], TINYGLTF_TYPE_VEC4, 4, false, 0), joint_nodes[j], "rotation");
            channel(gltf::add_floats(m, tra[j], TINYGLTF_TYPE_VEC3, 3, false, 0), joint_nodes[j], "translation");
        }
        if (!wrinkle_keys.key_names.empty()) {
            // glTF animates no extras: the wrinkle keys' weights per frame
            // (frame-major, keys in wrinkles.keys' order) for an engine to
            // play alongside.
            std::vector<float> kw;
            for (const auto& fw : wrinkle_keys.frame_weights) kw.insert(kw.end(), fw.begin(), fw.end());
            tinygltf::Value::Object ae;
            ae["wrinkleWeights"] = tinygltf::Value(gltf::add_floats(m, kw, TINYGLTF_TYPE_SCALAR, 1, false, 0));
            tinygltf::Value::Array kn;
            for (const auto& n : wrinkle_keys.key_names) kn.emplace_back(n);
            ae["wrinkleKeys"] = tinygltf::Value(kn);
            anim.extras = tinygltf::Value(ae);
        }
        m.animations.push_back(anim);
    }
    m.buffers[0].name = "data";
    while (m.buffers[0].data.size() % 4) m.buffers[0].data.push_back(0);

    tinygltf::TinyGLTF writer;
    if (!writer.WriteGltfSceneToFile(&m, out.path(), true, true, false, true))
        fail<emoface::InputError>("export: cannot write {}", a.out);
    out.commit();
    fmt::print("{} -> {} ({} vertices, {} morph targets ({} FAPs, {} correctives: the worst vertex {:.4f} ES0 off "
               "the rig before skinning, {:.4f} without them), {} wrinkle keys, {} animation frames)\n",
               a.animation.empty() ? (a.mix.empty() ? "neutral" : a.mix) : a.animation, a.out, nv, names.size(),
               fap_targets, names.size() - first_corrective, correctives.worst_left / es0,
               correctives.worst_before / es0,
               wrinkle_keys.key_names.size(), frames.size());
}

void add_export_command(CLI::App& root) {
    auto a = std::make_shared<ExportArgs>();
    auto* sub = root.add_subcommand(
        "export", "Write the face as glTF 2.0 (.glb) with morph targets (FAPs, AUs, emotions, visemes, ARKit shapes) "
                  "and an animation file's frames as a glTF animation");
    sub->add_option("animation", a->animation, "Animation file (FAP, or an OpenFace, Live Link Face or MediaPipe CSV) to export as an animation");
    sub->add_option("--out", a->out, "The .glb file to write")->required();
    sub->add_option("--face", a->face, "default, FILE.wfm (Candide-3) or FILE.obj (with --fdp)")->capture_default_str();
    sub->add_option("--fdp", a->fdp, "Feature points of an .obj face");
    sub->add_option("--mix", a->mix, "A still expression, e.g. \"0.7 joy + 0.3 AU4\": the mesh's default weights");
    sub->add_option("--face-resolution", a->face_resolution, "The default face's mesh resolution (0.1..2)")
        ->capture_default_str();
    sub->add_option("--wrinkle-size", a->wrinkle_size, "Side of the wrinkle key maps in pixels (256..4096)")
        ->capture_default_str();
    // As mix's and face's: the base colour's painting is most of an export's
    // time, which the tests, checking the mesh and its targets, need not pay.
    sub->add_option("--texture-size", a->texture_size, "Base-colour image side of the default face (0: face.json's)")
        ->capture_default_str();
    sub->add_flag("--no-wrinkles", a->no_wrinkles, "Leave the wrinkle key maps out");
    sub->add_option("--data", a->data, "The project's data folder")->capture_default_str();
    sub->callback([a] { export_gltf(*a); });
}

}  // namespace

EMOFACE_COMMAND(add_export_command)
