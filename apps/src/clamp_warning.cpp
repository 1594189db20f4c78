#include "clamp_warning.h"

#include <cstdio>
#include <filesystem>

#include "emoface/expression/fap_clamp.h"

namespace emoface::apps {

namespace {
constexpr std::size_t kMaxLine = 300;  // README, "Exit codes": every message line
}

std::string clamp_warning(const std::string& command, const std::string& path, const fap::FapStream& stream,
                          const std::string& data_dir) {
    const std::string ranges_file = data_dir + "/expression/fap_ranges.json";
    if (!std::filesystem::is_regular_file(ranges_file)) return "";
    const expression::ClampSummary summary =
        expression::summarize_clamping(stream, expression::load_fap_ranges(ranges_file));
    if (summary.empty()) return "";
    std::string name = std::filesystem::path(path).filename().string();
    if (name.size() > 60) name = name.substr(0, 57) + "...";
    for (char& c : name)  // one line, whatever the file is called
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';
    const std::string head = "emoface: " + command + ": " + name + ": ";
    const std::string tail = "; --no-clamp keeps them";
    const std::size_t room = kMaxLine > head.size() + tail.size() + 80 ? kMaxLine - head.size() - tail.size() : 80;
    return head.substr(9) + expression::describe_clamping(summary, room) + tail;
}

void warn_clamped_faps(const std::string& command, const std::string& path, const fap::FapStream& stream,
                       const std::string& data_dir) {
    const std::string line = clamp_warning(command, path, stream, data_dir);
    if (!line.empty()) std::fprintf(stderr, "emoface: %s\n", line.c_str());
}

}  // namespace emoface::apps
