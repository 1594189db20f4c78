#include "emoface/common/output_batch.h"

#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <utility>

#include <fmt/format.h>

#include "emoface/common/error.h"

namespace emoface {
namespace {

namespace fs = std::filesystem;

bool exists_no_follow(const std::string& path, struct stat* st) { return ::lstat(path.c_str(), st) == 0; }

}  // namespace

OutputBatch::OutputBatch(const std::string& folder, std::string what)
    : folder_(folder.empty() ? "." : folder), what_(std::move(what)) {
    // The missing folders, deepest first; the first existing one must be a
    // folder (a file in the way is named, not left to mkdir's ENOTDIR).
    std::vector<std::string> missing;
    for (fs::path up = folder_; !up.empty(); up = up.parent_path()) {
        struct stat st {};
        if (::stat(up.c_str(), &st) == 0) {
            if (!S_ISDIR(st.st_mode)) fail<InputError>("{}: {} is a file, not a folder", what_, up.string());
            break;
        }
        if (errno != ENOENT && errno != ENOTDIR)
            fail<InputError>("{}: cannot write there: {}", what_, std::strerror(errno));
        missing.push_back(up.string());
        if (up == up.parent_path()) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        if (::mkdir(it->c_str(), 0777) != 0 && errno != EEXIST) {
            const int error = errno;
            discard();
            fail<InputError>("{}: cannot write there: {}", what_, std::strerror(error));
        }
        made_.insert(made_.begin(), *it);
    }
    static std::atomic<unsigned> counter{0};
    staging_ = (fs::path(folder_) / fmt::format(".emoface-{}-{}.tmp", ::getpid(), counter++)).string();
    if (::mkdir(staging_.c_str(), 0777) != 0) {
        const int error = errno;
        staging_.clear();
        discard();
        fail<InputError>("{}: cannot write there: {}", what_, std::strerror(error));
    }
}

OutputBatch::~OutputBatch() {
    if (!committed_) discard();
}

std::string OutputBatch::stage(const std::string& name) {
    if (name.empty() || name.find('/') != std::string::npos || name == "." || name == "..")
        fail<InternalError>("OutputBatch::stage(): expected a plain file name, got '{}'", name);
    names_.push_back(name);
    return (fs::path(staging_) / name).string();
}

std::string OutputBatch::destination(const std::string& name) const {
    return folder_ == "." ? name : (fs::path(folder_) / name).string();
}

void OutputBatch::commit() {
    if (committed_) fail<InternalError>("OutputBatch::commit(): expected one call, got a second");
    struct Move {
        std::string from, to, replaced;  // replaced: where the file it replaced waits ("" none)
    };
    std::vector<Move> moves;
    for (const std::string& name : names_) {
        const std::string from = (fs::path(staging_) / name).string();
        struct stat st {};
        if (!exists_no_follow(from, &st)) continue;
        moves.push_back({from, destination(name), ""});
    }
    // A folder in a file's place fails before anything moves.
    for (const Move& m : moves) {
        struct stat st {};
        if (::stat(m.to.c_str(), &st) == 0 && S_ISDIR(st.st_mode))
            fail<InputError>("{}: cannot write {}: {}", what_, m.to, std::strerror(EISDIR));
    }
    std::size_t done = 0;
    auto undo = [&] {
        for (std::size_t i = done; i-- > 0;) {
            ::unlink(moves[i].to.c_str());
            if (!moves[i].replaced.empty()) std::rename(moves[i].replaced.c_str(), moves[i].to.c_str());
        }
    };
    for (; done < moves.size(); ++done) {
        Move& m = moves[done];
        struct stat st {};
        if (exists_no_follow(m.to, &st)) {
            m.replaced = (fs::path(staging_) / fmt::format(".replaced-{}", done)).string();
            if (std::rename(m.to.c_str(), m.replaced.c_str()) != 0) {
                const int error = errno;
                m.replaced.clear();
                undo();
                fail<InputError>("{}: cannot write {}: {}", what_, m.to, std::strerror(error));
            }
        }
        if (std::rename(m.from.c_str(), m.to.c_str()) != 0) {
            const int error = errno;
            if (!m.replaced.empty()) std::rename(m.replaced.c_str(), m.to.c_str());
            undo();
            fail<InputError>("{}: cannot write {}: {}", what_, m.to, std::strerror(error));
        }
    }
    committed_ = true;
    std::error_code ignored;
    fs::remove_all(staging_, ignored);
}

std::string OutputBatch::shown_path(const std::string& path) {
    const fs::path p(path);
    const std::string folder = p.parent_path().filename().string();
    if (folder.rfind(".emoface-", 0) != 0 || folder.size() < 13 || folder.compare(folder.size() - 4, 4, ".tmp") != 0)
        return path;
    const fs::path destination_folder = p.parent_path().parent_path();
    return destination_folder.empty() || destination_folder == "." ? p.filename().string()
                                                                   : (destination_folder / p.filename()).string();
}

void OutputBatch::discard() noexcept {
    std::error_code ignored;
    if (!staging_.empty()) fs::remove_all(staging_, ignored);
    // Only folders left empty: never anything the batch did not make.
    for (const std::string& folder : made_) fs::remove(folder, ignored);
}

}  // namespace emoface
