// FaceState: FAP 2 to a mix and back to FAPs, mixes with AUs, the emotion mix
// from a frame's AUs, visemes.
#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/expression/face_state.h"

namespace emoface::expression {
namespace {

const EmotionProfiles& profiles() {
    static const EmotionProfiles p = load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
    return p;
}
const VisemeProfiles& visemes() {
    static const VisemeProfiles v = load_viseme_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/visemes.json");
    return v;
}

std::bitset<fap::kFapCount> all_low_level() {
    std::bitset<fap::kFapCount> m;
    for (int f = 3; f <= fap::kFapCount; ++f) m[f - 1] = true;
    return m;
}

TEST(MixFromActionUnits, RecoversAKnownMixThroughItsFaps) {
    struct Case {
        std::vector<std::pair<Emotion, double>> weights;
    } cases[] = {
        {{{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}}},
        {{{Emotion::Joy, 1.0}}},
        {{{Emotion::Sadness, 0.4}}},
        {{{Emotion::Disgust, 0.5}, {Emotion::Surprise, 0.25}, {Emotion::Joy, 0.25}}},
        {{{Emotion::Fear, 0.5}, {Emotion::Surprise, 0.5}}},
        {{}},
    };
    for (const Case& c : cases) {
        EmotionMix truth;
        for (auto [e, w] : c.weights) truth[e] = w;
        SCOPED_TRACE(truth.to_string());
        const AuIntensities aus = profiles().action_units.infer(profiles().faps(truth), all_low_level());
        const EmotionMix got = profiles().mix_from_action_units(aus);
        for (int e = 0; e < kEmotionCount; ++e) EXPECT_NEAR(got.weights[e], truth.weights[e], 0.05);
    }
}

TEST(MixFromActionUnits, StaysAValidMix) {
    // Every AU of the table at E on both sides: weights in [0, 1], sum at most 1.
    AuIntensities all;
    for (const ActionUnit& u : profiles().action_units.units) all.left[u.number] = all.right[u.number] = 1.0;
    const EmotionMix m = profiles().mix_from_action_units(all);
    for (double w : m.weights) {
        EXPECT_GE(w, 0.0);
        EXPECT_LE(w, 1.0);
    }
    EXPECT_LE(m.sum(), 1.0 + 1e-12);
    EXPECT_EQ(profiles().mix_from_action_units(AuIntensities{}).sum(), 0.0);
}

TEST(FaceState, Fap2GivesTheMixAndSynthesisesLowLevelFaps) {
    fap::FapFrame frame;
    frame.set_expression({3, 63, 4, 21, 0, 0});  // anger at 63/63, fear at 21/63
    const FaceState s = face_state(frame, profiles());
    EXPECT_EQ(s.mix_source, MixSource::Expression);
    EXPECT_NEAR(s.mix[Emotion::Anger], 0.75, 1e-9);  // 1 + 1/3 scaled to sum 1
    EXPECT_NEAR(s.mix[Emotion::Fear], 0.25, 1e-9);
    EXPECT_EQ(s.aus, profiles().action_units_of(s.mix));
    const FapValues expected = profiles().faps(s.mix);
    for (int f = 3; f <= fap::kFapCount; ++f) EXPECT_DOUBLE_EQ(s.faps[f - 1], expected[f - 1]) << f;
    EXPECT_TRUE(s.mask[31 - 1]);
    EXPECT_FALSE(s.mask[43 - 1]);  // no profile moves the tongue

    // Both selections naming one emotion add up; neutral code 0 adds nothing.
    frame.set_expression({1, 30, 1, 20, 0, 0});
    EXPECT_NEAR(face_state(frame, profiles()).mix[Emotion::Joy], 50.0 / 63.0, 1e-12);
    frame.set_expression({0, 63, 6, 63, 0, 0});
    EXPECT_NEAR(face_state(frame, profiles()).mix.sum(), 1.0, 1e-12);
}

TEST(FaceState, Fap2WithLowLevelFapsKeepsThem) {
    fap::FapFrame frame;
    frame.set_expression({2, 63, 0, 0, 0, 0});
    frame.set(3, 77);
    const FaceState s = face_state(frame, profiles());
    EXPECT_EQ(s.mix_source, MixSource::Expression);
    EXPECT_NEAR(s.mix[Emotion::Sadness], 1.0, 1e-12);
    EXPECT_EQ(s.faps[3 - 1], 77);
    EXPECT_EQ(s.faps[31 - 1], 0.0);
    EXPECT_EQ(s.mask.count(), 1u);
}

TEST(FaceState, LowLevelOnlyFramesGetTheirAusAndAMixFromThem) {
    EmotionMix truth;
    truth[Emotion::Surprise] = 0.6;
    const FapValues faps = profiles().faps(truth);
    fap::FapFrame frame;
    for (int f = 3; f <= fap::kFapCount; ++f)
        if (faps[f - 1] != 0) frame.set(f, faps[f - 1]);
    const FaceState s = face_state(frame, profiles());
    EXPECT_EQ(s.mix_source, MixSource::FromActionUnits);
    EXPECT_NEAR(s.mix[Emotion::Surprise], 0.6, 0.05);
    EXPECT_NEAR(s.aus.left[2], 0.6, 0.05);
    EXPECT_NEAR(s.aus.right[26], 0.6 * profiles().prototypes[emotion_index(Emotion::Surprise)].right[26], 0.05);
    EXPECT_EQ(s.faps, faps);

    const FaceState empty = face_state(fap::FapFrame{}, profiles());
    EXPECT_EQ(empty.mix_source, MixSource::None);
    EXPECT_EQ(empty.mask.count(), 0u);
}

TEST(FaceState, VisemeAddsMouthFapsOnlyWhenTheFrameHasNone) {
    fap::FapFrame frame;
    frame.set_viseme({10, 0, 63, 0});  // A: fully
    const FaceState s = face_state(frame, profiles(), &visemes());
    EXPECT_TRUE(s.has_viseme);
    EXPECT_EQ(s.viseme.select1, 10);
    EXPECT_DOUBLE_EQ(s.faps[3 - 1], visemes().profiles[10][3 - 1]);
    EXPECT_TRUE(s.mask[3 - 1]);
    // Without viseme profiles the viseme is only reported.
    EXPECT_EQ(face_state(frame, profiles()).faps[3 - 1], 0.0);
    // A frame with its own mouth FAPs keeps them.
    frame.set(3, 12);
    EXPECT_EQ(face_state(frame, profiles(), &visemes()).faps[3 - 1], 12);
}

TEST(FaceState, FromAMix) {
    const EmotionMix m = parse_emotion_mix("0.5 joy + 0.5 surprise");
    const FaceState s = face_state(m, profiles());
    EXPECT_EQ(s.mix_source, MixSource::Given);
    EXPECT_EQ(s.mix, m);
    EXPECT_DOUBLE_EQ(s.faps[59 - 1], 0.5 * profiles()[Emotion::Joy][59 - 1] + 0.5 * profiles()[Emotion::Surprise][59 - 1]);
    EXPECT_NEAR(s.aus.left[12], 0.5 * profiles().prototypes[emotion_index(Emotion::Joy)].left[12], 1e-12);
    EXPECT_GT(s.aus.left[12], 0.4);
    EXPECT_STREQ(mix_source_name(MixSource::FromActionUnits), "from the action units");
}

TEST(FaceState, FromAMixWithActionUnits) {
    struct Case {
        const char* text;
        Emotion shown;  // the emotion its AUs derive
        int au;
        double left, right;  // that AU's intensities in the state
    } cases[] = {
        {"0.6 joy + 0.3 AU4", Emotion::Joy, 4, 0.3, 0.3},
        {"AU1+AU2", Emotion::Surprise, 2, 1.0, 1.0},
        {"AU6 + AU12", Emotion::Joy, 12, 1.0, 1.0},
        {"0.8 AU12L", Emotion::Joy, 12, 0.8, 0.0},
        {"0.5 joy + 0.8 AU12", Emotion::Joy, 12, 1.0, 1.0},  // at most E
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        const FaceState s = face_state(parse_emotion_mix(c.text), profiles());
        EXPECT_EQ(s.mix_source, MixSource::FromActionUnits);
        EXPECT_NEAR(s.aus.left[c.au], c.left, 1e-12);
        EXPECT_NEAR(s.aus.right[c.au], c.right, 1e-12);
        Emotion top = Emotion::Joy;
        for (Emotion e : kEmotions)
            if (s.mix[e] > s.mix[top]) top = e;
        EXPECT_EQ(top, c.shown) << s.mix.to_string();
        EXPECT_TRUE(s.mix.aus.empty());
        const FapValues expected = profiles().action_units.faps(s.aus);
        EXPECT_EQ(s.faps, expected);
    }
    // A left-only AU moves the left only.
    const FaceState l = face_state(parse_emotion_mix("AU12L"), profiles());
    EXPECT_GT(l.faps[59 - 1], 0.0);
    EXPECT_EQ(l.faps[60 - 1], 0.0);
    // AUs the face cannot show, or a side of a midline AU, are named.
    struct Bad {
        const char* text;
        const char* message_start;
    } bad[] = {
        {"AU30", "expression: emotion mix \"1 AU30\": AU30 is not one the face can show (AUs 1, 2, 4,"},
        {"0.5 AU26L", "expression: emotion mix \"0.5 AU26L\": AU26 (jaw drop) has no sides; give it without L or R"},
    };
    for (const Bad& b : bad) {
        try {
            face_state(parse_emotion_mix(b.text), profiles());
            ADD_FAILURE() << "accepted " << b.text;
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()).rfind(b.message_start, 0), 0u) << e.what();
        }
    }
}

}  // namespace
}  // namespace emoface::expression
