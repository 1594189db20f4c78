#include "emoface/fap/fap_frame.h"

#include "emoface/common/error.h"

namespace emoface::fap {

namespace {

std::size_t checked_index(int fap, const char* function, int first = 1) {
    if (fap < first || fap > kFapCount)
        fail("fap: FapFrame::{}: expected a FAP number {}..{}, found {}", function, first, kFapCount,
             fap);
    return static_cast<std::size_t>(fap - 1);
}

constexpr std::array<std::string_view, kExpressionCodeCount> kExpressionNames{
    "neutral", "joy", "sadness", "anger", "fear", "disgust", "surprise"};
constexpr std::array<std::string_view, kVisemeCodeCount> kVisemeNames{
    "none", "p b m", "f v", "T D", "t d", "k g", "tS dZ S", "s z", "n l", "r", "A:", "e", "I", "Q", "U"};

}  // namespace

std::string_view expression_name(int code) {
    return code >= 0 && code < kExpressionCodeCount ? kExpressionNames[static_cast<std::size_t>(code)]
                                                    : std::string_view{};
}

std::string_view viseme_name(int code) {
    return code >= 0 && code < kVisemeCodeCount ? kVisemeNames[static_cast<std::size_t>(code)]
                                                : std::string_view{};
}

bool operator==(const Viseme& a, const Viseme& b) {
    return a.select1 == b.select1 && a.select2 == b.select2 && a.blend == b.blend && a.def == b.def;
}
bool operator!=(const Viseme& a, const Viseme& b) { return !(a == b); }

bool operator==(const Expression& a, const Expression& b) {
    return a.select1 == b.select1 && a.intensity1 == b.intensity1 && a.select2 == b.select2 &&
           a.intensity2 == b.intensity2 && a.init_face == b.init_face && a.def == b.def;
}
bool operator!=(const Expression& a, const Expression& b) { return !(a == b); }

bool FapFrame::has(int fap) const { return mask[checked_index(fap, "has")]; }

double FapFrame::get(int fap) const { return values[checked_index(fap, "get")]; }

void FapFrame::set(int fap, double value) {
    // FAP 1 and 2 are structs, not numbers.
    const std::size_t i = checked_index(fap, "set", 3);
    values[i] = value;
    mask.set(i);
}

void FapFrame::set_viseme(const Viseme& v) {
    viseme = v;
    mask.set(0);
}

void FapFrame::set_expression(const Expression& e) {
    expression = e;
    mask.set(1);
}

void FapFrame::clear(int fap) {
    const std::size_t i = checked_index(fap, "clear");
    mask.reset(i);
    values[i] = 0;
    if (fap == 1) viseme = Viseme{};
    if (fap == 2) expression = Expression{};
}

bool operator==(const FapFrame& a, const FapFrame& b) {
    if (a.number != b.number || a.mask != b.mask) return false;
    if (a.mask[0] && a.viseme != b.viseme) return false;
    if (a.mask[1] && a.expression != b.expression) return false;
    for (std::size_t i = 2; i < a.values.size(); ++i)
        if (a.mask[i] && a.values[i] != b.values[i]) return false;
    return true;
}
bool operator!=(const FapFrame& a, const FapFrame& b) { return !(a == b); }

}  // namespace emoface::fap
