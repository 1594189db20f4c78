#pragma once
// Places text labels next to the points they name without overlapping one
// another, covering another point's dot, or leaving the image: the feature
// points of inspect crowd around the eyes and lips, where "3.12" beside each
// dot would print labels over labels. Each label takes the nearest free
// place around its point; one that sits away from its point gets a leader
// line (drawn by the caller). Pure geometry, so it is tested on its own.
#include <optional>
#include <vector>

#include <opencv2/core/types.hpp>

namespace emoface::apps {

struct LabelRequest {
    cv::Point2f point;  // what the label names, in pixels
    cv::Size size;      // the label's box (text extent + outline)
};

struct PlacedLabel {
    cv::Rect box;     // inside the image, overlapping no other placed box
    bool leader;      // away from its point: draw a line from the point to the box
};

// One result per request; nullopt where no free place is left (a picture
// too small for all its labels: they are left out, never stacked).
// `dot_radius`: the dots (every request's point) that boxes keep clear of.
std::vector<std::optional<PlacedLabel>> place_labels(const std::vector<LabelRequest>& requests,
                                                     cv::Size image, float dot_radius = 3.0f);

}  // namespace emoface::apps
