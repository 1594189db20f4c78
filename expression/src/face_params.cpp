#include "face_params.h"

#include "json_reader.h"

namespace emoface::expression::detail {
namespace {

glm::dvec2 to_glm(const std::array<double, 2>& a) { return {a[0], a[1]}; }
glm::dvec3 to_glm(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

// Reads an ellipsoid's keys; the caller may read more keys of the object, then finishes it.
Ellipsoid read_ellipsoid(JsonReader& r) {
    Ellipsoid e;
    e.centre = to_glm(r.numbers<3>("centre"));
    e.radii = to_glm(r.numbers<3>("radii"));
    e.tilt_deg = r.number("tilt_deg", 0.0);
    e.exponent = r.number_in("exponent", 2.0, 8.0, 2.0);
    for (int i = 0; i < 3; ++i)
        if (!(e.radii[i] > 0.0)) r.at("radii").fail("3 positive radii");
    return e;
}

std::vector<RowKey> read_row_keys(JsonReader& r, const std::string& key) {
    std::vector<RowKey> keys;
    const std::vector<JsonReader> objects = r.objects(key);
    for (JsonReader k : objects) {
        RowKey rk;
        rk.origin_y = k.number("origin_y");
        const auto z = k.numbers<2>("origin_z");
        const auto a = k.numbers<2>("angle_deg");
        rk.origin_z_front = z[0];
        rk.origin_z_back = z[1];
        rk.angle_front_deg = a[0];
        rk.angle_back_deg = a[1];
        rk.spacing = k.number("spacing", 0.0);
        if (rk.spacing < 0 || (rk.spacing > 0 && rk.spacing < 0.2))
            k.at("spacing").fail("0 (the resolution's spacing) or at least 0.2 mm");
        k.finish();
        keys.push_back(rk);
    }
    if (keys.size() < 2) r.at(key).fail("at least 2 row keys", std::to_string(keys.size()));
    return keys;
}

Bump read_bump(JsonReader b) {
    Bump out;
    out.name = b.string("name");
    out.centre = to_glm(b.numbers<2>("centre"));
    out.radius = to_glm(b.numbers<2>("radius"));
    out.height = b.number("height");
    out.angle_deg = b.number("angle_deg", 0.0);
    out.mirror = b.boolean("mirror", false);
    if (!(out.radius[0] > 0.0 && out.radius[1] > 0.0)) b.at("radius").fail("2 positive radii");
    b.finish();
    return out;
}

glm::dvec3 colour(JsonReader& r, const std::string& key) { return to_glm(r.numbers<3>(key)); }

// A Gaussian patch of the face's albedo (a flush, a pore region): where, how
// wide, and how much, its amount in [min_amount, max_amount].
FaceParams::Flush read_patch(JsonReader& r, double min_amount, double max_amount) {
    FaceParams::Flush patch;
    patch.centre = to_glm(r.numbers<2>("centre"));
    patch.size = to_glm(r.numbers<2>("size"));
    if (!(patch.size[0] > 0 && patch.size[1] > 0)) r.at("size").fail("two widths > 0 (mm)");
    patch.amount = r.number_in("amount", min_amount, max_amount);
    r.finish();
    return patch;
}

}  // namespace

FaceParams read_face_params(const std::string& params_dir) {
    FaceParams p;
    p.file = params_dir + "/face.json";
    read_json_file(p.file, [&](JsonReader& top) {
        {
            JsonReader r = top.object("resolution");
            p.front_columns = r.integer_in("front_columns", 8, 4000);
            p.back_columns = r.integer_in("back_columns", 4, 4000);
            p.front_half_angle_deg = r.number("front_half_angle_deg");
            p.row_spacing = r.number_in("row_spacing_mm", 0.2, 50);
            p.upper_rows = read_row_keys(r, "upper_rows");
            p.lower_rows = read_row_keys(r, "lower_rows");
            {
                JsonReader b = r.object("bust");
                p.bust_rows = b.integer_in("rows", 0, 200);
                p.bust_length_mm = to_glm(b.numbers<3>("length_mm"));
                for (int c = 0; c < 3; ++c)
                    if (!(p.bust_length_mm[c] >= 1.0 && p.bust_length_mm[c] <= 500.0))
                        b.at("length_mm").fail("lengths in 1..500 mm (front, side, back)");
                p.bust_first_share = b.number_in("first_share", 0.1, 1.0);
                p.bust_texture_rows = b.number_in("texture_rows", 1.0, 200.0);
                b.finish();
            }
            p.eyeball_rings = r.integer_in("eyeball_rings", 6, 512);
            p.eyeball_segments = r.integer_in("eyeball_segments", 8, 512);
            p.texture_size = r.integer_in("texture_size", 16, 8192);
            r.finish();
        }
        {
            JsonReader r = top.object("head");
            for (JsonReader part : r.objects("parts")) {
                HeadPart hp;
                hp.name = part.string("name");
                hp.is_capsule = part.has("from");
                if (hp.is_capsule) {
                    hp.capsule.from = to_glm(part.numbers<3>("from"));
                    hp.capsule.to = to_glm(part.numbers<3>("to"));
                    hp.capsule.radii = to_glm(part.numbers<2>("radii"));
                    hp.capsule.mirror = part.boolean("mirror", false);
                    if (!(hp.capsule.radii[0] > 0 && hp.capsule.radii[1] > 0)) part.at("radii").fail("2 positive radii");
                } else {
                    hp.shape = read_ellipsoid(part);
                }
                hp.blend = part.number_in("blend", 0.0, 100.0, 0.0);
                part.finish();
                p.head_parts.push_back(std::move(hp));
            }
            if (p.head_parts.empty()) r.at("parts").fail("at least one part");
            JsonReader neck = r.object("neck");
            p.neck_centre_z = neck.number("centre_z");
            p.neck_radii = to_glm(neck.numbers<2>("radii"));
            p.neck_top_y = neck.number("top_y");
            p.neck_lean_deg = neck.number_in("lean_deg", -45.0, 45.0, 0.0);
            p.neck_blend = neck.number("blend");
            neck.finish();
            JsonReader shoulders = r.object("shoulders");
            p.shoulders = read_ellipsoid(shoulders);
            p.shoulders_blend = shoulders.number_in("blend", 0.0, 200.0);
            shoulders.finish();
            JsonReader hv = r.object("hair_volume");
            p.hair_volume.top = hv.number_in("top", 0.0, 40.0);
            p.hair_volume.sides = hv.number_in("sides", 0.0, 40.0);
            p.hair_volume.nape = hv.number_in("nape", 0.0, 40.0);
            p.hair_volume.fade = hv.number_in("fade", 0.5, 60.0);
            p.hair_volume.lumps = hv.number_in("lumps", 0.0, 0.8);
            p.hair_volume.lump_size = hv.number_in("lump_mm", 2.0, 100.0);
            p.hair_volume.tuft_size = to_glm(hv.numbers<2>("tuft_mm"));
            if (!(p.hair_volume.tuft_size[0] >= 1.0 && p.hair_volume.tuft_size[1] >= 1.0))
                hv.at("tuft_mm").fail("2 sizes of at least 1 mm");
            p.hair_volume.tufts = hv.number_in("tufts", 0.0, 0.9);
            hv.finish();
            r.finish();
        }
        {
            JsonReader r = top.object("eyes");
            p.eye_centre = to_glm(r.numbers<3>("centre"));
            p.eye_radius = r.number("radius");
            p.iris_radius = r.number("iris_radius");
            p.pupil_radius = r.number("pupil_radius");
            {
                JsonReader c = r.object("cornea");
                p.cornea_radius = c.number_in("radius", 5.0, 12.0);
                p.cornea_reach = c.number_in("reach", 1.0, 5.0);
                c.finish();
            }
            p.inner_corner = to_glm(r.numbers<2>("inner_corner"));
            p.outer_corner = to_glm(r.numbers<2>("outer_corner"));
            p.upper_lid_height = r.number("upper_lid_height");
            p.lower_lid_height = r.number("lower_lid_height");
            p.upper_lid_peak = r.number("upper_lid_peak");
            p.lower_lid_peak = r.number("lower_lid_peak");
            p.lid_clearance = r.number("lid_clearance");
            p.lid_thickness = r.number("lid_thickness");
            p.lid_blend_inner = r.number("lid_blend_inner");
            p.lid_blend_outer = r.number("lid_blend_outer");
            p.lid_rise = r.number_in("lid_rise", 0.0, 0.5);
            p.lid_warp_reach = r.number("lid_warp_reach");
            p.sclera_corner_tint = r.number_in("sclera_corner_tint", 0.0, 1.0);
            p.sclera_vessels = r.number_in("sclera_vessels", 0.0, 1.0);
            p.lid_shadow = r.number_in("lid_shadow", 0.0, 0.8);
            {
                JsonReader l = r.object("lash_line");
                auto& ll = p.lash_line;
                ll.width = to_glm(l.numbers<2>("width_mm"));
                if (!(ll.width[0] >= 0.0 && ll.width[1] >= 0.0 && ll.width[0] < 5.0 && ll.width[1] < 5.0))
                    l.at("width_mm").fail("two widths in [0, 5) (mm)");
                ll.amount = to_glm(l.numbers<2>("amount"));
                if (!(ll.amount[0] >= 0.0 && ll.amount[1] >= 0.0 && ll.amount[0] <= 1.0 && ll.amount[1] <= 1.0))
                    l.at("amount").fail("two amounts in [0, 1]");
                ll.upper_margin = l.number_in("upper_margin", 0.0, 1.0);
                ll.lower = l.number_in("lower", 0.0, 1.0);
                l.finish();
            }
            {
                JsonReader l = r.object("lid_crease");
                p.lid_crease.height = l.number_in("height_mm", 1.0, 15.0);
                p.lid_crease.width = l.number_in("width_mm", 0.2, 5.0);
                p.lid_crease.amount = l.number_in("amount", 0.0, 0.6);
                l.finish();
            }
            for (auto [key, row] : {std::pair{"upper_lashes", &p.upper_lashes}, std::pair{"lower_lashes", &p.lower_lashes}}) {
                JsonReader l = r.object(key);
                row->count = l.integer_in("count", 0, 400);
                row->length = l.number_in("length", 0.5, 20.0);
                row->width = l.number_in("width", 0.01, 1.0);
                row->lift_deg = l.number_in("lift_deg", -90.0, 90.0);
                row->curl_deg = l.number_in("curl_deg", -90.0, 90.0);
                l.finish();
            }
            if (!(p.eye_radius > 0 && p.iris_radius > p.pupil_radius && p.pupil_radius > 0 &&
                  p.iris_radius < p.eye_radius))
                r.fail("radius > iris_radius > pupil_radius > 0",
                       fmt::format("{} > {} > {}", p.eye_radius, p.iris_radius, p.pupil_radius));
            if (!(p.inner_corner[0] > 0)) r.at("inner_corner").fail("x > 0 (the face's left)");
            if (!(p.outer_corner[0] > p.inner_corner[0]))
                r.at("outer_corner").fail(fmt::format("x > {} (further left than inner_corner)", p.inner_corner[0]));
            r.finish();
        }
        {
            JsonReader r = top.object("mouth");
            p.mouth_y = r.number("centre_y");
            p.mouth_half_width = r.number("half_width");
            p.mouth_corner_rise = r.number("corner_rise");
            p.upper_lip_height = r.number("upper_lip_height");
            p.lower_lip_height = r.number("lower_lip_height");
            p.cupid_dip = r.number("cupid_dip");
            p.cupid_peak_x = r.number("cupid_peak_x");
            p.upper_lip_protrusion = r.number("upper_lip_protrusion");
            p.lower_lip_protrusion = r.number("lower_lip_protrusion");
            p.lip_crease_depth = r.number("crease_depth");
            p.lip_crease_width = r.number("crease_width");
            p.lower_lip_tuck = r.number_in("lower_lip_tuck", 0.0, 5.0);
            p.lower_lip_tuck_at = r.number_in("lower_lip_tuck_at", 1.0, 15.0);
            p.mouth_warp_reach = r.number("warp_reach");
            p.outer_corner_offset = r.number("outer_corner_offset");
            for (const char* key : {"half_width", "upper_lip_height", "lower_lip_height"})
                if (!(r.number(key) > 0)) r.at(key).fail("a positive size");
            r.finish();
        }
        {
            JsonReader r = top.object("mouth_interior");
            p.cavity_centre = to_glm(r.numbers<3>("cavity_centre"));
            p.cavity_radii = to_glm(r.numbers<3>("cavity_radii"));
            p.teeth_half_width = r.number("teeth_half_width");
            for (auto [key, crowns] : {std::pair{"upper_crowns", &p.upper_crowns}, std::pair{"lower_crowns", &p.lower_crowns}}) {
                const JsonReader list = r.at(key);
                for (const JsonReader& c : list.elements()) crowns->push_back(to_glm(c.as_numbers<2>()));
                if (crowns->size() < 3) list.fail("at least 3 crowns (incisors and a canine)");
                for (const glm::dvec2& c : *crowns)
                    if (!(c[0] > 1.0 && c[1] > 1.0)) list.fail("crowns of width and height above 1 mm");
            }
            p.teeth_depth = r.number("teeth_depth");
            p.teeth_gap = r.number("teeth_gap");
            p.tongue_centre = to_glm(r.numbers<3>("tongue_centre"));
            p.tongue_radii = to_glm(r.numbers<3>("tongue_radii"));
            r.finish();
        }
        for (JsonReader b : top.objects("bumps")) p.bumps.push_back(read_bump(b));
        for (JsonReader b : top.objects("nostrils")) p.nostrils.push_back(read_bump(b));
        for (JsonReader rr : top.objects("ridges")) {
            Ridge ridge;
            ridge.name = rr.string("name");
            const JsonReader points = rr.at("points");
            for (const JsonReader& pt : points.elements()) ridge.points.push_back(to_glm(pt.as_numbers<2>()));
            if (ridge.points.size() < 2) points.fail("at least 2 points");
            ridge.width = rr.number_list("width");
            ridge.height = rr.number_list("height");
            ridge.mirror = rr.boolean("mirror", false);
            ridge.apex_round = rr.number("apex_round", 0.0);
            if (ridge.apex_round < 0) rr.at("apex_round").fail("a length of 0 mm or more");
            const std::string per_point = fmt::format("{} values (one per point)", ridge.points.size());
            if (ridge.width.size() != ridge.points.size()) rr.at("width").fail(per_point);
            if (ridge.height.size() != ridge.points.size()) rr.at("height").fail(per_point);
            for (double w : ridge.width)
                if (!(w > 0.0)) rr.at("width").fail("positive widths");
            rr.finish();
            p.ridges.push_back(std::move(ridge));
        }
        {
            JsonReader r = top.object("ears");
            p.ear_centre_yz = to_glm(r.numbers<2>("centre_yz"));
            p.ear_radii_yz = to_glm(r.numbers<2>("radii_yz"));
            p.ear_tilt_deg = r.number_in("tilt_deg", -45.0, 45.0);
            p.ear_height = r.number("height");
            r.finish();
        }
        {
            JsonReader r = top.object("asymmetry");
            p.asymmetry_mm = r.number_in("shape_mm", 0.0, 4.0);
            p.asymmetry_albedo = r.number_in("albedo", 0.0, 0.3);
            r.finish();
        }
        {
            JsonReader r = top.object("pivots");
            p.jaw_pivot = to_glm(r.numbers<3>("jaw"));
            p.head_pivot = to_glm(r.numbers<3>("head"));
            r.finish();
        }
        {
            JsonReader r = top.object("texture_box");
            p.texture_box_min = to_glm(r.numbers<2>("min"));
            p.texture_box_max = to_glm(r.numbers<2>("max"));
            r.finish();
        }
        {
            JsonReader fps = top.object("feature_points");
            for (const auto& [id, value] : fps.entries()) {
                const std::size_t n = value.is_array() ? value.raw().size() : 0;
                if (n != 2 && n != 3) value.fail("[x, y] or [x, y, z]");
                p.feature_targets[id] = value.as_number_list();
            }
        }
        {
            JsonReader r = top.object("colours");
            p.skin = colour(r, "skin");
            p.lips = colour(r, "lips");
            p.brows = colour(r, "brows");
            p.hair = colour(r, "hair");
            p.iris = colour(r, "iris");
            p.iris_inner = colour(r, "iris_inner");
            p.sclera = colour(r, "sclera");
            p.lashes = colour(r, "lashes");
            p.mouth = colour(r, "mouth");
            p.teeth = colour(r, "teeth");
            p.tongue = colour(r, "tongue");
            r.finish();
        }
        {
            JsonReader r = top.object("brows");
            p.brow_points = {to_glm(r.numbers<2>("inner")), to_glm(r.numbers<2>("peak")),
                             to_glm(r.numbers<2>("outer"))};
            p.brow_thickness = to_glm(r.numbers<3>("thickness"));
            JsonReader h = r.object("hairs");
            p.brow_hair_spacing = h.number_in("spacing", 0.2, 5.0);
            p.brow_hair_width = h.number_in("width", 0.05, 2.0);
            p.brow_hair_length = to_glm(h.numbers<2>("length"));
            p.brow_medial_angle = h.number_in("medial_angle_deg", 0.0, 120.0);
            p.brow_lateral_angle = h.number_in("lateral_angle_deg", 0.0, 60.0);
            p.brow_hair_bend = h.number_in("bend_mm", 0.0, 5.0);
            p.brow_hair_tone = to_glm(h.numbers<2>("tone"));
            if (!(p.brow_hair_tone[0] > 0.0 && p.brow_hair_tone[0] <= p.brow_hair_tone[1] && p.brow_hair_tone[1] <= 3.0))
                h.at("tone").fail("an increasing pair of factors in (0, 3]");
            h.finish();
            r.finish();
        }
        {
            JsonReader r = top.object("hair");
            p.hairline_y = r.number("hairline_y");
            p.hairline_temple = to_glm(r.numbers<2>("temple"));
            p.sideburn_z = r.number("sideburn_z");
            p.sideburn_bottom_y = r.number("sideburn_bottom_y");
            p.hair_back_bottom_y = r.number("back_bottom_y");
            {
                JsonReader rc = r.object("recession");
                p.hair_recession = {rc.number_in("x", 0.0, 80.0), rc.number_in("rise", 0.0, 40.0),
                                    rc.number_in("width", 1.0, 60.0)};
                rc.finish();
            }
            p.hairline_wander = r.number_in("wander_mm", 0.0, 10.0);
            p.temple_depth = r.number_in("temple_depth", 1.0, 100.0);
            p.hair_crown = to_glm(r.numbers<3>("crown"));
            p.hairline_band = r.number_in("hairline_band", 0.0, 30.0);
            p.hair_strand_width = r.number_in("strand_width", 0.05, 5.0);
            p.hair_strand_length = r.number_in("strand_length", 0.5, 100.0);
            p.hair_tip_lightening = r.number_in("tip_lightening", 0.0, 1.0);
            p.hair_swirl = r.number_in("swirl_deg", -180.0, 180.0) * 3.14159265358979323846 / 180.0;
            p.hair_tuft_shade = r.number_in("tuft_shade", 0.0, 0.9);
            {
                JsonReader f = r.object("forelock");
                p.hair_forelock.locks = f.integer_in("locks", 0, 40);
                p.hair_forelock.strands = f.integer_in("strands", 1, 12);
                p.hair_forelock.length = to_glm(f.numbers<2>("length_mm"));
                if (!(p.hair_forelock.length[0] > 0.0 && p.hair_forelock.length[1] >= p.hair_forelock.length[0]))
                    f.at("length_mm").fail("shortest > 0 and longest >= shortest (mm)");
                p.hair_forelock.width = f.number_in("width_mm", 0.05, 2.0);
                f.finish();
            }
            r.finish();
        }
        {
            JsonReader r = top.object("albedo");
            auto& a = p.albedo;
            a.pigment_variation = r.number_in("pigment_variation", 0.0, 0.5);
            a.mottling = r.number_in("mottling", 0.0, 2.0);
            for (JsonReader& f : r.objects("flush")) a.flush.push_back(read_patch(f, 0.0, 1.5));
            for (JsonReader& t : r.objects("tones")) {
                FaceParams::Tone tone;
                tone.centre = to_glm(t.numbers<2>("centre"));
                tone.size = to_glm(t.numbers<2>("size"));
                if (!(tone.size[0] > 0 && tone.size[1] > 0)) t.at("size").fail("two widths > 0 (mm)");
                tone.tint = to_glm(t.numbers<3>("tint"));
                for (int c = 0; c < 3; ++c)
                    if (tone.tint[c] < 0.0 || tone.tint[c] > 1.5) t.at("tint").fail("three factors in [0, 1.5]");
                tone.amount = t.number_in("amount", 0.0, 1.0);
                t.finish();
                a.tones.push_back(tone);
            }
            {
                JsonReader b = r.object("blotches");
                a.blotch_size = b.number_in("size_mm", 1.0, 50.0);
                a.blotch_strength = b.number_in("strength", 0.0, 1.0);
                b.finish();
            }
            a.flush_breakup = r.number_in("flush_breakup", 0.0, 1.0);
            a.ear_flush = r.number_in("ear_flush", 0.0, 1.5);
            a.ear_fold_shade = r.number_in("ear_fold_shade", 0.0, 0.8);
            {
                JsonReader f = r.object("freckles");
                a.freckle_spacing = f.number_in("spacing_mm", 0.5, 100.0);
                a.freckle_size = f.number_in("size_mm", 0.05, 10.0);
                a.freckle_strength = f.number_in("strength", 0.0, 1.0);
                f.finish();
            }
            {
                JsonReader g = r.object("pores");
                auto& pores = a.pores;
                pores.spacing = g.number_in("spacing_mm", 0.2, 5.0);
                pores.size = g.number_in("size_mm", 0.05, 2.0);
                if (pores.size > pores.spacing) g.at("size_mm").fail("at most spacing_mm (mm)");
                pores.strength = g.number_in("strength", 0.0, 0.5);
                pores.base = g.number_in("base", 0.0, 1.0);
                for (JsonReader& f : g.objects("regions")) pores.regions.push_back(read_patch(f, -1.0, 1.0));
                JsonReader grain = g.object("grain");
                pores.grain_size = grain.number_in("size_mm", 0.1, 5.0);
                pores.grain_strength = grain.number_in("strength", 0.0, 0.3);
                grain.finish();
                g.finish();
            }
            for (auto [key, spots] : {std::pair{"blemishes", &a.blemishes}, std::pair{"moles", &a.moles}}) {
                JsonReader g = r.object(key);
                spots->spacing = g.number_in("spacing_mm", 0.5, 200.0);
                spots->chance = g.number_in("chance", 0.0, 1.0);
                spots->size = g.number_in("size_mm", 0.05, 10.0);
                spots->strength = g.number_in("strength", 0.0, 1.0);
                g.finish();
            }
            auto tint = [](JsonReader t, glm::dvec3* colour, double* amount) {
                *colour = to_glm(t.numbers<3>("tint"));
                for (int c = 0; c < 3; ++c)
                    if ((*colour)[c] < 0.0 || (*colour)[c] > 1.5) t.at("tint").fail("three factors in [0, 1.5]");
                *amount = t.number_in("amount", 0.0, 1.0);
                t.finish();
            };
            tint(r.object("beard"), &a.beard_tint, &a.beard_amount);
            tint(r.object("forehead"), &a.forehead_tint, &a.forehead_amount);
            tint(r.object("periorbital"), &a.periorbital_tint, &a.periorbital_amount);
            a.lip_border_mm = r.number_in("lip_border_mm", 0.05, 5.0);
            a.lip_lines = r.number_in("lip_lines", 0.0, 1.0);
            a.lip_sheen_breakup = r.number_in("lip_sheen_breakup", 0.0, 1.0);
            a.lid_margin = colour(r, "lid_margin");
            {
                JsonReader h = r.object("hairline");
                a.fine_hairs.spacing = to_glm(h.numbers<2>("spacing_mm"));
                a.fine_hairs.length = to_glm(h.numbers<2>("length_mm"));
                if (!(a.fine_hairs.spacing[0] > 0.05 && a.fine_hairs.spacing[1] > 0.05))
                    h.at("spacing_mm").fail("two spacings > 0.05 (mm)");
                if (!(a.fine_hairs.length[0] > 0.1 && a.fine_hairs.length[1] >= a.fine_hairs.length[0] &&
                      a.fine_hairs.length[1] < 30.0))
                    h.at("length_mm").fail("shortest > 0.1 and <= longest < 30 (mm)");
                a.fine_hairs.width = h.number_in("width_mm", 0.02, 1.0);
                tint(h.object("roots"), &a.fine_hairs.roots_tint, &a.fine_hairs.roots_amount);
                h.finish();
            }
            {
                JsonReader g = r.object("roughness");
                p.gloss.t_zone = g.number_in("t_zone", 0.3, 1.0);
                p.gloss.lips = g.number_in("lips", 0.3, 1.0);
                p.gloss.lid_margin = g.number_in("lid_margin", 0.3, 1.0);
                p.gloss.tear_line = g.number_in("tear_line", 0.3, 1.0);
                g.finish();
            }
            r.finish();
        }
        {
            JsonReader r = top.object("shirt");
            auto& s = p.shirt;
            s.colour = colour(r, "colour");
            JsonReader n = r.object("neckline_y");
            s.neckline_front = n.number_in("front", -300.0, -100.0);
            s.neckline_side = n.number_in("side", -300.0, -100.0);
            s.neckline_back = n.number_in("back", -300.0, -100.0);
            n.finish();
            s.dip_half_angle_deg = r.number_in("dip_half_angle_deg", 5.0, 90.0);
            s.collar_mm = r.number_in("collar_mm", 0.0, 40.0);
            s.collar_shade = r.number_in("collar_shade", 0.7, 1.3);
            s.rib_mm = r.number_in("rib_mm", 0.5, 10.0);
            s.rib_contrast = r.number_in("rib_contrast", 0.0, 0.2);
            s.seam_shade = r.number_in("seam_shade", 0.0, 0.5);
            s.collar_roll = r.number_in("collar_roll", 0.0, 0.5);
            s.edge_mm = r.number_in("edge_mm", 0.1, 5.0);
            s.thickness_mm = to_glm(r.numbers<2>("thickness_mm"));
            if (!(s.thickness_mm[0] >= 0.0 && s.thickness_mm[0] <= 6.0 && s.thickness_mm[1] >= 0.0 &&
                  s.thickness_mm[1] <= s.thickness_mm[0]))
                r.at("thickness_mm").fail("[collar, body] in 0..6 mm, the body no thicker than the collar");
            s.weave_mm = r.number_in("weave_mm", 0.3, 5.0);
            s.weave = r.number_in("weave", 0.0, 0.2);
            s.folds = r.number_in("folds", 0.0, 0.3);
            s.fold_count = r.number_in("fold_count", 0.0, 20.0);
            s.mottling = r.number_in("mottling", 0.0, 0.2);
            s.neck_shade_mm = r.number_in("neck_shade_mm", 0.0, 20.0);
            s.neck_shade = r.number_in("neck_shade", 0.0, 0.8);
            r.finish();
        }
    });
    return p;
}

}  // namespace emoface::expression::detail
