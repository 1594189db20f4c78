#include <cmath>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/fap/fap_table.h"
#include "emoface/fap/feature_points.h"

namespace emoface::fap {
namespace {

TEST(FapTable, NumberedInOrderWithUniqueNames) {
    std::set<std::string_view> names;
    for (std::size_t i = 0; i < fap_table().size(); ++i) {
        EXPECT_EQ(fap_table()[i].number, static_cast<int>(i) + 1);
        EXPECT_TRUE(names.insert(fap_table()[i].name).second) << fap_table()[i].name;
        EXPECT_EQ(find_fap(fap_table()[i].name), static_cast<int>(i) + 1);
    }
    EXPECT_EQ(kFapCount - 2, kLowLevelFapCount);
}

struct FapFact {
    int number;
    const char* name;
    FapUnit unit;
    bool bidirectional;
    const char* feature_point;
    std::array<float, 3> direction;
};

// Rows checked against shared/mpeg4/fap_table.tsv, including the FAP 19
// pitfall (the standard's IRISD, not Xface's MNS).
TEST(FapTable, SpotFacts) {
    const FapFact facts[] = {
        {1, "viseme", FapUnit::None, false, "", {0, 0, 0}},
        {2, "expression", FapUnit::None, false, "", {0, 0, 0}},
        {3, "open_jaw", FapUnit::MNS, false, "2.1", {0, -1, 0}},
        {6, "stretch_l_cornerlip", FapUnit::MW, true, "2.4", {1, 0, 0}},
        {7, "stretch_r_cornerlip", FapUnit::MW, true, "2.5", {-1, 0, 0}},
        {14, "thrust_jaw", FapUnit::MNS, false, "2.1", {0, 0, 1}},
        {19, "close_t_l_eyelid", FapUnit::IRISD, true, "3.1", {0, -1, 0}},
        {21, "close_b_l_eyelid", FapUnit::IRISD, true, "3.3", {0, 1, 0}},
        {23, "yaw_l_eyeball", FapUnit::AU, true, "3.5", {1, 0, 0}},
        {29, "dilate_l_pupil", FapUnit::IRISD, true, "3.5", {0, 0, 0}},
        {31, "raise_l_i_eyebrow", FapUnit::ENS, true, "4.1", {0, 1, 0}},
        {37, "squeeze_l_eyebrow", FapUnit::ES, true, "4.1", {-1, 0, 0}},
        {38, "squeeze_r_eyebrow", FapUnit::ES, true, "4.2", {1, 0, 0}},
        {41, "lift_l_cheek", FapUnit::ENS, false, "5.3", {0, 1, 0}},
        {47, "tongue_roll", FapUnit::AU, false, "6.3", {0, 0, 0}},
        {48, "head_pitch", FapUnit::AU, true, "7.1", {0, -1, 0}},
        {53, "stretch_l_cornerlip_o", FapUnit::MW, true, "8.3", {1, 0, 0}},
        {59, "raise_l_cornerlip_o", FapUnit::MNS, true, "8.3", {0, 1, 0}},
        {64, "bend_nose", FapUnit::ENS, true, "9.3", {-1, 0, 0}},
        {68, "pull_r_ear", FapUnit::ENS, true, "10.4", {-1, 0, 0}},
    };
    for (const FapFact& f : facts) {
        SCOPED_TRACE(f.number);
        const FapInfo& info = fap_info(f.number);
        EXPECT_EQ(info.name, f.name);
        EXPECT_EQ(info.unit, f.unit);
        EXPECT_EQ(info.bidirectional, f.bidirectional);
        EXPECT_EQ(info.feature_point, f.feature_point);
        EXPECT_EQ(info.direction, f.direction);
    }
    EXPECT_EQ(fap_info(47).feature_point_2, "6.4");
    EXPECT_EQ(fap_info(3).practical_max, 1080);
}

// The direction vector agrees with the standard's words for the positive
// direction, in the convention x = face's left, y = up, z = towards viewer.
TEST(FapTable, DirectionsMatchPositiveDirectionWords) {
    for (const FapInfo& info : fap_table()) {
        SCOPED_TRACE(info.name);
        const auto& d = info.direction;
        const float length = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        const bool no_line = info.number <= 2 || info.number == 29 || info.number == 30 ||
                             info.number == 47;
        if (no_line) {
            EXPECT_EQ(length, 0.f);
            continue;
        }
        EXPECT_FLOAT_EQ(length, 1.f);
        const std::array<float, 3> expected =
            info.positive_direction == "up"        ? std::array<float, 3>{0, 1, 0}
            : info.positive_direction == "down"    ? std::array<float, 3>{0, -1, 0}
            : info.positive_direction == "left"    ? std::array<float, 3>{1, 0, 0}
            : info.positive_direction == "right"   ? std::array<float, 3>{-1, 0, 0}
            : info.positive_direction == "forward" ? std::array<float, 3>{0, 0, 1}
                                                   : std::array<float, 3>{9, 9, 9};
        EXPECT_EQ(d, expected) << info.positive_direction;
    }
}

TEST(FapTable, EveryLowLevelFapNamesAFeaturePoint) {
    for (const FapInfo& info : fap_table()) {
        if (info.number <= 2) {
            EXPECT_TRUE(info.feature_point.empty());
            EXPECT_EQ(info.unit, FapUnit::None);
            continue;
        }
        EXPECT_TRUE(find_feature_point(info.feature_point).has_value()) << info.name;
        EXPECT_NE(info.unit, FapUnit::None) << info.name;
    }
}

TEST(FapTable, LookupErrors) {
    const std::pair<int, const char*> bad[] = {
        {0, "fap: fap_info: expected a FAP number 1..68, found 0"},
        {69, "fap: fap_info: expected a FAP number 1..68, found 69"},
        {-3, "fap: fap_info: expected a FAP number 1..68, found -3"},
    };
    for (const auto& [number, message] : bad) {
        try {
            fap_info(number);
            ADD_FAILURE() << number;
        } catch (const InputError& e) {
            EXPECT_STREQ(e.what(), message);
        }
    }
    EXPECT_EQ(find_fap("OPEN_JAW"), 3);
    EXPECT_EQ(find_fap("open jaw"), std::nullopt);
    EXPECT_EQ(find_fap(""), std::nullopt);
    EXPECT_EQ(unit_name(FapUnit::IRISD), "IRISD");
    EXPECT_EQ(unit_name(FapUnit::None), "");
}

TEST(FeaturePoints, IdsMatchGroupAndIndexAndLookUp) {
    std::set<std::string_view> ids;
    int previous_group = 2, previous_index = 0;
    for (int i = 0; i < kFeaturePointCount; ++i) {
        const FeaturePointInfo& p = feature_points()[static_cast<std::size_t>(i)];
        SCOPED_TRACE(p.id);
        EXPECT_TRUE(ids.insert(p.id).second);
        EXPECT_EQ(std::string(p.id), std::to_string(p.group) + "." + std::to_string(p.index));
        // Group order, indices counting from 1 within a group.
        if (p.group == previous_group) {
            EXPECT_EQ(p.index, previous_index + 1);
        } else {
            EXPECT_EQ(p.group, previous_group + 1);
            EXPECT_EQ(p.index, 1);
        }
        previous_group = p.group;
        previous_index = p.index;
        EXPECT_EQ(feature_point_index(p.id), i);
        EXPECT_EQ(p.candide3_vertices[0], p.candide3_vertex);
    }
    EXPECT_EQ(previous_group, 11);
}

TEST(FeaturePoints, CandideVertices) {
    const auto at = [](const char* id) { return feature_points()[static_cast<std::size_t>(feature_point_index(id))]; };
    EXPECT_EQ(at("2.1").candide3_vertex, 10);
    EXPECT_EQ(at("9.15").candide3_vertex, 6);
    EXPECT_EQ(at("3.5").candide3_vertices, (std::array<int, 4>{67, 68, 71, 72}));
    EXPECT_EQ(at("11.1").candide3_vertices, (std::array<int, 4>{1, 34, -1, -1}));
    EXPECT_EQ(at("6.1").candide3_vertex, -1);
    EXPECT_FALSE(at("6.1").description_verified);
    EXPECT_TRUE(at("2.1").description_verified);
}

TEST(FeaturePoints, BadIds) {
    for (const char* id : {"", "2", "2.", ".1", "1.1", "2.0", "2.15", "7.2", "11.7", "12.1",
                           "02.1", "2.01", "2.1.1", "a.b", "-2.1", "+2.1", "2,1", " 2.1"}) {
        EXPECT_EQ(find_feature_point(id), std::nullopt) << id;
    }
    try {
        feature_point_index("12.1");
        ADD_FAILURE();
    } catch (const InputError& e) {
        EXPECT_STREQ(e.what(), "fap: feature_point_index: expected a feature point id such as 3.5 "
                               "(group 2..11 '.' index), found '12.1'");
    }
}

}  // namespace
}  // namespace emoface::fap
