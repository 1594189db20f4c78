// The 84 feature points, from shared/mpeg4/feature_points.tsv (descriptions
// and Candide-3 vertices after Ahlberg 2001, Appendix B; left/right of the
// lip midpoints 2.6-2.9 and 8.5-8.8 as the FAPs that move them use them).
#include "emoface/fap/feature_points.h"

#include <charconv>

#include "emoface/common/error.h"
#include "text.h"

namespace emoface::fap {

namespace {

// {id, group, index, description, Candide-3 vertex, all Candide-3 vertices,
//  description verified}
const std::array<FeaturePointInfo, kFeaturePointCount> kFeaturePoints{{
    {"2.1", 2, 1, "Bottom of the chin", 10, {10, -1, -1, -1}, true},
    {"2.2", 2, 2, "Middle point of inner upper lip contour", 87, {87, -1, -1, -1}, true},
    {"2.3", 2, 3, "Middle point of inner lower lip contour", 40, {40, -1, -1, -1}, true},
    {"2.4", 2, 4, "Left corner of inner lip contour", 88, {88, -1, -1, -1}, true},
    {"2.5", 2, 5, "Right corner of inner lip contour", 89, {89, -1, -1, -1}, true},
    {"2.6", 2, 6, "Midpoint between 2.2 and 2.4 (left) on inner upper lip contour", 81, {81, -1, -1, -1}, true},
    {"2.7", 2, 7, "Midpoint between 2.2 and 2.5 (right) on inner upper lip contour", 82, {82, -1, -1, -1}, true},
    {"2.8", 2, 8, "Midpoint between 2.3 and 2.4 (left) on inner lower lip contour", 83, {83, -1, -1, -1}, true},
    {"2.9", 2, 9, "Midpoint between 2.3 and 2.5 (right) on inner lower lip contour", 84, {84, -1, -1, -1}, true},
    {"2.10", 2, 10, "Chin boss", 9, {9, -1, -1, -1}, true},
    {"2.11", 2, 11, "Chin left corner", 32, {32, -1, -1, -1}, true},
    {"2.12", 2, 12, "Chin right corner", 65, {65, -1, -1, -1}, true},
    {"2.13", 2, 13, "Left corner of jaw bone", 30, {30, -1, -1, -1}, true},
    {"2.14", 2, 14, "Right corner of jaw bone", 63, {63, -1, -1, -1}, true},
    {"3.1", 3, 1, "Center of upper inner left eyelid", 21, {21, -1, -1, -1}, true},
    {"3.2", 3, 2, "Center of upper inner right eyelid", 54, {54, -1, -1, -1}, true},
    {"3.3", 3, 3, "Center of lower inner left eyelid", 22, {22, -1, -1, -1}, true},
    {"3.4", 3, 4, "Center of lower inner right eyelid", 55, {55, -1, -1, -1}, true},
    {"3.5", 3, 5, "Center of the pupil of left eye", 67, {67, 68, 71, 72}, true},
    {"3.6", 3, 6, "Center of the pupil of right eye", 69, {69, 70, 73, 74}, true},
    {"3.7", 3, 7, "Outer corner of left eye", 20, {20, -1, -1, -1}, true},
    {"3.8", 3, 8, "Inner corner of right eye", 56, {56, -1, -1, -1}, true},
    {"3.9", 3, 9, "Center of lower outer left eyelid", 24, {24, -1, -1, -1}, true},
    {"3.10", 3, 10, "Center of lower outer right eyelid", 57, {57, -1, -1, -1}, true},
    {"3.11", 3, 11, "Inner corner of left eye", 23, {23, -1, -1, -1}, true},
    {"3.12", 3, 12, "Outer corner of right eye", 53, {53, -1, -1, -1}, true},
    {"3.13", 3, 13, "Center of upper outer left eyelid", 19, {19, -1, -1, -1}, true},
    {"3.14", 3, 14, "Center of upper outer right eyelid", 52, {52, -1, -1, -1}, true},
    {"4.1", 4, 1, "Inner corner of left eyebrow", 17, {17, -1, -1, -1}, true},
    {"4.2", 4, 2, "Inner corner of right eyebrow", 50, {50, -1, -1, -1}, true},
    {"4.3", 4, 3, "Uppermost point of the left eyebrow", 16, {16, -1, -1, -1}, true},
    {"4.4", 4, 4, "Uppermost point of the right eyebrow", 49, {49, -1, -1, -1}, true},
    {"4.5", 4, 5, "Outer corner of left eyebrow", 15, {15, -1, -1, -1}, true},
    {"4.6", 4, 6, "Outer corner of right eyebrow", 48, {48, -1, -1, -1}, true},
    {"5.1", 5, 1, "Center of the left cheek", 90, {90, -1, -1, -1}, true},
    {"5.2", 5, 2, "Center of the right cheek", 91, {91, -1, -1, -1}, true},
    {"5.3", 5, 3, "Left cheek bone", 27, {27, -1, -1, -1}, true},
    {"5.4", 5, 4, "Right cheek bone", 60, {60, -1, -1, -1}, true},
    {"6.1", 6, 1, "Tip of the tongue", -1, {-1, -1, -1, -1}, false},
    {"6.2", 6, 2, "Center of the tongue body", -1, {-1, -1, -1, -1}, false},
    {"6.3", 6, 3, "Left border of the tongue", -1, {-1, -1, -1, -1}, false},
    {"6.4", 6, 4, "Right border of the tongue", -1, {-1, -1, -1, -1}, false},
    {"7.1", 7, 1, "Top of spine (center of head rotation)", -1, {-1, -1, -1, -1}, true},
    {"8.1", 8, 1, "Middle point of outer upper lip contour", 7, {7, -1, -1, -1}, true},
    {"8.2", 8, 2, "Middle point of outer lower lip contour", 8, {8, -1, -1, -1}, true},
    {"8.3", 8, 3, "Left corner of outer lip contour", 31, {31, -1, -1, -1}, true},
    {"8.4", 8, 4, "Right corner of outer lip contour", 64, {64, -1, -1, -1}, true},
    {"8.5", 8, 5, "Midpoint between 8.3 (left) and 8.1 on outer upper lip contour", 79, {79, -1, -1, -1}, true},
    {"8.6", 8, 6, "Midpoint between 8.4 (right) and 8.1 on outer upper lip contour", 80, {80, -1, -1, -1}, true},
    {"8.7", 8, 7, "Midpoint between 8.3 (left) and 8.2 on outer lower lip contour", 85, {85, -1, -1, -1}, true},
    {"8.8", 8, 8, "Midpoint between 8.4 (right) and 8.2 on outer lower lip contour", 86, {86, -1, -1, -1}, true},
    {"8.9", 8, 9, "Uppermost point of right outer lip contour", 66, {66, -1, -1, -1}, true},
    {"8.10", 8, 10, "Uppermost point of left outer lip contour", 33, {33, -1, -1, -1}, true},
    {"9.1", 9, 1, "Left nostril border", 26, {26, -1, -1, -1}, true},
    {"9.2", 9, 2, "Right nostril border", 59, {59, -1, -1, -1}, true},
    {"9.3", 9, 3, "Nose tip", 5, {5, -1, -1, -1}, true},
    {"9.4", 9, 4, "Bottom right edge of nose", 112, {112, -1, -1, -1}, true},
    {"9.5", 9, 5, "Bottom left edge of nose", 111, {111, -1, -1, -1}, true},
    {"9.6", 9, 6, "Right upper edge of nose bone", 78, {78, -1, -1, -1}, true},
    {"9.7", 9, 7, "Left upper edge of nose bone", 77, {77, -1, -1, -1}, true},
    {"9.8", 9, 8, "Teeth (exact description not verified; absent from Candide table)", -1, {-1, -1, -1, -1}, false},
    {"9.9", 9, 9, "Teeth (upper/lower incisor point; exact description not verified)", -1, {-1, -1, -1, -1}, false},
    {"9.10", 9, 10, "Teeth (exact description not verified)", -1, {-1, -1, -1, -1}, false},
    {"9.11", 9, 11, "Teeth (exact description not verified)", -1, {-1, -1, -1, -1}, false},
    {"9.12", 9, 12, "Middle lower edge of nose bone (or nose bump)", 94, {94, -1, -1, -1}, true},
    {"9.13", 9, 13, "Left lower edge of nose bone", 92, {92, -1, -1, -1}, true},
    {"9.14", 9, 14, "Right lower edge of nose bone", 93, {93, -1, -1, -1}, true},
    {"9.15", 9, 15, "Bottom middle edge of nose", 6, {6, -1, -1, -1}, true},
    {"10.1", 10, 1, "Top of left ear", -1, {-1, -1, -1, -1}, false},
    {"10.2", 10, 2, "Top of right ear", -1, {-1, -1, -1, -1}, false},
    {"10.3", 10, 3, "Back of left ear", -1, {-1, -1, -1, -1}, false},
    {"10.4", 10, 4, "Back of right ear", -1, {-1, -1, -1, -1}, false},
    {"10.5", 10, 5, "Bottom of left ear lobe", -1, {-1, -1, -1, -1}, false},
    {"10.6", 10, 6, "Bottom of right ear lobe", -1, {-1, -1, -1, -1}, false},
    {"10.7", 10, 7, "Lower contact point between (Candide: right) ear and face", 61, {61, -1, -1, -1}, true},
    {"10.8", 10, 8, "Inner/lower contact point between (Candide: left) ear and face", 28, {28, -1, -1, -1}, true},
    {"10.9", 10, 9, "Upper contact point between left ear and face", 29, {29, -1, -1, -1}, true},
    {"10.10", 10, 10, "Upper contact point between right ear and face", 62, {62, -1, -1, -1}, true},
    {"11.1", 11, 1, "Middle border between hair and forehead", 1, {1, 34, -1, -1}, true},
    {"11.2", 11, 2, "Right border between hair and forehead", 46, {46, -1, -1, -1}, true},
    {"11.3", 11, 3, "Left border between hair and forehead", 13, {13, -1, -1, -1}, true},
    {"11.4", 11, 4, "Top of skull", 0, {0, -1, -1, -1}, true},
    {"11.5", 11, 5, "Hair thickness over 11.4", -1, {-1, -1, -1, -1}, true},
    {"11.6", 11, 6, "Back of skull", -1, {-1, -1, -1, -1}, true},
}};

// Points per group 2..11 and where each group starts in kFeaturePoints.
constexpr int kFirstGroup = 2;
constexpr int kLastGroup = 11;
constexpr std::array<int, 10> kGroupSize{14, 14, 6, 4, 4, 1, 10, 15, 10, 6};
constexpr std::array<int, 10> kGroupStart{0, 14, 28, 34, 38, 42, 43, 53, 68, 78};

bool parse_small_int(std::string_view text, int& out) {
    if (text.empty() || text.size() > 2 || text[0] == '0') return false;
    auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
    return ec == std::errc() && end == text.data() + text.size();
}

}  // namespace

const std::array<FeaturePointInfo, kFeaturePointCount>& feature_points() { return kFeaturePoints; }

std::optional<int> find_feature_point(std::string_view id) {
    const std::size_t dot = id.find('.');
    if (dot == std::string_view::npos) return std::nullopt;
    int group = 0, index = 0;
    if (!parse_small_int(id.substr(0, dot), group) || !parse_small_int(id.substr(dot + 1), index))
        return std::nullopt;
    if (group < kFirstGroup || group > kLastGroup) return std::nullopt;
    const int g = group - kFirstGroup;
    if (index < 1 || index > kGroupSize[g]) return std::nullopt;
    return kGroupStart[g] + index - 1;
}

int feature_point_index(std::string_view id) {
    if (auto index = find_feature_point(id)) return *index;
    fail<InputError>("fap: feature_point_index: expected a feature point id such as 3.5 "
                     "(group 2..11 '.' index), found {}",
                     detail::quoted(id));
}

}  // namespace emoface::fap
