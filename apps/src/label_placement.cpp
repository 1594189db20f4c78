#include "label_placement.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "emoface/common/constants.h"

namespace emoface::apps {

namespace {

// Points nearer than this are one cluster: their labels compete for room,
// so they are placed first and pushed away from the cluster's middle.
constexpr float kCrowdRadius = 40.0f;
// How far from its point a label may go, in rings (pixels from the dot to the
// box's nearest side), and how many directions each ring tries.
constexpr float kRings[] = {2, 5, 9, 14, 20, 28, 38, 50, 64, 80, 100, 125, 155, 190, 230};
constexpr int kDirections = 16;
// A leaderless label sits within this of its dot; farther needs a line.
constexpr float kLeaderDistance = 6.0f;

bool overlaps(const cv::Rect& a, const cv::Rect& b) { return (a & b).area() > 0; }

// Whether segments ab and cd cross (touching ends do not count).
bool crosses(cv::Point2f a, cv::Point2f b, cv::Point2f c, cv::Point2f d) {
    auto side = [](cv::Point2f o, cv::Point2f p, cv::Point2f q) { return (p - o).cross(q - o); };
    const float d1 = side(c, d, a), d2 = side(c, d, b), d3 = side(a, b, c), d4 = side(a, b, d);
    return ((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0));
}

// The point of `r` nearest to `p` (where a leader line meets the box).
cv::Point2f nearest_on(const cv::Rect& r, cv::Point2f p) {
    return {std::clamp(p.x, float(r.x), float(r.x + r.width - 1)), std::clamp(p.y, float(r.y), float(r.y + r.height - 1))};
}

// Distance from `p` to the nearest point of `r` (0 inside).
float distance_to(const cv::Rect& r, cv::Point2f p) {
    const float dx = std::max({float(r.x) - p.x, 0.0f, p.x - float(r.x + r.width)});
    const float dy = std::max({float(r.y) - p.y, 0.0f, p.y - float(r.y + r.height)});
    return std::hypot(dx, dy);
}

}  // namespace

std::vector<std::optional<PlacedLabel>> place_labels(const std::vector<LabelRequest>& requests,
                                                     cv::Size image, float dot_radius) {
    const std::size_t n = requests.size();
    std::vector<std::optional<PlacedLabel>> out(n);
    const cv::Rect frame(0, 0, image.width, image.height);

    // Every dot is an obstacle (a label must not hide another point).
    std::vector<cv::Rect> dots(n);
    const int r = int(std::ceil(dot_radius));
    for (std::size_t i = 0; i < n; ++i)
        dots[i] = cv::Rect(int(std::floor(requests[i].point.x)) - r, int(std::floor(requests[i].point.y)) - r,
                           2 * r + 1, 2 * r + 1);

    // Crowding and the way out of the crowd (away from the neighbours' mean).
    std::vector<int> crowd(n, 0);
    std::vector<cv::Point2f> away(n, cv::Point2f(0.7071f, -0.7071f));  // alone: upper right, as text reads
    for (std::size_t i = 0; i < n; ++i) {
        cv::Point2f sum(0, 0);
        for (std::size_t j = 0; j < n; ++j) {
            if (j == i) continue;
            const cv::Point2f d = requests[i].point - requests[j].point;
            if (std::hypot(d.x, d.y) < kCrowdRadius) sum += requests[j].point, ++crowd[i];
        }
        if (crowd[i] > 0) {
            const cv::Point2f d = requests[i].point - sum * (1.0f / float(crowd[i]));
            const float len = std::hypot(d.x, d.y);
            if (len > 1e-3f) away[i] = d * (1.0f / len);
        }
    }
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return crowd[a] > crowd[b]; });

    std::vector<cv::Rect> placed;
    placed.reserve(n);
    std::vector<std::pair<cv::Point2f, cv::Point2f>> leaders;
    auto free_box = [&](const cv::Rect& box) {
        if ((box & frame) != box) return false;
        // One pixel of air between labels keeps their outlines apart.
        const cv::Rect padded(box.x - 1, box.y - 1, box.width + 2, box.height + 2);
        for (const cv::Rect& p : placed)
            if (overlaps(padded, p)) return false;
        for (const cv::Rect& d : dots)
            if (overlaps(box, d)) return false;
        return true;
    };

    for (const std::size_t i : order) {
        const cv::Point2f p = requests[i].point;
        const cv::Size size = requests[i].size;
        if (size.width <= 0 || size.height <= 0 || size.width > image.width || size.height > image.height) continue;
        float best_cost = std::numeric_limits<float>::max();
        cv::Rect best;
        constexpr std::size_t kRingCount = sizeof(kRings) / sizeof(kRings[0]);
        for (std::size_t ri = 0; ri < kRingCount; ++ri) {
            const float ring = kRings[ri];
            for (int k = 0; k < kDirections; ++k) {
                const float angle = float(2.0 * kPi) * float(k) / float(kDirections);
                const cv::Point2f dir(std::cos(angle), std::sin(angle));
                // The box's centre, so that its side facing the dot is `ring`
                // beyond the dot's edge in this direction.
                const float reach = dot_radius + ring + std::abs(dir.x) * size.width * 0.5f +
                                    std::abs(dir.y) * size.height * 0.5f;
                const cv::Point2f c = p + dir * reach;
                const cv::Rect box(int(std::lround(c.x - size.width * 0.5f)),
                                   int(std::lround(c.y - size.height * 0.5f)), size.width, size.height);
                if (!free_box(box)) continue;
                // Near first; out of the crowd rather than into it; a leader
                // line that crosses another label or leader costs as much
                // as a long one.
                float cost = ring + 6.0f * (1.0f - dir.dot(away[i]));
                if (ring > kLeaderDistance) {
                    const cv::Point2f end = nearest_on(box, p);
                    for (const cv::Rect& other : placed) {
                        cv::Point a(p), b(end);
                        if (cv::clipLine(other, a, b)) cost += 60.0f;
                    }
                    for (const auto& [a, b] : leaders)
                        if (crosses(p, end, a, b)) cost += 40.0f;
                }
                if (cost < best_cost) best_cost = cost, best = box;
            }
            // Every place on a later ring costs at least that ring.
            if (ri + 1 < kRingCount && best_cost <= kRings[ri + 1]) break;
        }
        if (best_cost == std::numeric_limits<float>::max()) {
            // Every ring is full: the nearest free place anywhere.
            float best_distance = std::numeric_limits<float>::max();
            for (int y = 0; y + size.height <= image.height; y += 2)
                for (int x = 0; x + size.width <= image.width; x += 2) {
                    const cv::Rect box(x, y, size.width, size.height);
                    const float d = distance_to(box, p);
                    if (d < best_distance && free_box(box)) best_distance = d, best = box;
                }
            if (best_distance == std::numeric_limits<float>::max()) continue;
        }
        placed.push_back(best);
        const bool leader = distance_to(best, p) > dot_radius + kLeaderDistance;
        if (leader) leaders.emplace_back(p, nearest_on(best, p));
        out[i] = PlacedLabel{best, leader};
    }
    return out;
}

}  // namespace emoface::apps
