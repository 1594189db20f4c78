#pragma once
// The 84 MPEG-4 feature points (groups 2..11) with their matching vertex of
// the public Candide-3 face model (Ahlberg 2001). Left/right are the face's
// own sides, as in fap_table.h.
#include <array>
#include <optional>
#include <string_view>

namespace emoface::fap {

inline constexpr int kFeaturePointCount = 84;

struct FeaturePointInfo {
    std::string_view id;  // "2.1"
    int group;            // 2..11
    int index;            // 1-based within the group
    std::string_view description;
    // The Candide-3 vertex at this point, -1 when Candide-3 has none.
    int candide3_vertex;
    // Some points are the mean of several Candide-3 vertices (pupil centres
    // 3.5/3.6: four iris vertices; 11.1: two). The first entry equals
    // candide3_vertex; unused entries are -1.
    std::array<int, 4> candide3_vertices;
    // False where the description could not be checked against the standard
    // text (tongue, teeth and some ear points).
    bool description_verified;
};

// In group order: 2.1..2.14, 3.1..3.14, 4.1..4.6, 5.1..5.4, 6.1..6.4, 7.1,
// 8.1..8.10, 9.1..9.15, 10.1..10.10, 11.1..11.6.
const std::array<FeaturePointInfo, kFeaturePointCount>& feature_points();

// Position of an id such as "3.5" in feature_points(); throws
// emoface::InputError naming the id when there is no such point.
int feature_point_index(std::string_view id);

std::optional<int> find_feature_point(std::string_view id);

}  // namespace emoface::fap
