#include "atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include <fmt/format.h>

#include "emoface/common/error.h"

namespace emoface::render::detail {

std::string temporary_path_for(const std::string& path) {
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path p(path);
    const std::string name = fmt::format(".{}.tmp-{}-{}{}", p.stem().string(), ::getpid(),
                                         counter++, p.extension().string());
    return (p.parent_path() / name).string();
}

void commit_temporary(const std::string& temp, const std::string& path) {
    if (std::rename(temp.c_str(), path.c_str()) != 0) {
        const int e = errno;
        discard_temporary(temp);
        fail("render: cannot move the finished file to {}: {}", path, std::strerror(e));
    }
}

void discard_temporary(const std::string& temp) noexcept {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
}

}  // namespace emoface::render::detail
