#pragma once
// What a face shows in one frame (DESIGN.md, "One frame"): its low-level
// FAPs (which drive the rig), its FACS Action Units per side, its emotion
// mixture (which drives the wrinkles) and its viseme.
#include <bitset>

#include "emoface/expression/emotion.h"
#include "emoface/expression/fap_values.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/fap_frame.h"

namespace emoface::expression {

enum class MixSource {
    None,        // no emotion: neutral
    Expression,  // from FAP 2 (intensity / 63 of each selected emotion)
    FromActionUnits,  // derived from the frame's AUs (EmotionProfiles::mix_from_action_units)
    Given,            // set by the caller (face_state(const EmotionMix&, ...))
};
const char* mix_source_name(MixSource s);

struct FaceState {
    FapValues faps{};               // low-level FAPs 3..68 for the rig
    std::bitset<fap::kFapCount> mask;  // which of them the frame gave or were synthesised
    AuIntensities aus;              // the FACS Action Units the face shows, per side
    EmotionMix mix;                 // emotion weights only (its `aus` stay empty)
    MixSource mix_source = MixSource::None;
    bool has_viseme = false;
    fap::Viseme viseme;
};

// The state of one frame; pass frames resolved for untransmitted FAPs
// (fap::FapStream::resolved / sample) so the mask holds every FAP in effect.
//  - faps: the frame's transmitted low-level values;
//  - aus: inferred from the low-level FAPs, region by region and side by side
//    (ActionUnitTable::infer), when the frame has any; otherwise the AUs of
//    the mix from FAP 2;
//  - mix: from FAP 2 when transmitted (select1 at intensity1 / 63, select2 at
//    intensity2 / 63, summed if both name one emotion, scaled down if they
//    sum over 1); otherwise derived from the inferred AUs
//    (EmotionProfiles::mix_from_action_units), if there are any;
//  - a frame with FAP 2 and no low-level FAPs gets them synthesised from the
//    mix's AUs, so the mesh moves too;
//  - with `visemes`, a frame with FAP 1 and no mouth FAPs of its own gets the
//    viseme's mouth FAPs added.
FaceState face_state(const fap::FapFrame& frame, const EmotionProfiles& emotions,
                     const VisemeProfiles* visemes = nullptr);

// The state that shows `mix`: aus = its emotions' prototypes plus its own
// AUs (EmotionProfiles::action_units_of), faps = their FAPs (the mask: every
// FAP an emotion profile or the state's AUs set). mix: the given emotion
// weights (MixSource::Given); for a mix with AUs of its own, derived from
// all its AUs (MixSource::FromActionUnits), so "AU1+AU2" drives the
// wrinkles as a surprise does. Throws emoface::InputError for an AU the
// table lacks.
FaceState face_state(const EmotionMix& mix, const EmotionProfiles& emotions);

}  // namespace emoface::expression
