#include "cli_checks.h"

#include <charconv>
#include <filesystem>

namespace emoface::apps {

std::pair<int, int> parse_size(const std::string& text, const std::string& command, const std::string& option,
                               int lo, int hi) {
    auto bad = [&]() {
        fail<InputError>("{}: {} '{}': expected WIDTHxHEIGHT, each {}..{} (e.g. 1280x720)", command, option,
                         text.size() > 40 ? text.substr(0, 40) + "..." : text, lo, hi);
    };
    const auto x = text.find_first_of("xX");
    if (x == std::string::npos) bad();
    auto side = [&](std::size_t from, std::size_t to) {
        // from_chars takes digits only and reports overflow instead of
        // wrapping (4294967360 is not 64).
        int value = 0;
        const char* first = text.data() + from;
        const char* last = text.data() + to;
        if (first == last || *first < '0' || *first > '9') bad();
        const auto [end, error] = std::from_chars(first, last, value);
        if (error != std::errc() || end != last || value < lo || value > hi) bad();
        return value;
    };
    return {side(0, x), side(x + 1, text.size())};
}

std::pair<std::string, std::string> split_output_path(const std::string& path, const std::string& command,
                                                      const std::string& option) {
    const std::filesystem::path p(path);
    const std::string name = p.filename().string();
    if (path.empty() || name.empty() || name == "." || name == "..")
        fail<InputError>("{}: {} '{}': expected a file name, found {}", command, option, path,
                         path.empty() ? "nothing" : "a folder");
    std::error_code ec;
    if (std::filesystem::is_directory(p, ec))
        fail<InputError>("{}: {} {}: expected a file name, found a folder", command, option, path);
    return {p.parent_path().string(), name};
}

OutputFile::OutputFile(const std::string& path, const std::string& command, const std::string& option)
    : destination_(path),
      batch_(split_output_path(path, command, option).first, fmt::format("{}: {} {}", command, option, path)),
      staged_(batch_.stage(split_output_path(path, command, option).second)) {}

}  // namespace emoface::apps
