#include "au_label.h"

#include <cmath>

#include <fmt/format.h>

namespace emoface::apps {

std::string au_label(const expression::AuIntensities& aus) {
    // Shown to two decimals, as the mix is (to_string writes every digit, so
    // that a mix string reads back exactly). Its threshold keeps intensities
    // above it; a hair under 0.1 keeps 0.1 itself.
    expression::AuIntensities shown = aus;
    for (auto* side : {&shown.left, &shown.right})
        for (double& w : *side) w = std::round(w * 100.0) / 100.0;
    return shown.to_string(kShownAuIntensity - 1e-9);
}

std::string mix_label(const expression::EmotionMix& mix) {
    std::string out;
    for (const expression::Emotion e : expression::kEmotions) {
        const double w = mix[e];
        if (!(w >= 0.005)) continue;
        out += fmt::format("{}{:.2f} {}", out.empty() ? "" : " + ", w, expression::emotion_name(e));
    }
    const std::string aus = mix.aus.to_string();
    if (aus != "none") out += (out.empty() ? "" : " + ") + aus;
    return out.empty() ? "neutral" : out;
}

FrameTitle frame_title(const std::string& where, const expression::FaceState& state,
                       const expression::EmotionMix* given) {
    // What the frame is: the file's frame, or the mix asked for.
    std::string what = where;
    if (given && given->sum() > 0 && state.mix_source == expression::MixSource::FromActionUnits)
        what = (what.empty() ? "" : what + "   ") + "mix " + mix_label(*given);
    auto after = [&](const std::string& text) { return what.empty() ? text : what + "   " + text; };
    if (state.mix_source == expression::MixSource::FromActionUnits)
        return {after("AUs " + au_label(state.aus)),
                "derived mix " + mix_label(state.mix) + " (from the AUs; it drives the wrinkles)"};
    std::string mix = "mix " + mix_label(state.mix);
    if (!where.empty()) mix += fmt::format(" [{}]", expression::mix_source_name(state.mix_source));
    return {after(mix), "AUs: " + au_label(state.aus)};
}

}  // namespace emoface::apps
