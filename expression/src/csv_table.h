#pragma once
// The comma-separated tables capture tools write (OpenFace, Live Link Face,
// MediaPipe dumps): a header row of names, then rows of as many fields.
// Fields are trimmed of spaces and tabs (OpenFace's older versions write
// ", AU01_r"); no quoting (none of these tools quotes). Lines end in LF,
// CRLF or CR; a UTF-8 byte order mark is skipped; blank lines are skipped.
#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace emoface::expression::detail {

struct CsvRow {
    long long line = 0;
    std::vector<std::string_view> fields;  // views into the parsed text
};

struct CsvTable {
    std::string source;  // what messages call the file
    std::vector<std::string> header;
    long long header_line = 0;
    std::vector<CsvRow> rows;

    // Index of the column named `name` (exact, after trimming), or -1.
    int column(std::string_view name) const;
    // The number at (row, col): a finite decimal number; else
    // "capture: FILE:LINE: expected a finite number in column NAME, found ...".
    double number(const CsvRow& row, int col) const;
    [[noreturn]] void fail(long long line, std::string_view expected, std::string_view found) const;
};

// Whether `text` is a CSV rather than a FAP file: its first line that is
// neither blank nor a '#' comment has a comma and does not start with a digit.
bool looks_like_csv(std::string_view text);

// The table; rows with a field count other than the header's are an error
// (a truncated last row included). `text` must outlive the table.
CsvTable parse_csv(std::string_view text, const std::string& source);

}  // namespace emoface::expression::detail
