// FACS Action Units: the table in data/expression/action_units.json (each AU
// moves the FAPs its reasoning names, the way and on the side it says),
// emotions as sums of AUs, and reading AUs back from a frame's FAPs region by
// region and side by side.
#include <gtest/gtest.h>

#include <cctype>
#include <filesystem>
#include <set>

#include <fmt/format.h>

#include "emoface/expression/action_units.h"
#include "emoface/expression/face_state.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/fap_io.h"

namespace emoface::expression {
namespace {

const EmotionProfiles& profiles() {
    static const EmotionProfiles p = load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
    return p;
}
const ActionUnitTable& table() { return profiles().action_units; }

std::bitset<fap::kFapCount> all_low_level() {
    std::bitset<fap::kFapCount> m;
    for (int f = 3; f <= fap::kFapCount; ++f) m[f - 1] = true;
    return m;
}

int fap_number(const char* name) { return *fap::find_fap(name); }

// A frame transmitting every low-level FAP at `faps`.
fap::FapFrame fap_frame_of(const FapValues& faps) {
    fap::FapFrame frame;
    for (int f = 3; f <= fap::kFapCount; ++f) frame.set(f, faps[f - 1]);
    return frame;
}

TEST(ActionUnits, TheTableHasTheAusTheFaceShows) {
    for (int au : {1, 2, 4, 5, 6, 7, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 20, 22, 23, 24, 25, 26, 27, 28, 41, 43,
                   45, 46, 51, 52, 53, 54, 55, 56, 57, 58, 61, 62, 63, 64}) {
        const ActionUnit* u = table().find(au);
        ASSERT_NE(u, nullptr) << "AU" << au;
        EXPECT_FALSE(u->name.empty());
        EXPECT_FALSE(u->muscle.empty());
        EXPECT_GT(u->reasoning.size(), 60u) << "AU" << au;
    }
}

// The direction each AU's reasoning gives for one FAP on the face's left
// (bilateral AUs) or the midline; the right side must mirror it.
TEST(ActionUnits, EachAuMovesItsFapsTheWayItsReasoningSays) {
    enum Dir { Down = -1, Up = +1 };  // the FAP's value: negative or positive
    struct Case {
        int au;
        const char* fap;
        Dir dir;
    } cases[] = {
        {1, "raise_l_i_eyebrow", Up},       {1, "raise_l_m_eyebrow", Up},
        {2, "raise_l_o_eyebrow", Up},       {2, "raise_l_m_eyebrow", Up},
        {4, "raise_l_i_eyebrow", Down},     {4, "squeeze_l_eyebrow", Up},
        {5, "close_t_l_eyelid", Down},      {6, "lift_l_cheek", Up},
        {6, "close_b_l_eyelid", Up},        {7, "close_b_l_eyelid", Up},
        {9, "raise_nose", Up},              {9, "stretch_l_nose", Up},
        {9, "lower_t_midlip_o", Down},      {9, "raise_l_i_eyebrow", Down},
        {10, "lower_t_lip_lm", Down},       {10, "lower_t_midlip", Down},
        {11, "lower_t_lip_lm_o", Down},     {12, "raise_l_cornerlip_o", Up},
        {12, "stretch_l_cornerlip_o", Up},  {13, "raise_l_cornerlip_o", Up},
        {14, "stretch_l_cornerlip_o", Down}, {15, "raise_l_cornerlip_o", Down},
        {16, "raise_b_lip_lm", Down},       {16, "push_b_lip", Up},
        {17, "depress_chin", Up},           {17, "raise_b_midlip", Up},
        {18, "push_t_lip", Up},             {18, "stretch_l_cornerlip_o", Down},
        {20, "stretch_l_cornerlip_o", Up},  {22, "push_b_lip", Up},
        {23, "lower_t_midlip_o", Up},       {23, "raise_b_midlip_o", Up},
        {24, "lower_t_midlip", Up},         {25, "raise_b_midlip", Down},
        {26, "open_jaw", Up},               {27, "open_jaw", Up},
        {28, "push_b_lip", Down},           {41, "close_t_l_eyelid", Up},
        {43, "close_t_l_eyelid", Up},       {45, "close_t_l_eyelid", Up},
        {46, "close_t_l_eyelid", Up},       {51, "head_yaw", Up},
        {52, "head_yaw", Down},             {53, "head_pitch", Down},
        {54, "head_pitch", Up},             {55, "head_roll", Down},
        {56, "head_roll", Up},              {61, "yaw_l_eyeball", Up},
        {62, "yaw_l_eyeball", Down},        {63, "pitch_l_eyeball", Down},
        {64, "pitch_l_eyeball", Up},        {29, "thrust_jaw", Up},
        {57, "head_pitch", Up},             {58, "head_pitch", Down},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(fmt::format("AU{} {}", c.au, c.fap));
        const ActionUnit* u = table().find(c.au);
        ASSERT_NE(u, nullptr);
        const int f = fap_number(c.fap);
        EXPECT_GT(c.dir * u->faps[f - 1], 0.0);
        // The reasoning names the FAP by number.
        EXPECT_NE(u->reasoning.find(std::to_string(f)), std::string::npos);
    }
    // The cases above cover every AU in the table.
    std::set<int> covered;
    for (const Case& c : cases) covered.insert(c.au);
    for (const ActionUnit& u : table().units) EXPECT_TRUE(covered.count(u.number)) << "AU" << u.number;
}

TEST(ActionUnits, ReasoningNamesEveryFapTheAuMoves) {
    for (const ActionUnit& u : table().units) {
        // The numbers in the reasoning, e.g. "5/52 +100" -> 5, 52, 100.
        std::set<int> named;
        for (std::size_t i = 0; i < u.reasoning.size();) {
            if (!std::isdigit(static_cast<unsigned char>(u.reasoning[i]))) {
                ++i;
                continue;
            }
            std::size_t j = i;
            while (j < u.reasoning.size() && std::isdigit(static_cast<unsigned char>(u.reasoning[j]))) ++j;
            named.insert(std::stoi(u.reasoning.substr(i, std::min<std::size_t>(j - i, 6))));
            i = j;
        }
        for (int f = 3; f <= fap::kFapCount; ++f) {
            if (u.left[f - 1] == 0.0 && (u.sides || u.faps[f - 1] == 0.0)) continue;  // left half or midline
            EXPECT_TRUE(named.count(f)) << "AU" << u.number << " moves FAP " << f << " without naming it";
        }
    }
}

TEST(ActionUnits, BilateralHalvesStayOnTheirSideAndSumToTheWhole) {
    // FAPs on the face's left and right (fap_table.tsv's names: _l_ / _lm).
    auto side_of = [](int f) {
        const std::string n(fap::fap_info(f).name);
        if (n.find("_l_") != std::string::npos || n.find("_lm") != std::string::npos) return -1;
        if (n.find("_r_") != std::string::npos || n.find("_rm") != std::string::npos) return +1;
        return 0;
    };
    for (const ActionUnit& u : table().units) {
        SCOPED_TRACE(fmt::format("AU{}", u.number));
        for (int f = 3; f <= fap::kFapCount; ++f) {
            EXPECT_NEAR(u.left[f - 1] + u.right[f - 1], u.faps[f - 1], 1e-12) << "FAP " << f;
            if (!u.sides) continue;
            if (side_of(f) > 0) EXPECT_EQ(u.left[f - 1], 0.0) << "FAP " << f;
            if (side_of(f) < 0) EXPECT_EQ(u.right[f - 1], 0.0) << "FAP " << f;
        }
        // "AU12L" moves the left only: the FAPs of a left-only intensity.
        if (!u.sides) continue;
        AuIntensities l;
        l.left[u.number] = 1.0;
        const FapValues faps = table().faps(l);
        for (int f = 3; f <= fap::kFapCount; ++f)
            if (side_of(f) > 0) EXPECT_EQ(faps[f - 1], 0.0) << "FAP " << f;
    }
}

TEST(EmotionPrototypes, AreTheFacsPrototypesAndTheirFapsAreTheSumOfTheirAus) {
    struct Case {
        Emotion emotion;
        std::set<int> aus;  // EMFACS codes (sadness adds 64, from the Investigator's Guide's variants, and 41; anger the chin raiser 17 of its 4+5+7+17+23 variant)
    } cases[] = {
        {Emotion::Joy, {6, 12}},
        {Emotion::Sadness, {1, 4, 15, 41, 64}},
        {Emotion::Surprise, {1, 2, 5, 26}},
        {Emotion::Fear, {1, 2, 4, 5, 7, 20, 26}},
        {Emotion::Anger, {4, 5, 7, 17, 23}},
        {Emotion::Disgust, {9, 15, 16}},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(emotion_name(c.emotion));
        const AuIntensities& p = profiles().prototypes[emotion_index(c.emotion)];
        std::set<int> present;
        for (int a = 1; a < kAuNumberLimit; ++a) {
            EXPECT_EQ(p.left[a], p.right[a]);
            if (p.left[a] > 0) present.insert(a);
        }
        EXPECT_EQ(present, c.aus);
        FapValues sum{};
        for (int a : c.aus)
            for (int f = 0; f < fap::kFapCount; ++f) sum[f] += p.left[a] * table().find(a)->faps[f];
        for (int f = 0; f < fap::kFapCount; ++f) EXPECT_NEAR(profiles()[c.emotion][f], sum[f], 1e-9) << "FAP " << f + 1;
        // A mix of one emotion shows that emotion's FAPs and AUs.
        EmotionMix m;
        m[c.emotion] = 0.5;
        const FaceState s = face_state(m, profiles());
        for (int f = 0; f < fap::kFapCount; ++f) EXPECT_NEAR(s.faps[f], 0.5 * sum[f], 1e-9);
        for (int a : c.aus) EXPECT_NEAR(s.aus.left[a], 0.5 * p.left[a], 1e-12);
    }
}

TEST(AuInference, RecoversAKnownAsymmetricAuMix) {
    struct Term {
        int au;
        double left, right;
    };
    const std::vector<std::vector<Term>> cases = {
        {{1, 0.8, 0.2}, {2, 0.1, 0.6}, {5, 0.5, 0.2}, {6, 0.7, 0.3}, {12, 0.9, 0.4}, {26, 0.5, 0.5}},
        {{4, 0.3, 0.9}, {7, 0.0, 0.6}, {9, 0.4, 0.1}, {15, 0.2, 0.7}, {17, 0.4, 0.4}, {23, 0.6, 0.6}},
        {{2, 1.0, 0.0}, {10, 0.5, 0.2}, {20, 0.3, 0.8}, {16, 0.6, 0.1}, {25, 0.3, 0.3}, {61, 0.4, 0.4},
         {51, 0.5, 0.5}, {54, 0.3, 0.3}},
        {{43, 0.0, 1.0}, {6, 0.4, 0.0}, {18, 0.7, 0.7}, {29, 0.5, 0.5}, {64, 0.6, 0.6}, {55, 0.2, 0.2}},
    };
    for (const auto& terms : cases) {
        AuIntensities truth;
        for (const Term& t : terms) {
            truth.left[t.au] = t.left;
            truth.right[t.au] = t.right;
        }
        SCOPED_TRACE(truth.to_string());
        const AuIntensities got = table().infer(table().faps(truth), all_low_level());
        for (int a = 1; a < kAuNumberLimit; ++a) {
            EXPECT_NEAR(got.left[a], truth.left[a], 0.1) << "AU" << a << "L";
            EXPECT_NEAR(got.right[a], truth.right[a], 0.1) << "AU" << a << "R";
        }
    }
}

TEST(AuInference, ALeftOuterBrowRaiseIsALeftAu2Only) {
    FapValues faps{};
    std::bitset<fap::kFapCount> mask;
    faps[35 - 1] = 200;  // raise_l_o_eyebrow
    mask[35 - 1] = true;
    const AuIntensities aus = table().infer(faps, mask);
    EXPECT_GT(aus.left[2], 0.5);
    for (int a = 1; a < kAuNumberLimit; ++a) EXPECT_EQ(aus.right[a], 0.0) << "AU" << a << "R";
    // The same with every FAP transmitted (the other brow FAPs at 0).
    const AuIntensities all = table().infer(faps, all_low_level());
    EXPECT_GT(all.left[2], 0.3);
    for (int a = 1; a < kAuNumberLimit; ++a) EXPECT_EQ(all.right[a], 0.0) << "AU" << a << "R";
}

TEST(AuInference, IntensitiesStayInZeroToOneAndIgnoreUntransmittedFaps) {
    FapValues faps{};
    std::bitset<fap::kFapCount> mask;
    for (int f = 3; f <= fap::kFapCount; ++f) faps[f - 1] = (f % 3 == 0 ? 5000.0 : -5000.0);
    const AuIntensities wild = table().infer(faps, all_low_level());
    for (int a = 1; a < kAuNumberLimit; ++a) {
        EXPECT_GE(wild.left[a], 0.0);
        EXPECT_LE(wild.left[a], 1.0);
        EXPECT_GE(wild.right[a], 0.0);
        EXPECT_LE(wild.right[a], 1.0);
    }
    EXPECT_TRUE(table().infer(faps, mask).empty());
}

TEST(AuInference, EmotionMixFromAusNamesTheEmotionOfEachPrototype) {
    for (Emotion e : kEmotions) {
        SCOPED_TRACE(emotion_name(e));
        EmotionMix m;
        m[e] = 0.8;
        const FaceState s = face_state(fap_frame_of(profiles().faps(m)), profiles());
        EXPECT_EQ(s.mix_source, MixSource::FromActionUnits);
        EXPECT_NEAR(s.mix[e], 0.8, 0.1);
        for (Emotion other : kEmotions)
            if (other != e) EXPECT_LT(s.mix[other], 0.1) << emotion_name(other);
    }
}

TEST(AuInference, XfaceJoySmilesWithoutWorry) {
    const std::filesystem::path path = std::filesystem::path(EMOFACE_REALDATA_DIR) / "fap" / "xface_joy.fap";
    if (!std::filesystem::exists(path))
        GTEST_SKIP() << path << " is absent (set EMOFACE_REALDATA_DIR to the folder holding fap/xface_joy.fap)";
    const fap::FapStream stream = fap::resolve_untransmitted(fap::read_fap_file(path.string()));
    double most_joy = 0.0;
    for (std::size_t k = 0; k < stream.frames.size(); ++k) {
        SCOPED_TRACE(fmt::format("frame {}", k));
        const FaceState s = face_state(stream.frames[k], profiles());
        const AuIntensities& a = s.aus;
        const double worry = a.left[1] + a.right[1] + a.left[4] + a.right[4];
        const double smile = a.left[6] + a.right[6] + a.left[12] + a.right[12];
        EXPECT_TRUE(worry < smile || worry == 0.0) << "AU1+AU4 " << worry << ", AU6+AU12 " << smile;
        EXPECT_LT(s.mix[Emotion::Fear], 0.1);
        EXPECT_LT(s.mix[Emotion::Sadness], 0.1);
        most_joy = std::max(most_joy, s.mix[Emotion::Joy]);
    }
    EXPECT_GT(most_joy, 0.5);
}

}  // namespace
}  // namespace emoface::expression
