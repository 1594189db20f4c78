#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/fap/fapu.h"

namespace emoface::fap {
namespace {

// A face in the convention of fap_table.h with known distances.
FeaturePointPositions synthetic_face() {
    FeaturePointPositions p{};
    const auto put = [&](const char* id, double x, double y) {
        p[static_cast<std::size_t>(feature_point_index(id))] = {x, y, 0.1};
    };
    // Whole numbers, so the differences are exact.
    put("3.1", 30, 52);   // upper left eyelid
    put("3.3", 30, 48);   // lower left eyelid: IRISD0 = 4
    put("3.5", 30, 50);   // left pupil (face's left = +x)
    put("3.6", -30, 50);  // right pupil: ES0 = 60
    put("9.15", 0, 10);   // nose bottom: ENS0 = 40
    put("2.2", 0, -5);    // inner upper lip: MNS0 = 15
    put("8.3", 25, -8);   // left mouth corner
    put("8.4", -25, -8);  // right mouth corner: MW0 = 50
    return p;
}

TEST(Fapu, DistancesOver1024) {
    const Fapu u = compute_fapu(synthetic_face());
    EXPECT_EQ(u.irisd, 4.0 / 1024);
    EXPECT_EQ(u.es, 60.0 / 1024);
    EXPECT_EQ(u.ens, 40.0 / 1024);
    EXPECT_EQ(u.mns, 15.0 / 1024);
    EXPECT_EQ(u.mw, 50.0 / 1024);
    EXPECT_DOUBLE_EQ(u.au, 1e-5);
}

TEST(Fapu, OfUnit) {
    const Fapu u{1, 2, 3, 4, 5, 6};
    const std::pair<FapUnit, double> table[] = {{FapUnit::None, 0}, {FapUnit::IRISD, 1},
                                                {FapUnit::ES, 2},   {FapUnit::ENS, 3},
                                                {FapUnit::MNS, 4},  {FapUnit::MW, 5},
                                                {FapUnit::AU, 6}};
    for (const auto& [unit, value] : table) EXPECT_EQ(u.of(unit), value) << unit_name(unit);
    // FAP 19's unit is IRISD (the standard), so a full close of 1024 units
    // is one neutral eyelid gap.
    EXPECT_EQ(1024 * compute_fapu(synthetic_face()).of(fap_info(19).unit), 4.0);
}

TEST(Fapu, NonPositiveDistancesAreErrors) {
    struct Case {
        const char* id;
        double x, y;
        const char* message;
    };
    const Case cases[] = {
        {"3.3", 30, 52,
         "fap: compute_fapu: expected IRISD0 = 3.1.y - 3.3.y > 0 on the neutral face, found 0"},
        {"3.6", 40, 50,  // a mirrored face
         "fap: compute_fapu: expected ES0 = 3.5.x - 3.6.x > 0 on the neutral face, found -10"},
        {"9.15", 0, 50,
         "fap: compute_fapu: expected ENS0 = 3.5.y - 9.15.y > 0 on the neutral face, found 0"},
        {"2.2", 0, 35,
         "fap: compute_fapu: expected MNS0 = 9.15.y - 2.2.y > 0 on the neutral face, found -25"},
        {"8.4", 25, -8,
         "fap: compute_fapu: expected MW0 = 8.3.x - 8.4.x > 0 on the neutral face, found 0"},
    };
    for (const Case& c : cases) {
        FeaturePointPositions p = synthetic_face();
        p[static_cast<std::size_t>(feature_point_index(c.id))] = {c.x, c.y, 0};
        try {
            compute_fapu(p);
            ADD_FAILURE() << c.id;
        } catch (const InputError& e) {
            EXPECT_STREQ(e.what(), c.message);
        }
    }
    FeaturePointPositions nan_face = synthetic_face();
    nan_face[static_cast<std::size_t>(feature_point_index("8.3"))][0] = std::nan("");
    EXPECT_THROW(compute_fapu(nan_face), InputError);
}

}  // namespace
}  // namespace emoface::fap
