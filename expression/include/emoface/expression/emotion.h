#pragma once
// Ekman emotion mixtures: "0.7 anger + 0.3 fear" (DESIGN.md, "Emotion
// mixtures"). Each of the six weights is in [0, 1]; neutral takes 1 - sum.
// A mix may add FACS Action Units beside the emotions ("0.6 joy + 0.3 AU4",
// "AU12L"): they are shown on top and do not count in the sum.
#include <array>
#include <optional>
#include <string>
#include <string_view>

#include "emoface/expression/action_units.h"

namespace emoface::expression {

// Numbered as FAP 2's expression codes (1..6); 0 is neutral there.
enum class Emotion { Joy = 1, Sadness = 2, Anger = 3, Fear = 4, Disgust = 5, Surprise = 6 };
inline constexpr int kEmotionCount = 6;
inline constexpr std::array<Emotion, kEmotionCount> kEmotions{Emotion::Joy,  Emotion::Sadness, Emotion::Anger,
                                                              Emotion::Fear, Emotion::Disgust, Emotion::Surprise};

// 0..5, the position in EmotionMix::weights.
constexpr int emotion_index(Emotion e) { return static_cast<int>(e) - 1; }
// "joy", "sadness", "anger", "fear", "disgust", "surprise".
const char* emotion_name(Emotion e);
// The names above, plus "happiness" for joy (ASCII case-insensitive).
std::optional<Emotion> find_emotion(std::string_view name);

struct EmotionMix {
    std::array<double, kEmotionCount> weights{};  // by emotion_index()
    AuIntensities aus;                            // added on top of the emotions' own AUs

    double& operator[](Emotion e) { return weights[emotion_index(e)]; }
    double operator[](Emotion e) const { return weights[emotion_index(e)]; }
    double sum() const;
    double neutral() const { return 1.0 - sum(); }
    // "0.7 anger + 0.3 fear + 0.5 AU12L" (emotions in enum order, then the
    // AUs; zero weights left out); "neutral" for an empty mix.
    // parse_emotion_mix() reads it back.
    std::string to_string() const;
};

bool operator==(const EmotionMix& a, const EmotionMix& b);
bool operator!=(const EmotionMix& a, const EmotionMix& b);

// Parses a mix. Parts are separated by ',' or '+'; a part is "name=weight",
// "weight name" or a bare "name" (weight 1); "neutral" may be named too (its
// weight counts in the sum). Names are those of find_emotion() or action
// units "AU4", "AU12L", "AU12R" (parse_au_term; whether the face has the AU
// is checked where the mix is shown, against the AU table).
// Throws emoface::InputError, message starting
//   expression: emotion mix "<text>": ...
// for an empty text or part, a part that is none of the forms, an unknown
// name, a malformed AU ("AU12X"), a weight that is not a number, negative or
// above 1, an emotion or AU side given twice, and an emotion sum above 1
// unless `normalise` (then all emotion weights, neutral's too, are divided by
// their sum; a sum of 1 or less is kept as given; AUs are kept as given).
EmotionMix parse_emotion_mix(std::string_view text, bool normalise = false);

}  // namespace emoface::expression
