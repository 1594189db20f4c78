#pragma once
// What a face shows in one frame (DESIGN.md, "One frame"): its low-level
// FAPs (which drive the rig), its emotion mixture (which drives the
// wrinkles) and its viseme.
#include <bitset>

#include "emoface/expression/emotion.h"
#include "emoface/expression/fap_values.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/fap_frame.h"

namespace emoface::expression {

enum class MixSource {
    None,        // no emotion: neutral
    Expression,  // from FAP 2 (intensity / 63 of each selected emotion)
    Fitted,      // inferred from the low-level FAPs (non-negative least squares)
    Given,       // set by the caller (face_state(const EmotionMix&, ...))
};
const char* mix_source_name(MixSource s);

struct FaceState {
    FapValues faps{};               // low-level FAPs 3..68 for the rig
    std::bitset<fap::kFapCount> mask;  // which of them the frame gave or were synthesised
    EmotionMix mix;
    MixSource mix_source = MixSource::None;
    bool has_viseme = false;
    fap::Viseme viseme;
};

// The state of one frame; pass frames resolved for untransmitted FAPs
// (fap::FapStream::resolved / sample) so the mask holds every FAP in effect.
//  - faps: the frame's transmitted low-level values;
//  - mix: from FAP 2 when transmitted (select1 at intensity1 / 63, select2 at
//    intensity2 / 63, summed if both name one emotion, scaled down if they
//    sum over 1); otherwise the NNLS fit of the low-level FAPs onto the six
//    profiles (fit_emotion_mix), if there are any;
//  - a frame with FAP 2 and no low-level FAPs gets them synthesised from the
//    mix's profiles, so the mesh moves too;
//  - with `visemes`, a frame with FAP 1 and no mouth FAPs of its own gets the
//    viseme's mouth FAPs added.
FaceState face_state(const fap::FapFrame& frame, const EmotionProfiles& emotions,
                     const VisemeProfiles* visemes = nullptr);

// The state that shows `mix`: its profiles' FAPs (every FAP any profile sets
// in the mask).
FaceState face_state(const EmotionMix& mix, const EmotionProfiles& emotions);

// The mix whose profiles best explain `faps` over the FAPs in `mask` that
// some profile sets: min |A w - b| with w >= 0 (Lawson-Hanson NNLS), scaled
// down to sum 1 if it sums over 1. Empty overlap: neutral.
EmotionMix fit_emotion_mix(const FapValues& faps, const std::bitset<fap::kFapCount>& mask,
                           const EmotionProfiles& emotions);

}  // namespace emoface::expression
