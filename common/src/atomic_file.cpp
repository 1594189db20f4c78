#include "emoface/common/atomic_file.h"

#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "emoface/common/error.h"
#include "emoface/common/output_batch.h"

namespace emoface {
namespace {

[[noreturn]] void cannot_write(std::string_view module, const std::string& path, int error) {
    fail_data(module, FileLoc{OutputBatch::shown_path(path), 0, ""}, "a writable file", std::strerror(error));
}

}  // namespace

std::string temporary_path_for(const std::string& path) {
    static std::atomic<unsigned> counter{0};
    const std::filesystem::path p(path);
    const std::string name =
        fmt::format(".{}.tmp-{}-{}{}", p.stem().string(), ::getpid(), counter++, p.extension().string());
    return (p.parent_path() / name).string();
}

void commit_temporary(const std::string& temp, const std::string& path, std::string_view module) {
    if (std::rename(temp.c_str(), path.c_str()) != 0) {
        const int error = errno;
        discard_temporary(temp);
        cannot_write(module, path, error);
    }
}

void discard_temporary(const std::string& temp) noexcept {
    std::error_code ignored;
    std::filesystem::remove(temp, ignored);
}

void write_file_atomically(const std::string& path, std::string_view bytes, std::string_view module) {
    const std::string temp = temporary_path_for(path);
    {
        std::ofstream out(temp, std::ios::binary | std::ios::trunc);
        if (!out) cannot_write(module, path, errno);
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.close();
        if (!out) {
            const int error = errno;
            discard_temporary(temp);
            cannot_write(module, path, error);
        }
    }
    commit_temporary(temp, path, module);
}

}  // namespace emoface
