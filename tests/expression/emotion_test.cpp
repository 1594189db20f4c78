// EmotionMix: what parse_emotion_mix accepts and the exact message for each
// thing it rejects; the profile files.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"
#include "emoface/expression/profiles.h"
#include "support/expect_error.h"

namespace emoface::expression {
namespace {

EmotionMix mix(std::initializer_list<std::pair<Emotion, double>> w) {
    EmotionMix m;
    for (auto [e, v] : w) m[e] = v;
    return m;
}

TEST(EmotionMix, AcceptsBothNotationsAndHappiness) {
    struct Case {
        const char* text;
        EmotionMix expected;
    } cases[] = {
        {"anger=0.7,fear=0.3", mix({{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}})},
        {"0.7 anger + 0.3 fear", mix({{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}})},
        {" Anger = 0.7 , FEAR=0.3 ", mix({{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}})},
        {"happiness=0.5", mix({{Emotion::Joy, 0.5}})},
        {"0.5 joy + 0.5 surprise", mix({{Emotion::Joy, 0.5}, {Emotion::Surprise, 0.5}})},
        {"sadness", mix({{Emotion::Sadness, 1.0}})},
        {"disgust=0", mix({})},
        {"0.25 neutral + 0.75 disgust", mix({{Emotion::Disgust, 0.75}})},
        {"anger=+0.5", mix({{Emotion::Anger, 0.5}})},
        {"1 anger", mix({{Emotion::Anger, 1.0}})},
        {"joy=.2,sadness=.2,anger=.2,fear=.2,disgust=.1,surprise=.1",
         mix({{Emotion::Joy, .2}, {Emotion::Sadness, .2}, {Emotion::Anger, .2}, {Emotion::Fear, .2},
              {Emotion::Disgust, .1}, {Emotion::Surprise, .1}})},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        const EmotionMix m = parse_emotion_mix(c.text);
        for (int e = 0; e < kEmotionCount; ++e) EXPECT_NEAR(m.weights[e], c.expected.weights[e], 1e-12);
    }
    EXPECT_NEAR(parse_emotion_mix("anger=0.7,fear=0.3").neutral(), 0.0, 1e-12);
    EXPECT_NEAR(parse_emotion_mix("anger=0.2").neutral(), 0.8, 1e-12);
}

TEST(EmotionMix, RejectsWithMessagesThatNameThePart) {
    const std::string expected_names =
        "expected joy (or happiness), sadness, anger, fear, disgust, surprise, neutral or an action unit (AU4, AU12L)";
    struct Case {
        const char* text;
        std::string message;
    } cases[] = {
        {"", "expression: emotion mix \"\": empty; expected e.g. \"anger=0.7,fear=0.3\" or \"0.7 anger + 0.3 fear\""},
        {"   ", "expression: emotion mix \"   \": empty; expected e.g. \"anger=0.7,fear=0.3\" or \"0.7 anger + 0.3 fear\""},
        {"anger=0.7,fera=0.3",
         "expression: emotion mix \"anger=0.7,fera=0.3\": unknown emotion \"fera\" in part 2 (\"fera=0.3\"); " +
             expected_names},
        {"0.5 rage", "expression: emotion mix \"0.5 rage\": unknown emotion \"rage\" in part 1 (\"0.5 rage\"); " +
                         expected_names},
        {"anger=-0.3", "expression: emotion mix \"anger=-0.3\": part 1 (\"anger=-0.3\"): weight -0.3 is negative; "
                       "weights are in [0, 1]"},
        {"joy=1.5", "expression: emotion mix \"joy=1.5\": part 1 (\"joy=1.5\"): weight 1.5 is above 1; weights are "
                    "in [0, 1]"},
        {"anger=0.7,fear=0.5", "expression: emotion mix \"anger=0.7,fear=0.5\": weights sum to 1.2, more than 1 "
                               "(neutral takes 1 - sum); lower them or let the mix be normalised"},
        {"0.7 anger + 0.6 fear", "expression: emotion mix \"0.7 anger + 0.6 fear\": weights sum to 1.3, more than 1 "
                                 "(neutral takes 1 - sum); lower them or let the mix be normalised"},
        {"anger=0.2,anger=0.3", "expression: emotion mix \"anger=0.2,anger=0.3\": \"anger\" is given twice (parts 1 "
                                "and 2)"},
        {"joy=0.2 + happiness=0.1", "expression: emotion mix \"joy=0.2 + happiness=0.1\": \"joy\" is given twice "
                                    "(parts 1 and 2)"},
        {"anger=0.5,,fear=0.1", "expression: emotion mix \"anger=0.5,,fear=0.1\": part 2 is empty"},
        {"anger=0.5,", "expression: emotion mix \"anger=0.5,\": part 2 is empty"},
        {"anger=abc", "expression: emotion mix \"anger=abc\": part 1 (\"anger=abc\"): \"abc\" is not a number"},
        {"anger=", "expression: emotion mix \"anger=\": part 1 (\"anger=\"): expected \"name=weight\", \"weight "
                   "name\" or \"name\""},
        {"anger 0.7", "expression: emotion mix \"anger 0.7\": part 1 (\"anger 0.7\"): expected \"weight name\", the "
                      "name comes last"},
        {"0.3 0.4 fear", "expression: emotion mix \"0.3 0.4 fear\": part 1 (\"0.3 0.4 fear\"): expected "
                         "\"name=weight\", \"weight name\" or \"name\""},
        {"anger=nan", "expression: emotion mix \"anger=nan\": part 1 (\"anger=nan\"): \"nan\" is not a number"},
        // Not a number in float either: NaN and infinity spelt several ways.
        {"anger=inf", "expression: emotion mix \"anger=inf\": part 1 (\"anger=inf\"): \"inf\" is not a number"},
        {"anger=-Infinity", "expression: emotion mix \"anger=-Infinity\": part 1 (\"anger=-Infinity\"): "
                            "\"-Infinity\" is not a number"},
        {"1e999 joy", "expression: emotion mix \"1e999 joy\": part 1 (\"1e999 joy\"): \"1e999\" is not a number"},
        // The user's text comes back escaped and cut: one short line.
        {"joy\n+ fear\x1b[31m",
         "expression: emotion mix \"joy\\n+ fear\\x1b[31m\": unknown emotion \"fear\\x1b[31m\" in part 2; " +
             expected_names},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        testing::expect_error<InputError>([&] { parse_emotion_mix(c.text); }, c.message);
    }
}

TEST(EmotionMix, EchoesHugeNamesCut) {
    // A 120 KB unknown name is echoed as its first 60 (the mix) or 40 (a
    // part, a name) characters: the message stays one short line.
    const std::string expected_names =
        "expected joy (or happiness), sadness, anger, fear, disgust, surprise, neutral or an action unit (AU4, AU12L)";
    const std::string huge(120000, 'x');
    const std::string cut60 = std::string(60, 'x') + "\u2026", cut40 = std::string(40, 'x') + "\u2026";
    testing::expect_error<InputError>([&] { parse_emotion_mix(huge); },
                                      "expression: emotion mix \"" + cut60 + "\": unknown emotion \"" + cut40 +
                                          "\" in part 1; " + expected_names);
    const std::string au38 = "AU" + std::string(38, 'x') + "\u2026";
    testing::expect_error<InputError>([&] { parse_emotion_mix("AU" + huge); },
                                      "expression: emotion mix \"AU" + std::string(58, 'x') + "\u2026\": part 1 (\"" +
                                          au38 + "\"): \"" + au38 +
                                          "\" is not an action unit; expected AU<number>, AU<number>L or "
                                          "AU<number>R (e.g. AU12, AU12L)");
}

TEST(EmotionMix, AcceptsActionUnitsBesideEmotions) {
    struct Case {
        const char* text;
        Emotion emotion;  // weight below; Joy with 0 for none
        double weight;
        int au;
        double left, right;
    } cases[] = {
        {"0.6 joy + 0.3 AU4", Emotion::Joy, 0.6, 4, 0.3, 0.3},
        {"AU1+AU2", Emotion::Joy, 0.0, 1, 1.0, 1.0},
        {"AU1+AU2", Emotion::Joy, 0.0, 2, 1.0, 1.0},
        {"AU12L", Emotion::Joy, 0.0, 12, 1.0, 0.0},
        {"au12r=0.5", Emotion::Joy, 0.0, 12, 0.0, 0.5},
        {"0.2 AU12L + 0.7 AU12R, anger=0.4", Emotion::Anger, 0.4, 12, 0.2, 0.7},
        {"1 joy + 1 AU4", Emotion::Joy, 1.0, 4, 1.0, 1.0},  // AUs do not count in the sum
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        const EmotionMix m = parse_emotion_mix(c.text);
        EXPECT_NEAR(m[c.emotion], c.weight, 1e-12);
        EXPECT_NEAR(m.aus.left[c.au], c.left, 1e-12);
        EXPECT_NEAR(m.aus.right[c.au], c.right, 1e-12);
        EXPECT_EQ(parse_emotion_mix(m.to_string()), m) << m.to_string();
    }
    EXPECT_EQ(parse_emotion_mix("0.6 joy + 0.3 AU4").to_string(), "0.6 joy + 0.3 AU4");
    EXPECT_EQ(parse_emotion_mix("AU12L + 0.5 AU12R").to_string(), "1 AU12L + 0.5 AU12R");
    // Normalising divides the emotions only.
    const EmotionMix n = parse_emotion_mix("0.8 joy + 0.8 anger + 0.5 AU4", true);
    EXPECT_NEAR(n[Emotion::Joy], 0.5, 1e-12);
    EXPECT_NEAR(n.aus.left[4], 0.5, 1e-12);
}

TEST(EmotionMix, RejectsBadActionUnits) {
    struct Case {
        const char* text;
        std::string message;
    } cases[] = {
        {"AU12X", "expression: emotion mix \"AU12X\": part 1 (\"AU12X\"): \"AU12X\" is not an action unit; expected "
                  "AU<number>, AU<number>L or AU<number>R (e.g. AU12, AU12L)"},
        {"0.3 AU", "expression: emotion mix \"0.3 AU\": part 1 (\"0.3 AU\"): \"AU\" is not an action unit; expected "
                   "AU<number>, AU<number>L or AU<number>R (e.g. AU12, AU12L)"},
        {"AU0", "expression: emotion mix \"AU0\": part 1 (\"AU0\"): \"AU0\": action units are numbered 1..64"},
        {"AU99L", "expression: emotion mix \"AU99L\": part 1 (\"AU99L\"): \"AU99L\": action units are numbered 1..64"},
        {"AU12 + 0.5 AU12L", "expression: emotion mix \"AU12 + 0.5 AU12L\": AU12 is given twice (parts 1 and 2)"},
        {"AU12R + AU12", "expression: emotion mix \"AU12R + AU12\": AU12 is given twice (parts 1 and 2)"},
        {"1.5 AU4", "expression: emotion mix \"1.5 AU4\": part 1 (\"1.5 AU4\"): weight 1.5 is above 1; weights are "
                    "in [0, 1]"},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.text);
        testing::expect_error<InputError>([&] { parse_emotion_mix(c.text); }, c.message);
    }
}

TEST(EmotionMix, NormalisesWhenAsked) {
    const EmotionMix m = parse_emotion_mix("anger=0.8,fear=0.8", true);
    EXPECT_NEAR(m[Emotion::Anger], 0.5, 1e-12);
    EXPECT_NEAR(m[Emotion::Fear], 0.5, 1e-12);
    const EmotionMix n = parse_emotion_mix("1 joy + 1 neutral", true);
    EXPECT_NEAR(n[Emotion::Joy], 0.5, 1e-12);
    EXPECT_NEAR(n.neutral(), 0.5, 1e-12);
    // Below 1 nothing changes.
    EXPECT_NEAR(parse_emotion_mix("joy=0.3", true)[Emotion::Joy], 0.3, 1e-12);
}

TEST(EmotionMix, ToStringReadsBack) {
    EXPECT_EQ(EmotionMix{}.to_string(), "neutral");
    const EmotionMix m = mix({{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}});
    EXPECT_EQ(m.to_string(), "0.7 anger + 0.3 fear");
    EXPECT_EQ(parse_emotion_mix(m.to_string()), m);
    EXPECT_EQ(find_emotion("Happiness"), Emotion::Joy);
    EXPECT_FALSE(find_emotion("joyful"));
    for (Emotion e : kEmotions) EXPECT_EQ(find_emotion(emotion_name(e)), e);
}

TEST(Profiles, EmotionProfilesLoadWithReasoningAndDiffer) {
    const EmotionProfiles p = load_emotion_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/emotions.json");
    for (Emotion e : kEmotions) {
        SCOPED_TRACE(emotion_name(e));
        EXPECT_GT(p.reasoning[emotion_index(e)].size(), 100u);
        EXPECT_EQ(p[e][0], 0.0);
        EXPECT_EQ(p[e][1], 0.0);
    }
    // Signs the thesis (chapter 2.3) asks for.
    auto at = [&](Emotion e, int fap) { return p[e][fap - 1]; };
    EXPECT_GT(at(Emotion::Joy, 59), 0);        // lip corners up
    EXPECT_LT(at(Emotion::Sadness, 59), 0);    // corners down
    EXPECT_GT(at(Emotion::Sadness, 31), 0);    // inner brows up
    EXPECT_LT(at(Emotion::Anger, 31), 0);      // inner brows down
    EXPECT_GT(at(Emotion::Anger, 37), 0);      // and together
    EXPECT_GT(at(Emotion::Fear, 31), 0);       // brows up
    EXPECT_GT(at(Emotion::Disgust, 19), 0);    // eyes nearly closed
    EXPECT_LT(at(Emotion::Disgust, 4), 0);     // upper lip raised
    EXPECT_GT(at(Emotion::Surprise, 33), 0);   // brows as high as they go
    EXPECT_LT(at(Emotion::Surprise, 19), 0);   // lids wide open
    EXPECT_GT(at(Emotion::Surprise, 3), 0);    // mouth open
    const EmotionMix m = mix({{Emotion::Anger, 0.7}, {Emotion::Fear, 0.3}});
    const FapValues f = p.faps(m);
    EXPECT_NEAR(f[31 - 1], 0.7 * at(Emotion::Anger, 31) + 0.3 * at(Emotion::Fear, 31), 1e-9);
}

TEST(Profiles, VisemesAreMouthOnlyAndBlend) {
    const VisemeProfiles v = load_viseme_profiles(std::string(EMOFACE_DATA_DIR) + "/expression/visemes.json");
    for (int code = 1; code < kVisemeCount; ++code) {
        bool any = false;
        for (int f = 1; f <= fap::kFapCount; ++f) {
            if (v.profiles[code][f - 1] == 0.0) continue;
            any = true;
            EXPECT_TRUE(is_mouth_fap(f)) << "viseme " << code << " FAP " << f;
        }
        EXPECT_TRUE(any) << code;
    }
    // A: opens the jaw wider than p b m, which closes the lips.
    EXPECT_GT(v.profiles[10][3 - 1], v.profiles[1][3 - 1]);
    EXPECT_GT(v.profiles[1][5 - 1], 0);
    const FapValues half = v.faps({10, 1, 21, 0});  // 1/3 of viseme 10, 2/3 of viseme 1
    for (int f = 0; f < fap::kFapCount; ++f)
        EXPECT_NEAR(half[f], v.profiles[10][f] / 3.0 + v.profiles[1][f] * 2.0 / 3.0, 1e-9);
    const FapValues none = v.faps({0, 99, 63, 0});
    for (double x : none) EXPECT_EQ(x, 0.0);
}

TEST(Profiles, BadFilesNameTheEntry) {
    const auto dir = std::filesystem::temp_directory_path() / "emoface_profiles_test";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "emotions.json").string();
    const std::string aus_path = (dir / "action_units.json").string();
    std::filesystem::copy_file(std::string(EMOFACE_DATA_DIR) + "/expression/action_units.json", aus_path,
                               std::filesystem::copy_options::overwrite_existing);
    auto load = [&]() {
        try {
            load_emotion_profiles(path);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("(no error)");
    };
    const std::string five =
        R"("action_units": "action_units.json", "emotions": {
           "joy": {"reasoning": "r", "action_units": {"AU12": 1}}, "sadness": {"reasoning": "r", "action_units": {}},
           "anger": {"reasoning": "r", "action_units": {}}, "fear": {"reasoning": "r", "action_units": {}},
           "disgust": {"reasoning": "r", "action_units": {}})";
    struct Case {
        const char* what;
        std::string emotions;  // emotions.json
        std::string message;   // after "expression: <path>: "
    } cases[] = {
        {"no surprise", "{" + five + "}}", "emotions.surprise: expected a value, found no such key"},
        {"unknown AU", "{" + five + R"(, "surprise": {"reasoning": "r", "action_units": {"AU30": 1}}}})",
         "emotions.surprise.action_units.AU30: expected an AU of action_units.json (1, 2, 4, 5, 6, 7, 9, 10, 11, 12, "
         "13, 14, 15, 16, 17, 18, 20, 22, 23, 24, 25, 26, 27, 28, 29, 41, 43, 45, 46, 51, 52, 53, 54, 55, 56, 57, 58, "
         "61, 62, 63, 64), found \"AU30\""},
        {"AU with a side", "{" + five + R"(, "surprise": {"reasoning": "r", "action_units": {"AU1L": 1}}}})",
         "emotions.surprise.action_units.AU1L: expected a whole action unit \"AU<number>\" as the key, found \"AU1L\""},
        {"intensity", "{" + five + R"(, "surprise": {"reasoning": "r", "action_units": {"AU1": 1.5}}}})",
         "emotions.surprise.action_units.AU1: expected an intensity in (0, 1], found 1.5"},
        {"unknown key", "{" + five + R"(, "surprise": {"reasoning": "r", "action_units": {}, "faps": {}}}})",
         "emotions.surprise.faps: expected a known key (reasoning, action_units), found \"faps\""},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::ofstream(path) << c.emotions;
        EXPECT_EQ(load(), "expression: " + path + ": " + c.message);
    }
    std::filesystem::remove_all(dir);
}

TEST(ActionUnitTable, BadEntriesNameTheKey) {
    const auto dir = std::filesystem::temp_directory_path() / "emoface_action_units_test";
    std::filesystem::create_directories(dir);
    const std::string path = (dir / "action_units.json").string();
    const std::string regions =
        R"("regions": [{"name": "brows", "faps": [31, 32, 33, 34, 35, 36, 37, 38]}, {"name": "mouth", "faps": [59, 60]}])";
    auto au = [](const std::string& body) {
        return R"(, "action_units": {"AU1": {"name": "n", "muscle": "m", "reasoning": "r", )" + body + "}}}";
    };
    struct Case {
        const char* what;
        std::string text;
        std::string message;  // after "expression: <path>: "
    } cases[] = {
        {"asymmetric", "{" + regions + au(R"("region": "brows", "sides": true, "faps": {"31": 100, "32": 90})"),
         "action_units.AU1.faps: expected left-right symmetric values (a bilateral AU's halves mirror each other), "
         "found FAP 31 (raise_l_i_eyebrow) 100 but FAP 32 (raise_r_i_eyebrow) 90"},
        {"earlier region", "{" + regions + au(R"("region": "mouth", "sides": false, "faps": {"31": 100, "59": 10})"),
         "action_units.AU1.faps: expected FAPs of region \"mouth\" or of regions fitted after it, found FAP 31 "
         "(raise_l_i_eyebrow) of region \"brows\", fitted before"},
        {"unknown region", "{" + regions + au(R"("region": "ears", "sides": false, "faps": {})"),
         "action_units.AU1.region: expected the name of one of \"regions\", found \"ears\""},
        {"bad FAP", "{" + regions + au(R"("region": "brows", "sides": false, "faps": {"2": 1})"),
         "action_units.AU1.faps.2: expected a low-level FAP (3..68), found FAP 2 (expression)"},
        {"FAP in two regions",
         R"({"regions": [{"name": "a", "faps": [31]}, {"name": "b", "faps": [31]}], "action_units": {}})",
         "regions[1].faps: expected each FAP in one region, found FAP 31 also in \"a\""},
        {"bad AU key", "{" + regions + R"(, "action_units": {"AU12X": {}}})",
         "action_units.AU12X: expected an action unit key \"AU<number>\", found \"AU12X\""},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::ofstream(path) << c.text;
        try {
            load_action_units(path);
            ADD_FAILURE() << "accepted";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()), "expression: " + path + ": " + c.message);
        }
    }
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace emoface::expression
