#pragma once
// The FACS Action Units of a face as one line of text, the same in `info`,
// `inspect`'s title and the viewer's panel. Built in every build (info draws
// nothing), so it lives apart from session.h.
#include <string>

#include "emoface/expression/action_units.h"

namespace emoface::apps {

// AUs below this are not listed: traces a fit leaves from speech or noise.
inline constexpr double kShownAuIntensity = 0.1;

// "1 AU1 + 0.8 AU6L + 0.6 AU6R": AUs in number order at kShownAuIntensity
// and above, both sides as one term where they are equal, "L"/"R" terms where
// they differ; "none" when nothing is left (AuIntensities::to_string).
std::string au_label(const expression::AuIntensities& aus);

}  // namespace emoface::apps
