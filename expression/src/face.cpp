#include "emoface/expression/face.h"

#include <algorithm>
#include <cmath>

#include "emoface/common/error.h"
#include "emoface/fap/feature_points.h"

namespace emoface::expression {

const char* part_name(VertexPart part) {
    switch (part) {
        case VertexPart::Skin: return "skin";
        case VertexPart::EyeballLeft: return "eyeball_left";
        case VertexPart::EyeballRight: return "eyeball_right";
        case VertexPart::MouthUpper: return "mouth_upper";
        case VertexPart::MouthLower: return "mouth_lower";
        case VertexPart::Tongue: return "tongue";
    }
    return "?";
}

const Vec3d& Face::position(int feature_point) const {
    const FeaturePointLocation& fp = feature_points.at(feature_point);
    if (!fp.present)
        fail("expression: face \"{}\" has no feature point {}", name,
             std::string(fap::feature_points()[feature_point].id));
    return fp.position;
}

fap::FeaturePointPositions Face::positions() const {
    fap::FeaturePointPositions out{};
    for (int k = 0; k < fap::kFeaturePointCount; ++k)
        if (feature_points[k].present) out[k] = feature_points[k].position;
    return out;
}

void update_fapu(Face& face, const std::string& source) {
    const std::string subject = source.empty() ? "face \"" + face.name + "\"" : source;
    std::string missing;
    for (const char* id : {"3.1", "3.3", "3.5", "3.6", "9.15", "2.2", "8.3", "8.4"}) {
        if (!face.has(fap::feature_point_index(id))) missing += missing.empty() ? id : std::string(", ") + id;
    }
    if (!missing.empty())
        fail<InputError>("expression: {}: cannot compute FAPU without feature points {}", subject, missing);
    try {
        face.fapu = fap::compute_fapu(face.positions());
    } catch (const InputError& e) {
        fail<InputError>("expression: {}: {} (x must point to the face's left, y up, z to the viewer)", subject,
                         e.what());
    }
}

void validate_face(const Face& face, const std::string& context) {
    const int n = face.vertex_count();
    if (n == 0 || face.mesh.n_faces() == 0) fail<InputError>("expression: {}: the mesh has no triangles", context);
    if (static_cast<int>(face.parts.size()) != n)
        fail<InputError>("expression: {}: {} vertex parts for {} vertices", context, face.parts.size(), n);
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const FeaturePointLocation& fp = face.feature_points[k];
        if (!fp.present) continue;
        const auto id = fap::feature_points()[k].id;
        if (fp.vertex >= n)
            fail<InputError>("expression: {}: feature point {} names vertex {}, the mesh has {}", context,
                             std::string(id), fp.vertex, n);
        for (double c : fp.position)
            if (!std::isfinite(c))
                fail<InputError>("expression: {}: feature point {} has a position that is not finite", context,
                                 std::string(id));
    }
    for (const Eyeball& e : face.eyeballs) {
        if (e.vertices.first < 0 || e.vertices.count <= 0 || e.vertices.end() > n)
            fail<InputError>("expression: {}: eyeball vertices [{}, {}) outside the mesh's {} vertices", context,
                             e.vertices.first, e.vertices.end(), n);
        if (!(e.radius > 0))
            fail<InputError>("expression: {}: eyeball radius must be positive, found {}", context, e.radius);
        for (const auto* margin : {&e.upper_margin, &e.lower_margin})
            for (int v : *margin)
                if (v < 0 || v >= n)
                    fail<InputError>("expression: {}: eyelid margin vertex {} outside the mesh's {} vertices", context,
                                     v, n);
        if (e.upper_margin.size() != e.lower_margin.size())
            fail<InputError>("expression: {}: eyelid margins have {} upper and {} lower vertices", context,
                             e.upper_margin.size(), e.lower_margin.size());
    }
    for (const auto& w : face.welded)
        if (w[0] < 0 || w[0] >= n || w[1] < 0 || w[1] >= n)
            fail<InputError>("expression: {}: welded pair ({}, {}) outside the mesh's {} vertices", context, w[0], w[1], n);
    if (face.eyeballs.size() > 2)
        fail<InputError>("expression: {}: at most 2 eyeballs, found {}", context, face.eyeballs.size());
    if (!face.base_colour.empty() &&
        face.base_colour.rgba.size() != static_cast<std::size_t>(face.base_colour.width) * face.base_colour.height * 4)
        fail<InputError>("expression: {}: base colour image size does not match its pixels", context);
}

void estimate_pivots(Face& face) {
    auto has = [&](const char* id) { return face.has(fap::feature_point_index(id)); };
    auto at = [&](const char* id) { return face.position(fap::feature_point_index(id)); };
    for (const char* id : {"3.5", "3.6", "9.15"})
        if (!has(id)) fail<InputError>("expression: face \"{}\": cannot place the jaw pivot without feature point {}", face.name, id);
    const Vec3d l = at("3.5"), r = at("3.6"), nose = at("9.15");
    const double es0 = std::abs(l[0] - r[0]);
    double back_z = 0.5 * (l[2] + r[2]);
    if (has("3.7") && has("3.12")) back_z = 0.5 * (at("3.7")[2] + at("3.12")[2]);
    const double eye_y = 0.5 * (l[1] + r[1]);
    face.jaw_pivot = {0.5 * (l[0] + r[0]), nose[1] + 0.35 * (eye_y - nose[1]), back_z - 0.8 * es0};
    const int spine = fap::feature_point_index("7.1");
    if (face.has(spine)) {
        face.head_pivot = face.position(spine);
    } else {
        const double chin_y = has("2.1") ? at("2.1")[1] : nose[1] - 1.2 * (eye_y - nose[1]);
        face.head_pivot = {face.jaw_pivot[0], chin_y + 0.23 * (eye_y - chin_y), face.jaw_pivot[2] - 0.4 * es0};
    }
}

TextureBox frontal_box(const Face& face) {
    double x0 = 1e30, y0 = 1e30, x1 = -1e30, y1 = -1e30;
    for (int v = 0; v < face.vertex_count(); ++v) {
        if (!face.parts.empty() && face.parts[v] != VertexPart::Skin) continue;
        const auto p = face.mesh.point(TriMesh::VertexHandle(v));
        x0 = std::min<double>(x0, p[0]);
        x1 = std::max<double>(x1, p[0]);
        y0 = std::min<double>(y0, p[1]);
        y1 = std::max<double>(y1, p[1]);
    }
    if (x0 > x1) return {};
    const double mx = 0.05 * (x1 - x0), my = 0.05 * (y1 - y0);
    TextureBox box;
    box.min = {static_cast<float>(x0 - mx), static_cast<float>(y0 - my)};
    box.max = {static_cast<float>(x1 + mx), static_cast<float>(y1 + my)};
    return box;
}

std::vector<std::string> missing_feature_points(const Face& face) {
    std::vector<std::string> out;
    for (int k = 0; k < fap::kFeaturePointCount; ++k)
        if (!face.feature_points[k].present) out.emplace_back(fap::feature_points()[k].id);
    return out;
}

}  // namespace emoface::expression
