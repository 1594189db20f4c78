#include "emoface/expression/feature_layout.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vector_relational.hpp>
#include <nlohmann/json.hpp>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/expression/face.h"
#include "json_reader.h"

namespace emoface::expression {

glm::vec2 project_to_texture(const glm::vec3& point, const TextureBox& box) {
    const glm::vec2 size = box.max - box.min;
    return {(point.x - box.min.x) / size.x, (box.max.y - point.y) / size.y};
}

glm::vec2 FeatureLayout::at(const std::string& id) const {
    const int index = fap::feature_point_index(id);
    if (!present[index]) fail("expression: FeatureLayout::at(): layout has no feature point {}", id);
    return points[index];
}

float FeatureLayout::face_unit() const {
    const int left_pupil = fap::feature_point_index("3.5");
    const int right_pupil = fap::feature_point_index("3.6");
    if (present[left_pupil] && present[right_pupil])
        return glm::distance(points[left_pupil], points[right_pupil]);
    const int left_corner = fap::feature_point_index("3.7");
    const int right_corner = fap::feature_point_index("3.12");
    if (present[left_corner] && present[right_corner])
        return 0.7f * glm::distance(points[left_corner], points[right_corner]);
    fail("expression: FeatureLayout::face_unit(): layout has neither pupils (3.5, 3.6) nor outer eye corners (3.7, 3.12)");
}

FeatureLayout projective_layout(const std::array<glm::vec3, kFeatureCount>& positions,
                                const std::bitset<kFeatureCount>& present,
                                const TextureBox& box) {
    FeatureLayout layout;
    layout.present = present;
    for (int i = 0; i < kFeatureCount; ++i)
        if (present[i]) layout.points[i] = project_to_texture(positions[i], box);
    return layout;
}

FeatureLayout projective_layout(const fap::FeaturePointPositions& positions,
                                const std::bitset<kFeatureCount>& present,
                                const TextureBox& box) {
    std::array<glm::vec3, kFeatureCount> points{};
    for (int i = 0; i < kFeatureCount; ++i)
        points[i] = {static_cast<float>(positions[i][0]), static_cast<float>(positions[i][1]),
                     static_cast<float>(positions[i][2])};
    return projective_layout(points, present, box);
}

FeatureLayout anchored_layout(const std::array<glm::vec2, kFeatureCount>& uvs,
                              const std::bitset<kFeatureCount>& present) {
    FeatureLayout layout;
    layout.present = present;
    for (int i = 0; i < kFeatureCount; ++i)
        if (present[i]) layout.points[i] = {uvs[i].x, 1.0f - uvs[i].y};
    return layout;
}

namespace {

// The UV (v up) the skin around `position` gives it: the least-squares affine
// map (x, y) -> (u, v) of the nearest feature points on skin vertices,
// evaluated at position. Feature points, not any skin vertices: those lie on
// the face's UV island by definition, while skin vertices near an off-skin
// point (inside the lids, around the mouth's interior) may be mapped to
// other parts of an atlas.
glm::vec2 skin_uv_at(const Face& face, const Vec3d& position) {
    constexpr std::size_t kNeighbours = 8;
    const glm::dvec3 p(position[0], position[1], position[2]);
    std::vector<std::pair<double, int>> near;
    for (const FeaturePointLocation& fp : face.feature_points) {
        if (!fp.present || fp.vertex < 0 || face.parts[std::size_t(fp.vertex)] != VertexPart::Skin) continue;
        const auto& q = face.mesh.point(TriMesh::VertexHandle(fp.vertex));
        const glm::dvec3 d = glm::dvec3(q[0], q[1], q[2]) - p;
        near.emplace_back(glm::dot(d, d), fp.vertex);
    }
    if (near.empty())
        fail<InputError>("expression: face '{}': no feature point lies on a skin vertex, so the anchored "
                         "layout has no UVs to place the others by",
                         face.name);
    const std::size_t k = std::min(kNeighbours, near.size());
    std::partial_sort(near.begin(), near.begin() + std::ptrdiff_t(k), near.end());
    // Normal equations of [x y 1] * A = [u v], centred on `position` so the
    // answer is the constant term.
    glm::dmat3 ata(0.0);
    glm::dvec3 atu(0.0), atv(0.0);
    glm::dvec2 mean(0.0), lo(1e30), hi(-1e30);
    double mean_weight = 0.0;
    for (std::size_t i = 0; i < k; ++i) {
        const auto vh = TriMesh::VertexHandle(near[i].second);
        const auto& q = face.mesh.point(vh);
        const auto& t = face.mesh.texcoord2D(vh);
        const glm::dvec3 row(q[0] - p.x, q[1] - p.y, 1.0);
        ata += glm::outerProduct(row, row);
        atu += row * double(t[0]);
        atv += row * double(t[1]);
        // The fallback: inverse-distance weighted mean of their UVs.
        const double w = 1.0 / (std::sqrt(near[i].first) + 1e-9);
        mean += w * glm::dvec2(t[0], t[1]);
        mean_weight += w;
        lo = glm::min(lo, glm::dvec2(t[0], t[1]));
        hi = glm::max(hi, glm::dvec2(t[0], t[1]));
    }
    mean /= mean_weight;
    // Neighbours (nearly) on a line in the frontal view fix no affine map:
    // their weighted mean UV. ata's upper 2x2 less the mean's part is k times the
    // covariance of their x, y.
    const double n = double(k);
    const double cxx = ata[0][0] - ata[2][0] * ata[2][0] / n, cyy = ata[1][1] - ata[2][1] * ata[2][1] / n,
                 cxy = ata[1][0] - ata[2][0] * ata[2][1] / n;
    if (k < 3 || !(cxx * cyy - cxy * cxy > 1e-6 * (cxx + cyy) * (cxx + cyy))) return glm::vec2(mean);
    const glm::dmat3 inv = glm::inverse(ata);
    const glm::dvec2 fit((inv * atu).z, (inv * atv).z);
    // Neighbours whose UVs do not follow their positions (a seam, lid
    // margins folded into the socket) make the fit extrapolate wildly: keep
    // it only where it stays near their UVs.
    const glm::dvec2 reach = 0.5 * (hi - lo);
    if (glm::any(glm::lessThan(fit, lo - reach)) || glm::any(glm::greaterThan(fit, hi + reach)))
        return glm::vec2(mean);
    return glm::vec2(fit);
}

}  // namespace

FeatureLayout anchored_layout(const Face& face) {
    if (!face.mesh.has_vertex_texcoords2D() || face.parts.size() != face.mesh.n_vertices())
        fail<InputError>("expression: face '{}' has no UVs of its own for the anchored layout "
                         "(use the projective layout)",
                         face.name);
    std::array<glm::vec2, kFeatureCount> uvs{};
    std::bitset<kFeatureCount> present;
    for (int i = 0; i < kFeatureCount; ++i) {
        const FeaturePointLocation& fp = face.feature_points[std::size_t(i)];
        if (!fp.present) continue;
        present[i] = true;
        if (fp.vertex >= 0 && face.parts[std::size_t(fp.vertex)] == VertexPart::Skin) {
            const auto& t = face.mesh.texcoord2D(TriMesh::VertexHandle(fp.vertex));
            uvs[std::size_t(i)] = {t[0], t[1]};
        } else {
            uvs[std::size_t(i)] = skin_uv_at(face, fp.position);
        }
    }
    FeatureLayout layout = anchored_layout(uvs, present);
    glm::vec2 lo(1e30f), hi(-1e30f);
    for (int i = 0; i < kFeatureCount; ++i)
        if (present[i]) {
            lo = glm::min(lo, layout.points[std::size_t(i)]);
            hi = glm::max(hi, layout.points[std::size_t(i)]);
        }
    if (!(hi.x - lo.x > 1e-4f) || !(hi.y - lo.y > 1e-4f))
        fail<InputError>("expression: face '{}': its feature points' UVs span no area ({}, {})-({}, {}); "
                         "the anchored layout needs the mesh's own UVs (use the projective layout)",
                         face.name, lo.x, lo.y, hi.x, hi.y);
    return layout;
}

std::string layout_to_json(const FeatureLayout& layout) {
    nlohmann::ordered_json doc;
    doc["convention"] = "normalised texture coordinates: x to the image's right (the face's left), y down the image";
    nlohmann::ordered_json points = nlohmann::ordered_json::object();
    for (int i = 0; i < kFeatureCount; ++i)
        if (layout.present[i])
            points[std::string(fap::feature_points()[i].id)] = {layout.points[i].x, layout.points[i].y};
    doc["points"] = points;
    return doc.dump(1) + "\n";
}

FeatureLayout layout_from_json(std::string_view text, const std::string& source) {
    return detail::read_json_text(text, source, [](detail::JsonReader& root) {
        root.comment("convention");
        FeatureLayout layout;
        for (const auto& [id, value] : root.object("points").entries()) {
            const auto index = fap::find_feature_point(id);
            if (!index) value.fail("an MPEG-4 feature point id as the key", "\"" + id + "\"");
            const auto xy = value.as_numbers<2>();
            layout.points[*index] = {static_cast<float>(xy[0]), static_cast<float>(xy[1])};
            layout.present[*index] = true;
        }
        return layout;
    });
}

void save_layout(const FeatureLayout& layout, const std::string& path) {
    write_file_atomically(path, layout_to_json(layout), "expression");
}

FeatureLayout load_layout(const std::string& path) { return layout_from_json(detail::read_text_file(path), path); }

std::vector<FeatureLine> load_feature_lines(const std::string& path) {
    return detail::read_json_file(path, [](detail::JsonReader& root) {
        root.comment("about");
        const detail::JsonReader list = root.at("lines");
        std::vector<FeatureLine> lines;
        for (detail::JsonReader item : list.elements()) {
            item = item.as_object();
            const auto point = [&](const char* key) {
                const detail::JsonReader id = item.at(key);
                const auto index = fap::find_feature_point(id.as_string());
                if (!index) id.fail("an MPEG-4 feature point id");
                return *index;
            };
            FeatureLine line{point("from"), point("to"), item.string("region", "")};
            if (line.from == line.to) item.at("to").fail("a feature point other than \"from\"");
            item.finish();
            lines.push_back(std::move(line));
        }
        if (lines.size() < 40 || lines.size() > 100)
            list.fail("40 to 100 feature lines", std::to_string(lines.size()));
        return lines;
    });
}

std::vector<FeatureLine> lines_for_face(const std::vector<FeatureLine>& lines,
                                        const std::bitset<kFeatureCount>& present) {
    std::vector<FeatureLine> kept;
    for (const FeatureLine& line : lines)
        if (present[line.from] && present[line.to]) kept.push_back(line);
    return kept;
}

std::vector<Segment> layout_segments(const std::vector<FeatureLine>& lines,
                                     const FeatureLayout& layout, float min_length) {
    std::vector<Segment> segments;
    segments.reserve(lines.size());
    for (const FeatureLine& line : lines) {
        Segment s{layout.points[line.from], layout.points[line.to]};
        const float length = glm::distance(s.p, s.q);
        if (!(length >= min_length) || !std::isfinite(length)) s.q = s.p;
        segments.push_back(s);
    }
    return segments;
}

void check_lines_have_length(const std::vector<FeatureLine>& lines, const FeatureLayout& neutral,
                             const std::string& source, float min_length) {
    for (const FeatureLine& line : lines) {
        const float length = glm::distance(neutral.points[line.from], neutral.points[line.to]);
        if (length >= min_length && std::isfinite(length)) continue;
        const std::string from(fap::feature_points()[line.from].id), to(fap::feature_points()[line.to].id);
        fail_data("expression", FileLoc{source.empty() ? "the face" : source, 0, "feature_points"},
                  fmt::format("{} and {} apart (a feature line of the wrinkle morph joins them)", from, to),
                  "them at one place seen from the front");
    }
}

}  // namespace emoface::expression
