// FaceState: FAP 2 to a mix and back to FAPs, the NNLS fit, visemes.
#include <gtest/gtest.h>

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

TEST(FitEmotionMix, RecoversAKnownMixFromItsFaps) {
    struct Case {
        std::vector<std::pair<Emotion, double>> weights;
    } cases[] = {
        {{{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}}},
        {{{Emotion::Joy, 1.0}}},
        {{{Emotion::Sadness, 0.4}}},
        {{{Emotion::Disgust, 0.5}, {Emotion::Surprise, 0.25}, {Emotion::Joy, 0.25}}},
        {{}},
    };
    for (const Case& c : cases) {
        EmotionMix truth;
        for (auto [e, w] : c.weights) truth[e] = w;
        SCOPED_TRACE(truth.to_string());
        const EmotionMix fit = fit_emotion_mix(profiles().faps(truth), all_low_level(), profiles());
        for (int e = 0; e < kEmotionCount; ++e) EXPECT_NEAR(fit.weights[e], truth.weights[e], 0.05);
    }
}

TEST(FitEmotionMix, UsesOnlyTheTransmittedFapsAndStaysNonNegative) {
    EmotionMix truth;
    truth[Emotion::Anger] = 0.7;
    truth[Emotion::Fear] = 0.3;
    FapValues faps = profiles().faps(truth);
    // Only brows and lips transmitted (like VREng's files); the rest is garbage the fit must ignore.
    std::bitset<fap::kFapCount> mask;
    for (int f : {31, 32, 33, 34, 35, 36, 37, 38, 51, 52, 53, 54, 59, 60, 19, 20, 21, 22, 3, 5}) mask[f - 1] = true;
    for (int f = 3; f <= fap::kFapCount; ++f)
        if (!mask[f - 1]) faps[f - 1] = 5000;
    const EmotionMix fit = fit_emotion_mix(faps, mask, profiles());
    EXPECT_NEAR(fit[Emotion::Anger], 0.7, 0.05);
    EXPECT_NEAR(fit[Emotion::Fear], 0.3, 0.05);
    // Opposite of joy: no negative joy, just zero.
    FapValues sad{};
    for (int f = 1; f <= fap::kFapCount; ++f) sad[f - 1] = -profiles()[Emotion::Joy][f - 1];
    const EmotionMix s = fit_emotion_mix(sad, all_low_level(), profiles());
    for (double w : s.weights) EXPECT_GE(w, 0.0);
    EXPECT_EQ(s[Emotion::Joy], 0.0);
    // Twice joy is clamped to a valid mix.
    FapValues twice{};
    for (int f = 1; f <= fap::kFapCount; ++f) twice[f - 1] = 2 * profiles()[Emotion::Joy][f - 1];
    const EmotionMix t = fit_emotion_mix(twice, all_low_level(), profiles());
    EXPECT_NEAR(t.sum(), 1.0, 1e-9);
    EXPECT_NEAR(t[Emotion::Joy], 1.0, 1e-6);
    // Nothing in common with the profiles: neutral.
    EXPECT_EQ(fit_emotion_mix(twice, {}, profiles()).sum(), 0.0);
}

TEST(FaceState, Fap2GivesTheMixAndSynthesisesLowLevelFaps) {
    fap::FapFrame frame;
    frame.set_expression({3, 63, 4, 21, 0, 0});  // anger at 63/63, fear at 21/63
    const FaceState s = face_state(frame, profiles());
    EXPECT_EQ(s.mix_source, MixSource::Expression);
    EXPECT_NEAR(s.mix[Emotion::Anger], 0.75, 1e-9);  // 1 + 1/3 scaled to sum 1
    EXPECT_NEAR(s.mix[Emotion::Fear], 0.25, 1e-9);
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

TEST(FaceState, LowLevelOnlyFramesAreFitted) {
    EmotionMix truth;
    truth[Emotion::Surprise] = 0.6;
    const FapValues faps = profiles().faps(truth);
    fap::FapFrame frame;
    for (int f = 3; f <= fap::kFapCount; ++f)
        if (faps[f - 1] != 0) frame.set(f, faps[f - 1]);
    const FaceState s = face_state(frame, profiles());
    EXPECT_EQ(s.mix_source, MixSource::Fitted);
    EXPECT_NEAR(s.mix[Emotion::Surprise], 0.6, 0.05);
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
    EXPECT_STREQ(mix_source_name(MixSource::Fitted), "fitted to the FAPs");
}

}  // namespace
}  // namespace emoface::expression
