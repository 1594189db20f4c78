// libFuzzer target for emotion mixes ("0.7 anger + 0.3 fear", "AU12L"): the
// first byte picks normalisation, the rest is the text. Any input may fail
// with emoface::InputError in one bounded line, nothing else; a mix that
// parses has weights in [0, 1] summing to at most 1, and its to_string()
// parses again to the same emotions and AUs.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace emoface::expression;
    if (size == 0) return 0;
    const bool normalise = data[0] & 1;
    const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
    EmotionMix mix;
    try {
        mix = parse_emotion_mix(text, normalise);
    } catch (const emoface::InputError& e) {
        const std::string line = emoface::error_line(e);
        if (line.size() > emoface::kMaxErrorLine || line.find('\n') != std::string::npos) std::abort();
        return 0;
    }
    for (double w : mix.weights)
        if (!(w >= 0.0 && w <= 1.0)) std::abort();
    if (!(mix.sum() <= 1.0 + 1e-9)) std::abort();
    // The text form reads back (weights printed with 6 digits: compared loosely).
    const EmotionMix again = parse_emotion_mix(mix.to_string(), true);
    for (int e = 0; e < kEmotionCount; ++e)
        if (std::abs(again.weights[e] - mix.weights[e]) > 1e-5) std::abort();
    return 0;
}
