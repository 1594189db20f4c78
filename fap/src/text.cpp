#include "text.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include <fmt/format.h>

namespace emoface::fap::detail {

std::string_view trim(std::string_view s) {
    std::size_t b = 0, e = s.size();
    while (b < e && is_space(s[b])) ++b;
    while (e > b && is_space(s[e - 1])) --e;
    return s.substr(b, e - b);
}

std::string quoted(std::string_view token) {
    constexpr std::size_t kShown = 40;
    std::string out = "'";
    for (std::size_t i = 0; i < token.size() && i < kShown; ++i) {
        const auto c = static_cast<unsigned char>(token[i]);
        if (c < 0x20 || c >= 0x7f || c == '\'' || c == '\\')
            out += fmt::format("\\x{:02x}", c);
        else
            out += static_cast<char>(c);
    }
    if (token.size() > kShown) out += "...";
    out += "'";
    return out;
}

bool LineReader::next(std::string_view& line, long long& line_number) {
    if (pos_ >= text_.size()) return false;
    std::size_t end = pos_;
    while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
    line = text_.substr(pos_, end - pos_);
    line_number = ++line_;
    if (end < text_.size() && text_[end] == '\r' && end + 1 < text_.size() && text_[end + 1] == '\n')
        pos_ = end + 2;
    else
        pos_ = end + 1;
    return true;
}

bool LineReader::next_content(std::string_view& line, long long& line_number) {
    while (next(line, line_number)) {
        const std::string_view content = trim(line);
        if (!content.empty() && content[0] != '#') return true;
    }
    return false;
}

namespace {

// For a well-formed decimal that a double cannot hold: true when it is too
// small (|x| < 1e-300 or so), false when too large. Decided by the position
// of its first significant digit plus its exponent.
bool underflows(std::string_view number) {
    if (!number.empty() && number[0] == '-') number.remove_prefix(1);
    const std::size_t e = number.find_first_of("eE");
    const std::string_view mantissa = number.substr(0, e);
    long long exponent = 0;
    if (e != std::string_view::npos) {
        std::string_view exp_text = number.substr(e + 1);
        if (!exp_text.empty() && exp_text[0] == '+') exp_text.remove_prefix(1);
        auto [end, ec] = std::from_chars(exp_text.data(), exp_text.data() + exp_text.size(), exponent);
        if (ec == std::errc::result_out_of_range) return exp_text[0] == '-';
        // Mantissas are shorter than 2^40 digits, so these decide alone (and
        // keep the sum below from overflowing).
        if (exponent > (1LL << 40)) return false;
        if (exponent < -(1LL << 40)) return true;
    }
    // Decimal magnitude of the mantissa: digits before the point once leading
    // zeros are gone, or minus the zeros after the point.
    const std::size_t point = mantissa.find('.');
    const std::string_view whole = mantissa.substr(0, point);
    const std::size_t first_nonzero = whole.find_first_not_of('0');
    long long magnitude = 0;
    if (first_nonzero != std::string_view::npos) {
        magnitude = static_cast<long long>(whole.size() - first_nonzero);
    } else if (point != std::string_view::npos) {
        const std::string_view fraction = mantissa.substr(point + 1);
        const std::size_t nz = fraction.find_first_not_of('0');
        magnitude = -static_cast<long long>(nz == std::string_view::npos ? fraction.size() : nz);
    }
    return magnitude + exponent <= 0;
}

}  // namespace

NumberStatus parse_number(std::string_view token, double& out) {
    std::string_view digits = token;
    if (!digits.empty() && digits[0] == '+') {
        digits.remove_prefix(1);
        if (!digits.empty() && digits[0] == '-') return NumberStatus::NotANumber;
    }
    if (digits.empty()) return NumberStatus::NotANumber;
    // from_chars also takes "inf", "nan" and "infinity": they are numbers, but
    // not finite ones.
    const char* first = digits.data();
    const char* last = digits.data() + digits.size();
    double value = 0;
    auto [end, ec] = std::from_chars(first, last, value, std::chars_format::general);
    if (end != last || (ec != std::errc() && ec != std::errc::result_out_of_range))
        return NumberStatus::NotANumber;
    if (ec == std::errc::result_out_of_range) {
        if (!underflows(digits)) return NumberStatus::NotFinite;
        out = digits[0] == '-' ? -0.0 : 0.0;
        return NumberStatus::Ok;
    }
    if (!std::isfinite(value)) return NumberStatus::NotFinite;
    out = value;
    return NumberStatus::Ok;
}

bool parse_integer(std::string_view token, long long& out) {
    if (!token.empty() && token[0] == '+') {
        token.remove_prefix(1);
        if (!token.empty() && token[0] == '-') return false;
    }
    if (token.empty()) return false;
    const char* last = token.data() + token.size();
    auto [end, ec] = std::from_chars(token.data(), last, out);
    return ec == std::errc() && end == last;
}

}  // namespace emoface::fap::detail
