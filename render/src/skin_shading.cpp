// Reads data/render/skin.json with the project's one strict JSON reader
// (expression/src/json_reader.h): every key required, unknown keys are errors.
#include "emoface/render/skin_shading.h"

#include "json_reader.h"

namespace emoface::render {
namespace {

using expression::detail::JsonReader;

glm::vec3 vec3_at(JsonReader& r, const std::string& key) {
    const auto v = r.numbers<3>(key);
    return {float(v[0]), float(v[1]), float(v[2])};
}
glm::vec3 colour_at(JsonReader& r, const std::string& key) {
    JsonReader c = r.at(key);
    const auto v = c.as_numbers<3>();
    for (double x : v)
        if (x < 0.0) c.fail("three linear intensities >= 0");
    return {float(v[0]), float(v[1]), float(v[2])};
}
RigLight rig_light(JsonReader r) {
    RigLight l;
    l.direction = vec3_at(r, "direction");
    if (l.direction == glm::vec3(0.0f)) r.at("direction").fail("a direction of non-zero length");
    l.colour = colour_at(r, "colour");
    r.finish();
    return l;
}

}  // namespace

SkinShading load_skin_shading(const std::string& path) {
    return expression::detail::read_json_file(path, [](JsonReader& root) {
        SkinShading s;
        JsonReader scatter = root.object("scattering");
        std::vector<JsonReader> gaussians = scatter.objects("profile");
        if (gaussians.size() != s.profile.size())
            scatter.at("profile").fail("6 Gaussians (d'Eon & Luebke 2007)");
        for (std::size_t i = 0; i < gaussians.size(); ++i) {
            JsonReader& g = gaussians[i];
            s.profile[i].variance_mm2 = float(g.number_in("variance_mm2", 1e-6, 1e3));
            s.profile[i].weight = colour_at(g, "weight");
            g.finish();
        }
        s.max_curvature = float(scatter.number_in("max_curvature_per_mm", 1e-3, 10.0));
        s.min_curvature = float(scatter.number_in("min_curvature_per_mm", 0.0, s.max_curvature));
        s.mm_per_unit = float(scatter.number_in("mm_per_unit", 1e-6, 1e6));
        const auto softening = scatter.numbers<2>("normal_softening");
        s.normal_softening = {float(softening[0]), float(softening[1])};
        for (int c = 0; c < 2; ++c)
            if (s.normal_softening[c] < 0.0f || s.normal_softening[c] > 1.0f)
                scatter.at("normal_softening").fail("two numbers in [0, 1] (red; green and blue)");
        s.cavity_direct = float(scatter.number_in("cavity_direct", 0.0, 1.0));
        scatter.finish();

        JsonReader spec = root.object("specular");
        s.f0 = float(spec.number_in("f0", 0.0, 1.0));
        const auto rough = spec.numbers<2>("roughness");
        for (int i = 0; i < 2; ++i) {
            if (!(rough[std::size_t(i)] > 0.0 && rough[std::size_t(i)] <= 1.0))
                spec.at("roughness").fail("two roughnesses in (0, 1]");
            s.roughness[std::size_t(i)] = float(rough[std::size_t(i)]);
        }
        s.lobe_weight = float(spec.number_in("lobe_weight", 0.0, 1.0));
        s.gloss_exponent = float(spec.number_in("gloss_exponent", 0.0, 8.0));
        s.matte_sheen = float(spec.number_in("matte_sheen", 0.0, 1.0));
        s.full_sheen_gloss = float(spec.number_in("full_sheen_gloss", 0.0, 0.99));
        spec.finish();

        JsonReader occlusion = root.object("occlusion");
        s.occlusion_key = float(occlusion.number_in("key", 0.0, 1.0));
        s.occlusion_fill = float(occlusion.number_in("fill", 0.0, 1.0));
        s.occlusion_specular = float(occlusion.number_in("specular", 0.0, 1.0));
        s.occlusion_key_lean = float(occlusion.number_in("key_lean", 0.0, 4.0));
        s.occlusion_key_cone_max = float(occlusion.number_in("key_cone_max", 0.0, 1.0));
        s.key_shadow = float(occlusion.number_in("key_shadow", 0.0, 1.0));
        const auto fade = occlusion.numbers<2>("key_shadow_fade_deg");
        if (!(fade[0] >= 0.0 && fade[0] < fade[1] && fade[1] <= 90.0))
            occlusion.at("key_shadow_fade_deg").fail("an increasing pair of angles in [0, 90]");
        for (int i = 0; i < 2; ++i) s.key_shadow_fade_deg[std::size_t(i)] = float(fade[std::size_t(i)]);
        occlusion.finish();

        JsonReader pores = root.object("pores");
        s.pores.size = pores.integer_in("map_size", 8, 2048);
        if (s.pores.size % 4 != 0) pores.at("map_size").fail("a multiple of 4");
        s.pores.cells = pores.integer_in("cells", 1, s.pores.size / 2);
        s.pores.pit_radius = float(pores.number_in("pit_radius", 0.0, 1.5));
        s.pores.pit_depth = float(pores.number_in("pit_depth", 0.0, 10.0));
        s.pores.noise_scale = float(pores.number_in("noise_scale", 0.0, 10.0));
        s.pores.seed = unsigned(pores.integer_in("seed", 0, 1 << 30));
        s.pore_tiles = float(pores.number_in("tiles_per_uv", 1e-3, 1e4));
        s.pore_strength = float(pores.number_in("strength", 0.0, 4.0));
        pores.finish();

        JsonReader detail = root.object("albedo_detail");
        s.albedo_bump_mm = float(detail.number_in("bump_mm", 0.0, 10.0));
        s.albedo_bump_bias = float(detail.number_in("mip_bias", 0.5, 8.0));
        detail.finish();

        JsonReader hair = root.object("hair");
        const auto lum = hair.numbers<2>("mean_luminance");
        if (!(lum[0] >= 0.0 && lum[0] < lum[1] && lum[1] <= 1.0))
            hair.at("mean_luminance").fail("an increasing pair in [0, 1]");
        s.hair_luminance = {float(lum[0]), float(lum[1])};
        s.hair_wrap = float(hair.number_in("wrap", 0.0, 1.0));
        s.hair_roughness = float(hair.number_in("roughness", 0.01, 1.0));
        s.hair_sheen = float(hair.number_in("sheen", 0.0, 1.0));
        hair.finish();

        JsonReader wet = root.object("wet");
        s.wet_f0 = float(wet.number_in("f0", 0.0, 1.0));
        s.wet_broad_roughness = float(wet.number_in("broad_roughness", 0.01, 1.0));
        s.wet_broad_weight = float(wet.number_in("broad_weight", 0.0, 1.0));
        s.wet_tight_scale = float(wet.number_in("tight_scale", 0.05, 4.0));
        s.wet_sheen = float(wet.number_in("sheen", 0.0, 8.0));
        wet.finish();

        JsonReader rig = root.object("light_rig");
        s.key_tint = colour_at(rig, "key_tint");
        s.softness = float(rig.number_in("softness", 0.0, 1.0));
        s.fill = rig_light(rig.object("fill"));
        s.rim = rig_light(rig.object("rim"));
        s.sky = colour_at(rig, "sky");
        s.ground = colour_at(rig, "ground");
        s.exposure = float(rig.number_in("exposure", 1e-3, 1e3));
        const std::string tone = rig.string("tone_mapping");
        if (tone == "aces") s.tone_mapping = ToneMapping::Aces;
        else if (tone == "none") s.tone_mapping = ToneMapping::None;
        else rig.at("tone_mapping").fail("\"aces\" or \"none\"");
        rig.finish();
        return s;
    });
}

}  // namespace emoface::render
