#include "csv_table.h"

#include <charconv>
#include <cmath>

#include <fmt/format.h>

#include "emoface/common/error.h"

namespace emoface::expression::detail {
namespace {

std::string_view trim(std::string_view s) {
    while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
    while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
    return s;
}

std::string_view skip_bom(std::string_view text) {
    constexpr std::string_view kBom = "\xEF\xBB\xBF";
    if (text.substr(0, kBom.size()) == kBom) text.remove_prefix(kBom.size());
    return text;
}

// Splits text into lines at LF, CRLF or a lone CR, numbered from 1.
class Lines {
public:
    explicit Lines(std::string_view text) : text_(text) {}
    bool next(std::string_view& line, long long& number) {
        if (pos_ >= text_.size()) return false;
        std::size_t end = pos_;
        while (end < text_.size() && text_[end] != '\n' && text_[end] != '\r') ++end;
        line = text_.substr(pos_, end - pos_);
        if (end < text_.size() && text_[end] == '\r' && end + 1 < text_.size() && text_[end + 1] == '\n') ++end;
        pos_ = end + 1;
        number = ++line_;
        return true;
    }

private:
    std::string_view text_;
    std::size_t pos_ = 0;
    long long line_ = 0;
};

void split(std::string_view line, std::vector<std::string_view>& out) {
    out.clear();
    std::size_t start = 0;
    for (;;) {
        const std::size_t comma = line.find(',', start);
        out.push_back(trim(line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start)));
        if (comma == std::string_view::npos) break;
        start = comma + 1;
    }
}

}  // namespace

int CsvTable::column(std::string_view name) const {
    for (std::size_t i = 0; i < header.size(); ++i)
        if (header[i] == name) return static_cast<int>(i);
    return -1;
}

void CsvTable::fail(long long line, std::string_view expected, std::string_view found) const {
    fail_data("capture", FileLoc{source, static_cast<int>(line), ""}, expected, found);
}

double CsvTable::number(const CsvRow& row, int col) const {
    std::string_view token = row.fields[static_cast<std::size_t>(col)];
    if (!token.empty() && token[0] == '+') token.remove_prefix(1);
    double value = 0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (token.empty() || end != token.data() + token.size() || ec != std::errc() || !std::isfinite(value))
        fail(row.line, fmt::format("a finite number in column {}", header[static_cast<std::size_t>(col)]),
             fmt::format("\"{}\"", echo_input(row.fields[static_cast<std::size_t>(col)], 40)));
    return value;
}

bool looks_like_csv(std::string_view text) {
    Lines lines(skip_bom(text));
    std::string_view line;
    long long number = 0;
    // A FAP file's comments ('#') may hold commas, and so may its header's
    // name, but that header starts with its version number; a capture CSV
    // starts with a header of names.
    while (lines.next(line, number)) {
        const std::string_view content = trim(line);
        if (content.empty() || content[0] == '#') continue;
        return content.find(',') != std::string_view::npos && !(content[0] >= '0' && content[0] <= '9');
    }
    return false;
}

CsvTable parse_csv(std::string_view text, const std::string& source) {
    CsvTable table;
    table.source = source;
    Lines lines(skip_bom(text));
    std::string_view line;
    long long number = 0;
    std::vector<std::string_view> fields;
    while (lines.next(line, number)) {
        if (trim(line).empty()) continue;
        split(line, fields);
        if (table.header_line == 0) {
            table.header_line = number;
            for (std::string_view f : fields) table.header.emplace_back(f);
            continue;
        }
        if (fields.size() != table.header.size())
            table.fail(number, fmt::format("{} comma-separated fields, as the header on line {} has", table.header.size(),
                                           table.header_line),
                       fmt::format("{}", fields.size()));
        table.rows.push_back({number, fields});
    }
    if (table.header_line == 0) table.fail(1, "a header row of column names", "an empty file");
    return table;
}

}  // namespace emoface::expression::detail
