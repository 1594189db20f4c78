#pragma once
// Text helpers of the FAP reader (internal): lines, tokens, numbers, and how
// messages show a token that may be binary junk.
#include <array>
#include <cstddef>
#include <string>
#include <string_view>

namespace emoface::fap::detail {

inline bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

std::string_view trim(std::string_view s);

// 'token' for a message: at most 40 characters, bytes outside printable
// ASCII as \xNN, so a message stays one line whatever the input holds.
std::string quoted(std::string_view token);

// Splits text into lines at LF, CRLF or a lone CR, counting them from 1.
class LineReader {
public:
    explicit LineReader(std::string_view text) : text_(text) {}
    // The next line, comments and blank lines included; false at the end.
    bool next(std::string_view& line, long long& line_number);
    // The next line that is neither blank nor a comment.
    bool next_content(std::string_view& line, long long& line_number);
    // The number a line read now would get.
    long long line_number() const { return line_ + 1; }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    long long line_ = 0;
};

// The tokens of a line, keeping at most N of them but counting all, so a huge
// line costs no memory.
template <std::size_t N>
struct Tokens {
    std::array<std::string_view, N> items{};
    std::size_t count = 0;  // all tokens on the line, kept or not

    explicit Tokens(std::string_view line) {
        std::size_t i = 0;
        while (i < line.size()) {
            while (i < line.size() && is_space(line[i])) ++i;
            if (i == line.size()) break;
            const std::size_t start = i;
            while (i < line.size() && !is_space(line[i])) ++i;
            if (count < N) items[count] = line.substr(start, i - start);
            ++count;
        }
    }
};

enum class NumberStatus { Ok, NotANumber, NotFinite };

// A decimal number as C writes it ("12", "-3.5", "+1e3"), whole token; no
// locale. Values too small for a double read as 0.
NumberStatus parse_number(std::string_view token, double& out);

// A decimal integer ("42", "+7"), whole token.
bool parse_integer(std::string_view token, long long& out);

}  // namespace emoface::fap::detail
