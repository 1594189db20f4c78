// Output files appear whole or not at all, and a failure names the file.
#include "emoface/common/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "emoface/common/error.h"

namespace emoface {
namespace {

namespace fs = std::filesystem;

std::string read_all(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

TEST(AtomicFile, ReplacesTheFileAndLeavesNoTemporary) {
    const fs::path dir = fs::path(::testing::TempDir()) / "emoface_atomic_file_test";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string path = (dir / "out.txt").string();
    write_file_atomically(path, "first", "test");
    write_file_atomically(path, std::string("second\0binary", 13), "test");
    EXPECT_EQ(read_all(path), std::string("second\0binary", 13));
    int files = 0;
    for (const auto& entry : fs::directory_iterator(dir)) {
        ++files;
        EXPECT_EQ(entry.path().filename(), "out.txt");
    }
    EXPECT_EQ(files, 1);
    fs::remove_all(dir);
}

TEST(AtomicFile, TemporaryKeepsTheExtensionInTheSameFolder) {
    const fs::path temp = temporary_path_for("/some/folder/frame.png");
    EXPECT_EQ(temp.parent_path(), "/some/folder");
    EXPECT_EQ(temp.extension(), ".png");
    EXPECT_NE(temp.filename(), "frame.png");
}

TEST(AtomicFile, AFolderThatIsNotThereIsBadInputNamingTheFile) {
    const std::string path = "/nonexistent-emoface-folder/out.txt";
    try {
        write_file_atomically(path, "x", "test");
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "test: " + path + ": expected a writable file, found No such file or directory");
    }
}

}  // namespace
}  // namespace emoface
