#include "emoface/common/input_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "emoface/common/error.h"

namespace emoface {
namespace {

std::string limit_text(std::uint64_t max_bytes) {
    if (max_bytes >= kMiB) return fmt::format("{} MiB", max_bytes / kMiB);
    return fmt::format("{} bytes", max_bytes);
}

// What a stat result or a failed stat is, as a message's "found" part; empty
// for a regular file within the limit.
std::string what_is_there(const struct stat& st, std::uint64_t max_bytes) {
    if (S_ISDIR(st.st_mode)) return "a directory";
    if (S_ISFIFO(st.st_mode)) return "a FIFO";
    if (S_ISCHR(st.st_mode)) return "a character device";
    if (S_ISBLK(st.st_mode)) return "a block device";
    if (S_ISSOCK(st.st_mode)) return "a socket";
    if (!S_ISREG(st.st_mode)) return "something that is not a file";
    const auto size = static_cast<std::uint64_t>(st.st_size);
    if (size > max_bytes)
        return size >= kMiB ? fmt::format("a file of {} MiB", (size + kMiB - 1) / kMiB)
                            : fmt::format("a file of {} bytes", size);
    return "";
}

std::string missing_reason(int err) {
    switch (err) {
        case ENOENT: return "no such file";
        case ENOTDIR: return "no such file (a part of the path is not a folder)";
        case ELOOP: return "a loop of symbolic links";
        case ENAMETOOLONG: return "a path too long for the system";
        default: return std::strerror(err);
    }
}

[[noreturn]] void refuse(std::string_view module, const std::string& path, std::uint64_t max_bytes,
                         const std::string& found) {
    fail_data(module, FileLoc{path, 0, ""}, "a regular file of at most " + limit_text(max_bytes), found);
}

class Fd {
public:
    explicit Fd(int fd) : fd_(fd) {}
    ~Fd() {
        if (fd_ >= 0) ::close(fd_);
    }
    Fd(const Fd&) = delete;
    Fd& operator=(const Fd&) = delete;
    int get() const { return fd_; }

private:
    int fd_;
};

}  // namespace

void check_input_file(const std::string& path, std::uint64_t max_bytes, std::string_view module) {
    struct stat st {};
    if (path.empty()) refuse(module, "(empty path)", max_bytes, "an empty path");
    if (::stat(path.c_str(), &st) != 0) refuse(module, path, max_bytes, missing_reason(errno));
    const std::string found = what_is_there(st, max_bytes);
    if (!found.empty()) refuse(module, path, max_bytes, found);
}

std::string read_input_file(const std::string& path, std::uint64_t max_bytes, std::string_view module) {
    if (path.empty()) refuse(module, "(empty path)", max_bytes, "an empty path");
    // O_NONBLOCK: opening a FIFO with no writer would otherwise wait forever.
    const Fd fd(::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC));
    if (fd.get() < 0) {
        const int err = errno;
        struct stat st {};
        if (err == EACCES && ::stat(path.c_str(), &st) == 0 && what_is_there(st, max_bytes).empty())
            fail_data(module, FileLoc{path, 0, ""}, "a readable file", "one without read permission");
        if (::stat(path.c_str(), &st) == 0 && !what_is_there(st, max_bytes).empty())
            refuse(module, path, max_bytes, what_is_there(st, max_bytes));
        refuse(module, path, max_bytes, missing_reason(err));
    }
    struct stat st {};
    if (::fstat(fd.get(), &st) != 0) refuse(module, path, max_bytes, missing_reason(errno));
    const std::string found = what_is_there(st, max_bytes);
    if (!found.empty()) refuse(module, path, max_bytes, found);
    const int flags = ::fcntl(fd.get(), F_GETFL);
    if (flags >= 0) ::fcntl(fd.get(), F_SETFL, flags & ~O_NONBLOCK);

    std::string text;
    text.reserve(static_cast<std::size_t>(st.st_size));
    char chunk[1 << 16];
    for (;;) {
        const ssize_t n = ::read(fd.get(), chunk, sizeof chunk);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const int err = errno;
            fail_data(module, FileLoc{path, 0, ""}, "a readable file",
                      err == EISDIR ? "a directory" : std::string("a read error: ") + std::strerror(err));
        }
        if (n == 0) break;
        text.append(chunk, static_cast<std::size_t>(n));
        if (text.size() > max_bytes) refuse(module, path, max_bytes, "a file that grew past that while read");
    }
    return text;
}

}  // namespace emoface
