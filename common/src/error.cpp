#include "emoface/common/error.h"

namespace emoface {

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
    if (exit_code(e) != kExitInternal) return e.what();
    if (dynamic_cast<const Error*>(&e)) return fmt::format("{} (this is a bug)", e.what());
    return fmt::format("unexpected exception: {} (this is a bug)", e.what());
}

}  // namespace emoface
