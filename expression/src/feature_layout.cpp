#include "emoface/expression/feature_layout.h"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include "emoface/common/error.h"

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
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
        fail<InputError>("expression: {}: not valid JSON ({})", source, e.what());
    }
    if (!doc.is_object() || !doc.contains("points") || !doc["points"].is_object())
        fail<InputError>("expression: {}: expected an object \"points\" mapping feature point ids to [x, y]", source);
    FeatureLayout layout;
    for (const auto& [id, value] : doc["points"].items()) {
        const auto index = fap::find_feature_point(id);
        if (!index) fail<InputError>("expression: {}: unknown feature point \"{}\"", source, id);
        if (!value.is_array() || value.size() != 2 || !value[0].is_number() || !value[1].is_number() ||
            !std::isfinite(value[0].get<double>()) || !std::isfinite(value[1].get<double>()))
            fail<InputError>("expression: {}: feature point {}: expected [x, y] with finite numbers, found {}",
                             source, id, value.dump());
        layout.points[*index] = {value[0].get<float>(), value[1].get<float>()};
        layout.present[*index] = true;
    }
    return layout;
}

void save_layout(const FeatureLayout& layout, const std::string& path) {
    const std::string temporary = path + ".tmp";
    {
        std::ofstream out(temporary, std::ios::binary);
        out << layout_to_json(layout);
        if (!out) fail<InputError>("expression: {}: cannot write the layout", path);
    }
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
        std::remove(temporary.c_str());
        fail<InputError>("expression: {}: cannot write the layout", path);
    }
}

FeatureLayout load_layout(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail<InputError>("expression: {}: cannot open the layout", path);
    std::stringstream text;
    text << in.rdbuf();
    return layout_from_json(text.str(), path);
}

std::vector<FeatureLine> load_feature_lines(const std::string& path) {
    std::ifstream in(path);
    if (!in) fail<InputError>("expression: {}: cannot open the feature-line file", path);
    nlohmann::json doc;
    try {
        doc = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
        fail<InputError>("expression: {}: not valid JSON ({})", path, e.what());
    }
    if (!doc.contains("lines") || !doc["lines"].is_array())
        fail<InputError>("expression: {}: expected an array \"lines\", found none", path);
    std::vector<FeatureLine> lines;
    int entry = 0;
    for (const auto& item : doc["lines"]) {
        ++entry;
        if (!item.is_object() || !item.contains("from") || !item.contains("to") ||
            !item["from"].is_string() || !item["to"].is_string())
            fail<InputError>("expression: {}: line {} must have string fields \"from\" and \"to\", found {}",
                             path, entry, item.dump());
        const auto from = fap::find_feature_point(item["from"].get<std::string>());
        const auto to = fap::find_feature_point(item["to"].get<std::string>());
        if (!from || !to)
            fail<InputError>("expression: {}: line {} names an unknown feature point ({} - {})", path,
                             entry, item["from"].get<std::string>(), item["to"].get<std::string>());
        if (*from == *to)
            fail<InputError>("expression: {}: line {} joins feature point {} to itself", path, entry,
                             item["from"].get<std::string>());
        lines.push_back({*from, *to, item.value("region", std::string{})});
    }
    if (lines.size() < 40 || lines.size() > 100)
        fail<InputError>("expression: {}: expected 40 to 100 feature lines, found {}", path, lines.size());
    return lines;
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

}  // namespace emoface::expression
