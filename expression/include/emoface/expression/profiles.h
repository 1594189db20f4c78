#pragma once
// FAP profiles. Each emotion is a FACS prototype: AU intensities
// (data/expression/emotions.json, with the reasoning behind each) over the
// AU table (data/expression/action_units.json), so its FAPs are the sum of
// its AUs'. Visemes are one mouth-only FAP vector per MPEG-4 viseme
// (data/expression/visemes.json).
#include <array>
#include <string>

#include "emoface/expression/action_units.h"
#include "emoface/expression/emotion.h"
#include "emoface/expression/fap_values.h"
#include "emoface/fap/fap_frame.h"

namespace emoface::expression {

struct EmotionProfiles {
    ActionUnitTable action_units;
    std::array<AuIntensities, kEmotionCount> prototypes{};  // by emotion_index(): AUs at weight 1
    std::array<FapValues, kEmotionCount> profiles{};        // the prototypes' FAPs
    // Each profile's FAPs read back into AUs (ActionUnitTable::infer): the
    // prototype as a frame's AUs would show it (an AU the FAPs cannot tell
    // apart is read as the one they can), for mix_from_action_units.
    std::array<AuIntensities, kEmotionCount> inferred_prototypes{};
    std::array<std::string, kEmotionCount> reasoning;

    const FapValues& operator[](Emotion e) const { return profiles[emotion_index(e)]; }
    // The mix's AUs: Σ weight × prototype over the emotions plus the mix's
    // own AUs, each at most 1 (FACS "E"). Throws emoface::InputError for an
    // AU the table lacks or a side given on a midline AU.
    AuIntensities action_units_of(const EmotionMix& mix) const;
    // The mix's low-level FAPs: the FAPs of action_units_of(mix), which for
    // a mix of emotions alone is Σ weight × profile.
    FapValues faps(const EmotionMix& mix) const;
    // The emotions a face's AUs show: the weights w in [0, 1] whose
    // Σ w × inferred prototype is nearest `aus` (least squares over the AUs,
    // each side apart, that some prototype has), each times the share of
    // its prototype the face shows at that weight (an AU counting by its
    // prototype intensity, in full at w × that intensity or more), scaled
    // down to sum 1 if they sum over 1. A whole prototype keeps its weight;
    // one AU that several prototypes share (a speaking mouth's AU15) gives
    // little. AUs no emotion uses count for nothing.
    EmotionMix mix_from_action_units(const AuIntensities& aus) const;
};

// Reads data/expression/emotions.json: {"action_units": "action_units.json"
// (beside it), "emotions": {"joy": {"reasoning": "...", "action_units":
// {"AU6": 0.8, "AU12": 1}}, ...}} with all six emotions; intensities in
// (0, 1], whole AUs only (prototypes are symmetric). Throws
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
