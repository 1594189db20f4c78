#include "emoface/common/error.h"

namespace emoface {
namespace {

// Length of the valid UTF-8 sequence starting at text[i] (2..4), or 0.
std::size_t utf8_length(std::string_view text, std::size_t i) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char b = byte(i);
    std::size_t n = 0;
    unsigned min = 0;
    if (b >= 0xC2 && b <= 0xDF) n = 2, min = 0x80;
    else if (b >= 0xE0 && b <= 0xEF) n = 3, min = 0x800;
    else if (b >= 0xF0 && b <= 0xF4) n = 4, min = 0x10000;
    else return 0;
    if (i + n > text.size()) return 0;
    unsigned code = b & (0xFF >> (n + 1));
    for (std::size_t k = 1; k < n; ++k) {
        if ((byte(i + k) & 0xC0) != 0x80) return 0;
        code = (code << 6) | (byte(i + k) & 0x3F);
    }
    if (code < min || code > 0x10FFFF || (code >= 0xD800 && code <= 0xDFFF)) return 0;
    if (code >= 0x80 && code <= 0x9F) return 0;  // C1 controls: escaped as bytes
    return n;
}

// Appends one character of `text` at i, escaped where needed; returns its length in text.
std::size_t append_escaped(std::string& out, std::string_view text, std::size_t i) {
    const unsigned char b = static_cast<unsigned char>(text[i]);
    if (b >= 0x20 && b < 0x7F) {
        out += static_cast<char>(b);
        return 1;
    }
    if (const std::size_t n = utf8_length(text, i)) {
        out.append(text.substr(i, n));
        return n;
    }
    switch (b) {
        case '\n': out += "\\n"; break;
        case '\r': out += "\\r"; break;
        case '\t': out += "\\t"; break;
        default: out += fmt::format("\\x{:02x}", b);
    }
    return 1;
}

}  // namespace

std::string echo_input(std::string_view text, std::size_t max_chars) {
    std::string out;
    std::size_t chars = 0, i = 0;
    while (i < text.size() && chars < max_chars) {
        i += append_escaped(out, text, i);
        ++chars;
    }
    if (i < text.size()) out += "\u2026";
    return out;
}

std::string FileLoc::str() const {
    std::string out = file;
    if (line > 0) out += fmt::format(":{}", line);
    if (!key.empty()) out += ": " + key;
    return out;
}

void fail_data(std::string_view module, const FileLoc& at, std::string_view expected, std::string_view found) {
    throw InputError(fmt::format("{}: {}: expected {}, found {}", module, at.str(), expected, found));
}

int exit_code(const std::exception& e) {
    if (dynamic_cast<const EnvironmentError*>(&e)) return kExitEnvironment;
    if (dynamic_cast<const InternalError*>(&e)) return kExitInternal;
    // A plain Error was thrown where the thrower did not classify the
    // problem; nearly all of them are about the data a command was given.
    if (dynamic_cast<const Error*>(&e)) return kExitBadInput;
    return kExitInternal;
}

std::string error_line(const std::exception& e) {
    std::string line;
    const std::string_view what = e.what();
    for (std::size_t i = 0; i < what.size();) i += append_escaped(line, what, i);
    const bool bug = exit_code(e) == kExitInternal;
    const std::string before = bug && !dynamic_cast<const Error*>(&e) ? "unexpected exception: " : "";
    const std::string after = bug ? " (this is a bug)" : "";
    const std::size_t room = kMaxErrorLine - before.size() - after.size();
    if (line.size() > room) {
        // Keep the start (module, file, place) and the end (what was found).
        const std::string_view cut = " \u2026 ";
        std::size_t head = (room - cut.size()) * 2 / 3, tail = room - cut.size() - head;
        // Whole UTF-8 characters only: no continuation byte at either edge.
        while (head > 0 && (static_cast<unsigned char>(line[head]) & 0xC0) == 0x80) --head;
        while (tail > 0 && (static_cast<unsigned char>(line[line.size() - tail]) & 0xC0) == 0x80) --tail;
        line = line.substr(0, head) + std::string(cut) + line.substr(line.size() - tail);
    }
    return before + line + after;
}

}  // namespace emoface
