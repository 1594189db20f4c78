// Several output files appear together or not at all (OutputBatch): a failed
// commit puts back what it replaced and moved, a batch dropped without commit
// leaves neither its staging folder nor the folders it made, and the errors
// name the user's path with the system's reason.
#include "emoface/common/output_batch.h"

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"

namespace emoface {
namespace {

namespace fs = std::filesystem;

class OutputBatchTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = fs::path(::testing::TempDir()) /
               ("emoface_output_batch_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
        fs::remove_all(dir_);
        fs::create_directories(dir_);
    }
    void TearDown() override { fs::remove_all(dir_); }

    // Every path under the folder, relative, hidden ones included.
    std::set<std::string> tree() const {
        std::set<std::string> out;
        for (const auto& e : fs::recursive_directory_iterator(dir_)) out.insert(fs::relative(e.path(), dir_).string());
        return out;
    }
    static std::string read(const fs::path& p) {
        std::ifstream in(p, std::ios::binary);
        std::ostringstream s;
        s << in.rdbuf();
        return s.str();
    }
    static void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

    fs::path dir_;
};

TEST_F(OutputBatchTest, CommitMovesEveryStagedFileAndLeavesNoStaging) {
    OutputBatch batch((dir_ / "out").string(), "test: --out out");
    for (int i = 0; i < 5; ++i) {
        const std::string staged = batch.stage("f" + std::to_string(i) + ".png");
        EXPECT_EQ(fs::path(staged).filename(), "f" + std::to_string(i) + ".png") << "the name and extension are kept";
        write(staged, "frame " + std::to_string(i));
    }
    EXPECT_FALSE(fs::exists(dir_ / "out" / "f0.png")) << "nothing appears before commit";
    batch.commit();
    EXPECT_EQ(tree(), (std::set<std::string>{"out", "out/f0.png", "out/f1.png", "out/f2.png", "out/f3.png",
                                             "out/f4.png"}));
    EXPECT_EQ(read(dir_ / "out" / "f3.png"), "frame 3");
}

TEST_F(OutputBatchTest, DroppedWithoutCommitLeavesTheFolderAsItWas) {
    write((dir_ / "keep.txt").string(), "mine");
    {
        // Two folders made for it, both removed again; the user's file stays.
        OutputBatch batch((dir_ / "a" / "b").string(), "test: --out a/b/x.png");
        write(batch.stage("x.png"), "half");
        EXPECT_TRUE(fs::is_directory(dir_ / "a" / "b"));
    }
    EXPECT_EQ(tree(), std::set<std::string>{"keep.txt"});
}

TEST_F(OutputBatchTest, AFolderWhereTheThirdOfFiveGoesLeavesNothingAndRestoresWhatItReplaced) {
    write((dir_ / "f0.png").string(), "old 0");  // replaced by the batch, then put back
    OutputBatch batch(dir_.string(), "test: --out f%d.png");
    for (int i = 0; i < 5; ++i) write(batch.stage("f" + std::to_string(i) + ".png"), "new");
    fs::create_directory(dir_ / "f2.png");  // appears while the batch is written
    try {
        batch.commit();
        FAIL() << "no error";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()),
                  "test: --out f%d.png: cannot write " + (dir_ / "f2.png").string() + ": Is a directory");
    }
    EXPECT_EQ(read(dir_ / "f0.png"), "old 0");
    EXPECT_TRUE(fs::is_directory(dir_ / "f2.png"));
    EXPECT_TRUE(fs::is_empty(dir_ / "f2.png"));
}

TEST_F(OutputBatchTest, ReplacesFilesOfTheSameName) {
    write((dir_ / "a.obj").string(), "old");
    OutputBatch batch(dir_.string(), "test");
    write(batch.stage("a.obj"), "new");
    batch.commit();
    EXPECT_EQ(read(dir_ / "a.obj"), "new");
    EXPECT_EQ(tree(), std::set<std::string>{"a.obj"});
}

TEST_F(OutputBatchTest, UnwritableDestinationsFailWhenTheBatchIsMadeWithTheSystemsReason) {
    write((dir_ / "file").string(), "x");
    struct Case {
        std::string folder, message;
    };
    // Tests may run as root, where permissions do not block: a file in the
    // way, and /proc, which refuses new entries to everyone.
    const Case cases[] = {
        {(dir_ / "file").string(), "test: " + (dir_ / "file").string() + " is a file, not a folder"},
        {(dir_ / "file" / "deeper").string(), "test: " + (dir_ / "file").string() + " is a file, not a folder"},
        {"/proc/emoface-no-such/x", "test: cannot write there: No such file or directory"},
    };
    for (const Case& c : cases) {
        try {
            OutputBatch batch(c.folder, "test");
            ADD_FAILURE() << c.folder << ": no error";
        } catch (const InputError& e) {
            EXPECT_EQ(std::string(e.what()), c.message);
        }
    }
    EXPECT_EQ(tree(), std::set<std::string>{"file"});
}

TEST_F(OutputBatchTest, MessagesNameTheUsersPathNotTheStagingFolder) {
    OutputBatch batch((dir_ / "out").string(), "test");
    const std::string staged = batch.stage("a.png");
    EXPECT_NE(staged, (dir_ / "out" / "a.png").string());
    EXPECT_EQ(OutputBatch::shown_path(staged), (dir_ / "out" / "a.png").string());
    EXPECT_EQ(OutputBatch::shown_path("plain/a.png"), "plain/a.png");
    OutputBatch here("", "test");
    EXPECT_EQ(OutputBatch::shown_path(here.stage("b.png")), "b.png");
}

}  // namespace
}  // namespace emoface
