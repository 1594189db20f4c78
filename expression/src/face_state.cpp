#include "emoface/expression/face_state.h"

#include <algorithm>

namespace emoface::expression {

const char* mix_source_name(MixSource s) {
    switch (s) {
        case MixSource::None: return "none";
        case MixSource::Expression: return "expression (FAP 2)";
        case MixSource::FromActionUnits: return "from the action units";
        case MixSource::Given: return "given";
    }
    return "?";
}

FaceState face_state(const EmotionMix& mix, const EmotionProfiles& emotions) {
    FaceState s;
    s.aus = emotions.action_units_of(mix);
    s.faps = emotions.action_units.faps(s.aus);
    for (int f = 3; f <= fap::kFapCount; ++f) {
        bool set = s.faps[f - 1] != 0.0;
        for (const FapValues& p : emotions.profiles) set |= p[f - 1] != 0.0;
        s.mask[f - 1] = set;
    }
    s.mix.weights = mix.weights;
    s.mix_source = MixSource::Given;
    if (!mix.aus.empty()) {
        s.mix = emotions.mix_from_action_units(s.aus);
        s.mix_source = MixSource::FromActionUnits;
    }
    return s;
}

FaceState face_state(const fap::FapFrame& frame, const EmotionProfiles& emotions, const VisemeProfiles* visemes) {
    FaceState s;
    bool any_low = false, any_mouth = false;
    for (int f = 3; f <= fap::kFapCount; ++f) {
        if (!frame.has(f)) continue;
        s.faps[f - 1] = frame.get(f);
        s.mask[f - 1] = true;
        any_low = true;
        any_mouth |= is_mouth_fap(f);
    }
    if (any_low) s.aus = emotions.action_units.infer(s.faps, s.mask);
    if (frame.has(2)) {
        const fap::Expression& x = frame.expression;
        auto add = [&](int code, int intensity) {
            if (code < 1 || code > kEmotionCount) return;  // 0 neutral; unknown codes ignored
            s.mix.weights[code - 1] += std::clamp(intensity, 0, fap::kMaxIntensity) / double(fap::kMaxIntensity);
        };
        add(x.select1, x.intensity1);
        add(x.select2, x.intensity2);
        const double sum = s.mix.sum();
        if (sum > 1.0)
            for (double& w : s.mix.weights) w /= sum;
        s.mix_source = s.mix.sum() > 0 ? MixSource::Expression : MixSource::None;
        if (!any_low) {
            const FaceState synth = face_state(s.mix, emotions);
            s.faps = synth.faps;
            s.mask = synth.mask;
            s.aus = synth.aus;
        }
    } else if (any_low) {
        s.mix = emotions.mix_from_action_units(s.aus);
        s.mix_source = s.mix.sum() > 0 ? MixSource::FromActionUnits : MixSource::None;
    }
    if (frame.has(1)) {
        s.has_viseme = true;
        s.viseme = frame.viseme;
        if (visemes && !any_mouth) {
            const FapValues v = visemes->faps(frame.viseme);
            for (int f = 3; f <= fap::kFapCount; ++f)
                if (v[f - 1] != 0.0) {
                    s.faps[f - 1] += v[f - 1];
                    s.mask[f - 1] = true;
                }
        }
    }
    return s;
}

}  // namespace emoface::expression
