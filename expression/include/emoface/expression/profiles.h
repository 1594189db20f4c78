#pragma once
// FAP profiles: one low-level FAP vector per emotion at full intensity
// (data/expression/emotions.json, with the reasoning behind each) and one
// mouth-only vector per MPEG-4 viseme (data/expression/visemes.json).
#include <array>
#include <string>

#include "emoface/expression/emotion.h"
#include "emoface/expression/fap_values.h"
#include "emoface/fap/fap_frame.h"

namespace emoface::expression {

struct EmotionProfiles {
    std::array<FapValues, kEmotionCount> profiles{};  // by emotion_index()
    std::array<std::string, kEmotionCount> reasoning;

    const FapValues& operator[](Emotion e) const { return profiles[emotion_index(e)]; }
    // The mix's low-level FAPs: sum over emotions of weight x profile.
    FapValues faps(const EmotionMix& mix) const;
};

// Reads data/expression/emotions.json: {"emotions": {"joy": {"reasoning":
// "...", "faps": {"raise_l_cornerlip_o": 220, ...}}, ...}} with all six
// emotions; FAPs by name or number, low-level only (3..68). Throws
// emoface::InputError naming the file and the entry.
EmotionProfiles load_emotion_profiles(const std::string& path);

// Visemes by FAP 1 code: 0 none (all zero), 1 "p b m" ... 14 "U".
inline constexpr int kVisemeCount = fap::kVisemeCodeCount;

struct VisemeProfiles {
    std::array<FapValues, kVisemeCount> profiles{};
    // FAP 1's mouth: select1 x blend/63 + select2 x (1 - blend/63); codes
    // outside 0..14 count as none, blend is clamped to 0..63.
    FapValues faps(const fap::Viseme& viseme) const;
};

// The FAPs a viseme may set: jaw, lips, chin and tongue (3-18, 43-47, 51-60).
bool is_mouth_fap(int fap);

// Reads data/expression/visemes.json: {"visemes": {"1": {"phonemes": "p b m",
// "faps": {...}}, ...}} for codes 1..14, mouth FAPs only.
VisemeProfiles load_viseme_profiles(const std::string& path);

}  // namespace emoface::expression
