#include "sheet.h"

#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "emoface/common/error.h"
#include "emoface/fap/feature_points.h"
#include "emoface/render/image_io.h"
#include "label_placement.h"

namespace emoface::apps {

cv::Mat to_bgr(const render::ImageRGBA8& image) {
    const cv::Mat rgba(image.height, image.width, CV_8UC4, const_cast<std::uint8_t*>(image.pixels.data()));
    cv::Mat bgr;
    cv::cvtColor(rgba, bgr, cv::COLOR_RGBA2BGR);
    return bgr;
}

render::ImageRGBA8 to_rgba(const cv::Mat& bgr) {
    render::ImageRGBA8 out(bgr.cols, bgr.rows);
    cv::Mat rgba(bgr.rows, bgr.cols, CV_8UC4, out.pixels.data());
    cv::cvtColor(bgr, rgba, cv::COLOR_BGR2RGBA);
    return out;
}

void write_bgr(const std::string& path, const cv::Mat& bgr) { render::write_image(path, to_rgba(bgr)); }

cv::Mat shade_normal_map(const render::ImageRGBA8& map) {
    cv::Mat out(map.height, map.width, CV_8UC3);
    // Light from the upper left, low over the skin (image y runs down, as the
    // map's n.y does), so grooves show a dark and a bright flank.
    const float lx = -0.45f, ly = -0.45f, lz = 0.77f;
    const float flat = lz;  // n = (0, 0, 1)
    for (int y = 0; y < map.height; ++y) {
        auto* row = out.ptr<cv::Vec3b>(y);
        for (int x = 0; x < map.width; ++x) {
            const std::uint8_t* p = map.at(x, y);
            float nx = p[0] / 127.5f - 1.0f, ny = p[1] / 127.5f - 1.0f, nz = p[2] / 127.5f - 1.0f;
            const float len = std::sqrt(nx * nx + ny * ny + nz * nz);
            if (len > 1e-6f) nx /= len, ny /= len, nz /= len;
            const float d = std::max(0.0f, nx * lx + ny * ly + nz * lz);
            // Flat skin maps to 150; the contrast is stretched so shallow
            // wrinkles show at thumbnail size.
            const float v = std::clamp(150.0f + (d - flat) * 600.0f, 0.0f, 255.0f);
            const auto g = static_cast<std::uint8_t>(std::lround(v));
            row[x] = cv::Vec3b(g, g, g);
        }
    }
    return out;
}

cv::Mat raw_normal_map(const render::ImageRGBA8& map) { return to_bgr(map); }

void put_label(cv::Mat& image, const std::string& text, cv::Point origin, double scale, cv::Scalar colour,
               int thickness) {
    cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(0, 0, 0), thickness + 2,
                cv::LINE_AA);
    cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, scale, colour, thickness, cv::LINE_AA);
}

cv::Mat contact_sheet(const std::string& title, const std::vector<SheetRow>& rows) {
    if (rows.empty() || rows[0].tiles.empty()) fail<Error>("apps: contact_sheet: no tiles");
    const cv::Size tile = rows[0].tiles[0].size();
    std::size_t columns = 0;
    for (const auto& r : rows) {
        columns = std::max(columns, r.tiles.size());
        for (const auto& t : r.tiles)
            if (t.size() != tile || t.type() != CV_8UC3)
                fail<Error>("apps: contact_sheet: tiles must all be {}x{} BGR", tile.width, tile.height);
    }
    const double scale = std::clamp(tile.width / 320.0, 0.4, 0.8);
    int baseline = 0;
    const int text_h = cv::getTextSize("Ag", cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).height + baseline;
    int label_w = 0;
    for (const auto& r : rows)
        if (!r.label.empty())
            label_w = std::max(label_w,
                               cv::getTextSize(r.label, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width + 16);
    const int gap = 6, caption_h = text_h + 8, title_h = title.empty() ? gap : text_h * 2 + 8;
    const int width = label_w + int(columns) * (tile.width + gap) + gap;
    const int height = title_h + int(rows.size()) * (tile.height + caption_h + gap);
    cv::Mat sheet(height, width, CV_8UC3, cv::Scalar(38, 34, 32));
    if (!title.empty()) put_label(sheet, title, cv::Point(gap + 2, text_h + 6), scale * 1.2);
    for (std::size_t r = 0; r < rows.size(); ++r) {
        const int y0 = title_h + int(r) * (tile.height + caption_h + gap);
        if (!rows[r].label.empty())
            put_label(sheet, rows[r].label, cv::Point(gap, y0 + tile.height / 2 + text_h / 2), scale);
        for (std::size_t c = 0; c < rows[r].tiles.size(); ++c) {
            const int x0 = label_w + gap + int(c) * (tile.width + gap);
            rows[r].tiles[c].copyTo(sheet(cv::Rect(x0, y0, tile.width, tile.height)));
            if (c < rows[r].captions.size()) {
                const std::string& cap = rows[r].captions[c];
                const int w = cv::getTextSize(cap, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline).width;
                put_label(sheet, cap, cv::Point(x0 + std::max(0, (tile.width - w) / 2), y0 + tile.height + text_h + 2),
                          scale, cv::Scalar(230, 230, 230));
            }
        }
    }
    return sheet;
}

namespace {

// One colour per feature-point group (2..11), BGR.
cv::Scalar group_colour(int group) {
    static const cv::Scalar colours[] = {
        {80, 220, 255},   // 2 chin, lips inner, jaw
        {255, 200, 60},   // 3 eyes
        {60, 255, 120},   // 4 brows
        {255, 120, 255},  // 5 cheeks
        {200, 200, 200},  // 6 tongue
        {180, 180, 180},  // 7 spine
        {60, 90, 255},    // 8 outer lips
        {255, 255, 120},  // 9 nose
        {120, 180, 255},  // 10 ears, face outline
        {160, 255, 255},  // 11 hairline, head top
    };
    return colours[std::clamp(group - 2, 0, 9)];
}

}  // namespace

void draw_feature_overlay(cv::Mat& image, const std::array<std::optional<glm::vec2>, expression::kFeatureCount>& points,
                          const std::vector<expression::FeatureLine>& lines, bool labels) {
    const auto& table = fap::feature_points();
    constexpr int kShift = 4;  // sub-pixel line positions
    auto fixed = [](const glm::vec2& p) { return cv::Point(int(std::lround(p.x * 16)), int(std::lround(p.y * 16))); };
    for (const auto& l : lines) {
        const auto& a = points[std::size_t(l.from)];
        const auto& b = points[std::size_t(l.to)];
        if (!a || !b) continue;
        cv::line(image, fixed(*a), fixed(*b), cv::Scalar(40, 230, 255), 1, cv::LINE_AA, kShift);
    }
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!points[i]) continue;
        cv::circle(image, fixed(*points[i]), 3 << kShift, cv::Scalar(0, 0, 0), -1, cv::LINE_AA, kShift);
        cv::circle(image, fixed(*points[i]), 2 << kShift, group_colour(table[i].group), -1, cv::LINE_AA, kShift);
    }
    if (!labels) return;
    const std::vector<FeatureLabel> placed = feature_labels(points, image.size());
    // Leader lines first, every label over them: a line may pass under a
    // label, never through its text.
    for (const FeatureLabel& l : placed) {
        const cv::Scalar colour = group_colour(table[std::size_t(l.point)].group);
        if (l.leader) {
            // From the dot's edge to the box's nearest point, dark under
            // light so it reads on skin and on the map alike.
            const cv::Point2f p(points[std::size_t(l.point)]->x, points[std::size_t(l.point)]->y);
            const cv::Point2f q(std::clamp(p.x, float(l.box.x), float(l.box.x + l.box.width - 1)),
                                std::clamp(p.y, float(l.box.y), float(l.box.y + l.box.height - 1)));
            const cv::Point2f d = q - p;
            const float len = std::hypot(d.x, d.y);
            const cv::Point2f from = len > 0 ? p + d * (3.0f / len) : p;
            auto fx = [](cv::Point2f v) { return cv::Point(int(std::lround(v.x * 16)), int(std::lround(v.y * 16))); };
            cv::line(image, fx(from), fx(q), cv::Scalar(0, 0, 0), 2, cv::LINE_AA, kShift);
            cv::line(image, fx(from), fx(q), colour, 1, cv::LINE_AA, kShift);
        }
    }
    for (const FeatureLabel& l : placed) {
        const cv::Scalar colour = group_colour(table[std::size_t(l.point)].group);
        put_label(image, l.text, cv::Point(l.box.x + 1, l.box.y + l.box.height - l.baseline - 1), l.scale, colour);
    }
}

std::vector<FeatureLabel> feature_labels(const std::array<std::optional<glm::vec2>, expression::kFeatureCount>& points, cv::Size image) {
    const auto& table = fap::feature_points();
    // Small enough that 84 of them fit a 480-pixel picture, large enough to read.
    const double scale = std::clamp(image.height / 1450.0, 0.3, 0.5);
    std::vector<LabelRequest> requests;
    std::vector<FeatureLabel> labels;
    for (std::size_t i = 0; i < points.size(); ++i) {
        if (!points[i]) continue;
        FeatureLabel l;
        l.point = int(i);
        l.text = std::string(table[i].id);
        l.scale = scale;
        const cv::Size text = cv::getTextSize(l.text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &l.baseline);
        // put_label's outline is 3 pixels thick: one more pixel on each side.
        requests.push_back({cv::Point2f(points[i]->x, points[i]->y),
                            cv::Size(text.width + 2, text.height + l.baseline + 2)});
        labels.push_back(l);
    }
    const auto placed = place_labels(requests, image);
    std::vector<FeatureLabel> out;
    for (std::size_t k = 0; k < labels.size(); ++k) {
        if (!placed[k]) continue;
        labels[k].box = placed[k]->box;
        labels[k].leader = placed[k]->leader;
        out.push_back(labels[k]);
    }
    return out;
}

std::array<std::optional<glm::vec2>, expression::kFeatureCount> layout_pixels(const expression::FeatureLayout& layout, int width,
                                                       int height) {
    std::array<std::optional<glm::vec2>, expression::kFeatureCount> out{};
    for (std::size_t i = 0; i < out.size(); ++i)
        if (layout.present[i]) out[i] = glm::vec2(layout.points[i].x * width, layout.points[i].y * height);
    return out;
}

}  // namespace emoface::apps
