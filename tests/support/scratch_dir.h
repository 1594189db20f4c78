#pragma once
// A fresh folder for one test's files, named after the test (and the
// process, so parallel ctest runs never share one), removed afterwards.
#include <string>

#include <filesystem>

namespace emoface::testing {

class ScratchDir {
public:
    ScratchDir();  // inside a running test: the name comes from it
    ~ScratchDir();
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;

    const std::filesystem::path& dir() const { return dir_; }
    // dir/name as a string (a file the test will make or expects).
    std::string path(const std::string& name) const;
    // Writes `text` to dir/name and returns the path.
    std::string write(const std::string& name, const std::string& text) const;

private:
    std::filesystem::path dir_;
};

// A whole file's bytes ("" when it cannot be read).
std::string read_file(const std::filesystem::path& file);

}  // namespace emoface::testing
