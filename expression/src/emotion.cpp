#include "emoface/expression/emotion.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <vector>

#include "emoface/common/error.h"

namespace emoface::expression {
namespace {

std::string lower(std::string_view s) {
    std::string out(s);
    for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return out;
}

std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
}

bool is_number_start(std::string_view s) {
    return !s.empty() && (std::isdigit(static_cast<unsigned char>(s[0])) || s[0] == '.' || s[0] == '-' || s[0] == '+');
}

bool parse_number(std::string_view s, double* out) {
    if (!s.empty() && s[0] == '+') s.remove_prefix(1);
    const char* end = s.data() + s.size();
    auto [p, ec] = std::from_chars(s.data(), end, *out);
    return !s.empty() && ec == std::errc() && p == end && std::isfinite(*out);
}

constexpr const char* kExpected =
    "expected joy (or happiness), sadness, anger, fear, disgust, surprise, neutral or an action unit (AU4, AU12L)";

}  // namespace

const char* emotion_name(Emotion e) {
    switch (e) {
        case Emotion::Joy: return "joy";
        case Emotion::Sadness: return "sadness";
        case Emotion::Anger: return "anger";
        case Emotion::Fear: return "fear";
        case Emotion::Disgust: return "disgust";
        case Emotion::Surprise: return "surprise";
    }
    return "?";
}

std::optional<Emotion> find_emotion(std::string_view name) {
    const std::string n = lower(name);
    if (n == "happiness") return Emotion::Joy;
    for (Emotion e : kEmotions)
        if (n == emotion_name(e)) return e;
    return std::nullopt;
}

double EmotionMix::sum() const {
    double s = 0;
    for (double w : weights) s += w;
    return s;
}

std::string EmotionMix::to_string() const {
    std::string out;
    for (Emotion e : kEmotions) {
        const double w = (*this)[e];
        if (w == 0.0) continue;
        if (!out.empty()) out += " + ";
        out += fmt::format("{:g} {}", w, emotion_name(e));
    }
    if (!aus.empty()) out += (out.empty() ? "" : " + ") + aus.to_string();
    return out.empty() ? "neutral" : out;
}

bool operator==(const EmotionMix& a, const EmotionMix& b) { return a.weights == b.weights && a.aus == b.aus; }
bool operator!=(const EmotionMix& a, const EmotionMix& b) { return !(a == b); }

EmotionMix parse_emotion_mix(std::string_view text, bool normalise) {
    // The user's text, cut and with control characters escaped: one short line.
    const std::string shown = echo_input(text, 60);
    auto bad = [&](const std::string& what) { fail<InputError>("expression: emotion mix \"{}\": {}", shown, what); };
    if (trim(text).empty()) bad("empty; expected e.g. \"anger=0.7,fear=0.3\" or \"0.7 anger + 0.3 fear\"");

    std::vector<std::string_view> parts;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i)
        if (i == text.size() || text[i] == ',' || text[i] == '+') {
            // A '+' right after '=' is a sign ("anger=+0.5"), not a separator.
            if (i < text.size() && text[i] == '+') {
                const std::string_view before = trim(text.substr(start, i - start));
                if (!before.empty() && before.back() == '=') continue;
            }
            parts.push_back(text.substr(start, i - start));
            start = i + 1;
        }

    EmotionMix mix;
    double neutral = 0.0;
    std::array<int, kEmotionCount + 1> given_in{};  // part number (1-based) per emotion, [6] = neutral
    std::array<int, kAuNumberLimit> au_left_in{}, au_right_in{};  // part number per AU side
    for (std::size_t k = 0; k < parts.size(); ++k) {
        const std::string_view part = trim(parts[k]);
        const int number = static_cast<int>(k) + 1;
        if (part.empty()) bad(fmt::format("part {} is empty", number));
        const std::string where = fmt::format("part {} (\"{}\")", number, echo_input(part, 40));
        std::string_view name, weight;
        const auto eq = part.find('=');
        if (eq != std::string_view::npos) {
            name = trim(part.substr(0, eq));
            weight = trim(part.substr(eq + 1));
        } else {
            const auto space = part.find_first_of(" \t*");
            if (space == std::string_view::npos) {
                name = part;
            } else {
                weight = trim(part.substr(0, space));
                name = trim(part.substr(space + 1));
                if (!name.empty() && name[0] == '*') name = trim(name.substr(1));
            }
        }
        if (name.empty() || name.find_first_of(" \t=*") != std::string_view::npos || (eq != std::string_view::npos && weight.empty()))
            bad(where + ": expected \"name=weight\", \"weight name\" or \"name\"");
        double w = 1.0;
        if (!weight.empty() && !parse_number(weight, &w)) {
            if (eq == std::string_view::npos && is_number_start(name)) bad(where + ": expected \"weight name\", the name comes last");
            bad(fmt::format("{}: \"{}\" is not a number", where, echo_input(weight, 40)));
        }
        std::string au_error;
        const auto au = parse_au_term(name, &au_error);
        if (!au_error.empty()) bad(fmt::format("{}: {}", where, au_error));
        const bool is_neutral = lower(name) == "neutral";
        const auto e = find_emotion(name);
        if (!e && !is_neutral && !au) {
            // The part is shown only when it says more than the name.
            const std::string in = name == part ? fmt::format("part {}", number) : where;
            bad(fmt::format("unknown emotion \"{}\" in {}; {}", echo_input(name, 40), in, kExpected));
        }
        if (w < 0) bad(fmt::format("{}: weight {:g} is negative; weights are in [0, 1]", where, w));
        if (w > 1) bad(fmt::format("{}: weight {:g} is above 1; weights are in [0, 1]", where, w));
        if (au) {
            const bool left = au->side != AuSide::Right, right = au->side != AuSide::Left;
            const int before = left && au_left_in[au->number] ? au_left_in[au->number]
                                                              : (right ? au_right_in[au->number] : 0);
            if (before != 0)
                bad(fmt::format("AU{} is given twice (parts {} and {})", au->number, before, number));
            if (left) {
                au_left_in[au->number] = number;
                mix.aus.left[au->number] = w;
            }
            if (right) {
                au_right_in[au->number] = number;
                mix.aus.right[au->number] = w;
            }
            continue;
        }
        const int slot = is_neutral ? kEmotionCount : emotion_index(*e);
        if (given_in[slot] != 0)
            bad(fmt::format("\"{}\" is given twice (parts {} and {})", is_neutral ? "neutral" : emotion_name(*e),
                            given_in[slot], number));
        given_in[slot] = number;
        if (is_neutral) neutral = w;
        else mix[*e] = w;
    }
    const double total = mix.sum() + neutral;
    if (total > 1.0 + 1e-9 && normalise) {
        for (double& w : mix.weights) w /= total;
    } else if (total > 1.0 + 1e-9) {
        bad(fmt::format("weights sum to {:g}, more than 1 (neutral takes 1 - sum); lower them or let the mix be "
                        "normalised",
                        total));
    }
    return mix;
}

}  // namespace emoface::expression
