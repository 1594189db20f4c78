#pragma once
// Pictures the commands compose with OpenCV: labelled contact sheets (mix
// --sheet, morph), the feature-point overlay (inspect), and a lit view of a
// normal map, in which wrinkles read as relief rather than as blue tints.
// Images are cv::Mat BGR 8-bit (CV_8UC3) here; render::ImageRGBA8 at the edges.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <opencv2/core.hpp>

#include "emoface/expression/feature_layout.h"
#include "emoface/render/image.h"

namespace emoface::apps {

cv::Mat to_bgr(const render::ImageRGBA8& image);
render::ImageRGBA8 to_rgba(const cv::Mat& bgr);
// Writes through render::write_image (temporary name, then rename).
void write_bgr(const std::string& path, const cv::Mat& bgr);

// A tangent-space normal map (RGB = 0.5 + 0.5 n) lit by a grazing light from
// the upper left: flat skin is mid grey, grooves and ridges shade.
cv::Mat shade_normal_map(const render::ImageRGBA8& normal_map);
// The encoded normals as they are (the map's own colours).
cv::Mat raw_normal_map(const render::ImageRGBA8& normal_map);

// Text with a dark outline, readable on any background; `origin` is the
// baseline's left end.
void put_label(cv::Mat& image, const std::string& text, cv::Point origin, double scale = 0.5,
               cv::Scalar colour = cv::Scalar(255, 255, 255), int thickness = 1);

struct SheetRow {
    std::string label;            // drawn left of the row (may be empty)
    std::vector<cv::Mat> tiles;   // all of one size
    std::vector<std::string> captions;  // one per tile, drawn under it
};

// Rows of tiles, a title on top, row labels on the left, captions under
// each tile; every row's tiles must have the size of the first row's.
cv::Mat contact_sheet(const std::string& title, const std::vector<SheetRow>& rows);

// The feature points (dot + label "2.1" ...) and the feature lines between
// them, drawn on `image`; points are in pixels of `image` (nullopt: absent).
// Labels are placed by feature_labels().
void draw_feature_overlay(cv::Mat& image, const std::array<std::optional<glm::vec2>, expression::kFeatureCount>& points,
                          const std::vector<expression::FeatureLine>& lines, bool labels = true);

// Where draw_feature_overlay puts each point's label: boxes inside the image
// that overlap neither one another nor a dot, near their points, with a
// leader line where a crowd (eyes, lips) pushes one away (label_placement.h).
// A point whose label finds no room is left out.
struct FeatureLabel {
    int point = 0;      // feature point index 0..83
    std::string text;   // "3.12"
    cv::Rect box;       // the label's box (text and its outline)
    bool leader = false;
    double scale = 0.4;  // font scale
    int baseline = 0;    // of the text, in pixels
};
std::vector<FeatureLabel> feature_labels(const std::array<std::optional<glm::vec2>, expression::kFeatureCount>& points, cv::Size image);

// A layout's points (normalised, y down) in pixels of a width x height image.
std::array<std::optional<glm::vec2>, expression::kFeatureCount> layout_pixels(const expression::FeatureLayout& layout, int width,
                                                       int height);

}  // namespace emoface::apps
