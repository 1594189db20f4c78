// Untrusted input files: FIFOs, devices, folders and huge files are refused
// up front, in one line naming the file (issue 12).
#include "emoface/common/input_file.h"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/un.h>
#include <unistd.h>

#include <filesystem>
#include <functional>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "emoface/common/error.h"

namespace emoface {
namespace {

namespace fs = std::filesystem;

class InputFile : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::path(::testing::TempDir()) /
               ("emoface_input_file_" + std::to_string(::getpid()) + "_" +
                ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }
    fs::path dir_;
};

std::string message_of(const std::function<void()>& fn) {
    try {
        fn();
    } catch (const InputError& e) {
        return e.what();
    }
    return "(no error)";
}

TEST_F(InputFile, RefusesWhatIsNotARegularFileOfAtMostTheLimit) {
    std::ofstream(path("small.txt")) << "hello";
    std::ofstream(path("big.txt")) << std::string(3 * kMiB + 5, 'x');
    ASSERT_EQ(::mkfifo(path("fifo").c_str(), 0600), 0);
    fs::create_directory_symlink(path("loop_b"), path("loop_a"));
    fs::create_directory_symlink(path("loop_a"), path("loop_b"));
    fs::create_symlink(path("small.txt"), path("link.txt"));
    struct Case {
        std::string file, found;
    } cases[] = {
        {path("missing"), "no such file"},
        {path("small.txt/x"), "no such file (a part of the path is not a folder)"},
        {dir_.string(), "a directory"},
        {path("fifo"), "a FIFO"},
        {"/dev/zero", "a character device"},
        {"/dev/null", "a character device"},
        {path("loop_a"), "a loop of symbolic links"},
        {path("big.txt"), "a file of 4 MiB"},
    };
    for (const Case& c : cases) {
        const std::string expected = "test: " + c.file + ": expected a regular file of at most 2 MiB, found " + c.found;
        EXPECT_EQ(message_of([&] { check_input_file(c.file, 2 * kMiB, "test"); }), expected);
        EXPECT_EQ(message_of([&] { read_input_file(c.file, 2 * kMiB, "test"); }), expected);
    }
    EXPECT_EQ(message_of([&] { check_input_file("", 2 * kMiB, "test"); }),
              "test: (empty path): expected a regular file of at most 2 MiB, found an empty path");
    EXPECT_EQ(message_of([&] { check_input_file(path("small.txt"), 4, "test"); }),
              "test: " + path("small.txt") + ": expected a regular file of at most 4 bytes, found a file of 5 bytes");
    // A regular file, or a link to one, is read whole.
    EXPECT_EQ(read_input_file(path("small.txt"), 2 * kMiB, "test"), "hello");
    EXPECT_EQ(read_input_file(path("link.txt"), 2 * kMiB, "test"), "hello");
    EXPECT_NO_THROW(check_input_file(path("link.txt"), 5, "test"));
}

TEST_F(InputFile, UnreadableFileSaysSo) {
    if (::geteuid() == 0) GTEST_SKIP() << "root reads every file";
    std::ofstream(path("secret.txt")) << "x";
    fs::permissions(path("secret.txt"), fs::perms::none);
    EXPECT_EQ(message_of([&] { read_input_file(path("secret.txt"), kMiB, "test"); }),
              "test: " + path("secret.txt") + ": expected a readable file, found one without read permission");
}

}  // namespace
}  // namespace emoface
