#include "gltf_wrinkles.h"

#include <algorithm>

#include <fmt/format.h>

#include "gltf_buffers.h"

#if EMOFACE_APPS_RENDER
#include "emoface/render/face_assets.h"
#include "emoface/render/tangents.h"
#endif

namespace emoface::apps::gltf {

#if EMOFACE_APPS_RENDER

bool wrinkles_available() { return true; }

std::vector<float> wrinkle_tangents(const expression::TriMesh& mesh, const std::vector<float>& uv) {
    // The frames' bitangent runs along +v of the UVs given: up the image
    // for (u, 1 - v).
    std::vector<glm::vec2> up(uv.size() / 2);
    for (std::size_t v = 0; v < up.size(); ++v) up[v] = {uv[2 * v], 1.0f - uv[2 * v + 1]};
    render::TangentFrames frames;
    frames.compute(mesh, up);
    std::vector<float> out;
    out.reserve(4 * up.size());
    for (const glm::vec4& t : frames.tangents()) out.insert(out.end(), {t.x, t.y, t.z, t.w < 0 ? -1.0f : 1.0f});
    return out;
}

namespace {

namespace ex = emoface::expression;
using tinygltf::Value;

// glTF's normal textures have green up the image (OpenGL's convention); the
// keys have it down (wrinkle_map.h), so green is flipped on the way out.
int add_normal_map(tinygltf::Model& m, const std::string& name, const ex::NormalMap& map) {
    std::vector<std::uint8_t> rgba = map.rgba;
    for (std::size_t i = 1; i < rgba.size(); i += 4) rgba[i] = static_cast<std::uint8_t>(255 - rgba[i]);
    return add_texture(m, add_png(m, name, map.width, map.height, rgba.data()));
}

Value layout_value(const ex::FeatureLayout& layout) {
    Value::Object points;
    for (int k = 0; k < ex::kFeatureCount; ++k)
        if (layout.present[k])
            points[std::string(fap::feature_points()[k].id)] =
                Value(Value::Array{Value(double(layout.points[k].x)), Value(double(layout.points[k].y))});
    return Value(points);
}

const char* side_name(ex::AuSide s) { return s == ex::AuSide::Left ? "left" : s == ex::AuSide::Right ? "right" : "both"; }

}  // namespace

WrinkleExport add_wrinkle_keys(tinygltf::Model& m, const ex::Face& face, std::unique_ptr<ex::FaceRig>& rig,
                               const ex::EmotionProfiles& emotions, const std::string& data_dir, int size,
                               const std::vector<std::string>& target_names, const std::vector<ex::FaceState>& states) {
    // The key maker works on assets; the rig is lent to them for it.
    render::FaceAssets assets;
    assets.face = face;
    assets.rig = std::move(rig);
    assets.emotions = emotions;
    assets.wrinkles = ex::load_wrinkle_spec(data_dir + "/expression/wrinkles.json");
    std::bitset<ex::kFeatureCount> present;
    for (int i = 0; i < ex::kFeatureCount; ++i) present[i] = face.feature_points[i].present;
    const std::vector<ex::FeatureLine> lines =
        ex::lines_for_face(ex::load_feature_lines(data_dir + "/expression/feature_lines.json"), present);
    std::vector<render::WrinkleKey> keys;
    try {
        keys = render::make_action_unit_keys(assets, size);
    } catch (...) {
        rig = std::move(assets.rig);
        throw;
    }
    rig = std::move(assets.rig);

    WrinkleExport out;
    Value::Array key_values, line_values;
    std::vector<render::WrinkleKey> au_keys;
    for (const render::WrinkleKey& key : keys) {
        if (key.name == "neutral") {
            out.neutral_texture = add_normal_map(m, "wrinkle_neutral", key.map);
            continue;
        }
        const auto driver = render::key_driver(key.name);
        const std::string target = fmt::format("AU{}", driver->au.number);
        const auto it = std::find(target_names.begin(), target_names.end(), target);
        Value::Object k;
        k["name"] = Value(key.name);
        k["texture"] = Value(add_normal_map(m, "wrinkle_" + key.name, key.map));
        k["image"] = Value(static_cast<int>(m.images.size()) - 1);
        k["target"] = Value(it == target_names.end() ? -1 : static_cast<int>(it - target_names.begin()));
        k["targetName"] = Value(target);
        k["side"] = Value(std::string(side_name(driver->au.side)));
        k["layout"] = layout_value(key.layout);
        k["region"] = Value(Value::Array{Value(double(key.region.min.x)), Value(double(key.region.min.y)),
                                         Value(double(key.region.max.x)), Value(double(key.region.max.y))});
        key_values.emplace_back(k);
        out.key_names.push_back(key.name);
        au_keys.push_back(key);
    }
    for (const ex::FeatureLine& l : lines)
        line_values.emplace_back(Value::Array{Value(std::string(fap::feature_points()[l.from].id)),
                                              Value(std::string(fap::feature_points()[l.to].id))});
    for (const ex::FaceState& s : states) out.frame_weights.push_back(render::key_weights(au_keys, s));

    Value::Object w;
    w["about"] = Value(std::string(
        "Wrinkle key maps: tangent-space normal maps (glTF convention, green up) in the UV set TEXCOORD_1 (the "
        "neutral face projected frontally), each drawn where the feature points sit in its own pose (layout: "
        "feature point id -> [x, y], y down the image). A key's weight is the weight of its AU morph target "
        "(target, an index into targetNames); side: the half of the face it covers (a left and a right key share "
        "their AU target). Blend: normal = normalize(neutral + sum of weight x (key - flat)). For exactness warp "
        "each key from its layout to the current one along featureLines (pairs of feature point ids), as emoface "
        "does; the animation's own key weights per frame are in animations[0].extras.wrinkleWeights."));
    w["size"] = Value(size);
    w["neutralTexture"] = Value(out.neutral_texture);
    w["texCoord"] = Value(1);
    w["featureLines"] = Value(line_values);
    w["keys"] = Value(key_values);
    out.extras = Value(w);
    return out;
}

#else

bool wrinkles_available() { return false; }

std::vector<float> wrinkle_tangents(const expression::TriMesh&, const std::vector<float>&) { return {}; }

WrinkleExport add_wrinkle_keys(tinygltf::Model&, const expression::Face&, std::unique_ptr<expression::FaceRig>&,
                               const expression::EmotionProfiles&, const std::string&, int,
                               const std::vector<std::string>&, const std::vector<expression::FaceState>&) {
    return {};
}

#endif

}  // namespace emoface::apps::gltf
