#include "au_label.h"

namespace emoface::apps {

std::string au_label(const expression::AuIntensities& aus) {
    // to_string keeps intensities above its threshold; a hair under 0.1 keeps
    // 0.1 itself.
    return aus.to_string(kShownAuIntensity - 1e-9);
}

}  // namespace emoface::apps
