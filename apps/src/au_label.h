#pragma once
// The FACS Action Units of a face as one line of text, the same in `info`,
// `inspect`'s title and the viewer's panel. Built in every build (info draws
// nothing), so it lives apart from session.h.
#include <string>

#include "emoface/expression/action_units.h"
#include "emoface/expression/emotion.h"
#include "emoface/expression/face_state.h"

namespace emoface::apps {

// AUs below this are not listed: traces a fit leaves from speech or noise.
inline constexpr double kShownAuIntensity = 0.1;

// "1 AU1 + 0.8 AU6L + 0.6 AU6R": AUs in number order at kShownAuIntensity
// and above, both sides as one term where they are equal, "L"/"R" terms where
// they differ; "none" when nothing is left (AuIntensities::to_string).
std::string au_label(const expression::AuIntensities& aus);

// "0.70 anger + 0.30 fear + 0.3 AU4" (emotions with two decimals, then the
// mix's own AU terms; "neutral" for none): for labels. parse_emotion_mix
// reads it back.
std::string mix_label(const expression::EmotionMix& mix);

// A frame's description in two lines (inspect's title). `where`: the frame
// ("tour.fap frame 12/49"), "" for a --mix; `given`: the --mix given, if any
// (named when it has emotions beside its AUs).
// Where the emotion mix was derived from the AUs (a frame of low-level FAPs,
// a --mix with AU terms), the AUs are what the face shows: they come first,
// and the mix follows labelled as derived (it drives the wrinkles). Else the
// mix comes first, with its source for a frame, and the AUs second.
struct FrameTitle {
    std::string first, second;
};
FrameTitle frame_title(const std::string& where, const expression::FaceState& state,
                       const expression::EmotionMix* given = nullptr);

}  // namespace emoface::apps
