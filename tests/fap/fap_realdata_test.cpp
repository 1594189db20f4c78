// Every third-party FAP file in ${EMOFACE_REALDATA_DIR}/fap parses, with its
// frame count and spot values checked against the file text.
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "emoface/fap/fap_io.h"

namespace emoface::fap {
namespace {

namespace fs = std::filesystem;

const std::string kRealDir = std::string(EMOFACE_REALDATA_DIR) + "/fap";

#define SKIP_WITHOUT_REALDATA()                                                        \
    if (!fs::is_directory(kRealDir))                                                   \
    GTEST_SKIP() << "no real FAP files at " << kRealDir                               \
                 << " (set -DEMOFACE_REALDATA_DIR=<folder holding fap/>)"

struct RealFile {
    const char* file;
    const char* version;
    const char* name;
    double fps;
    std::size_t frames;
    long long last_number;
    std::vector<std::string> warnings;  // without the "path:" prefix
};

const RealFile kRealFiles[] = {
    {"greta_empty.fap", "2.1", "empty", 25, 0, -1, {"4: the last frame transmits no FAP: dropped"}},
    {"isir_1-Welcome_1.fap", "2.1", "1-Welcome_1.fap", 25, 1, 0,
     {"2: mask lines have 69 tokens (Greta's Java writer): the 69th is ignored"}},
    {"vreng_S100_anger.fap", "2.1", "S100_angerFAPs.txt.fap", 10, 23, 22, {}},
    {"vreng_S100_fear.fap", "2.1", "S100_fearFAPs.txt.fap", 10, 14, 13, {}},
    {"vreng_S100_joy.fap", "2.1", "S100_joyFAPs.txt.fap", 10, 16, 15, {}},
    {"vreng_S100_surp.fap", "2.1", "S100_surpFAPs.txt.fap", 10, 15, 14, {}},
    {"vreng_jag.fap", "2.0", "jag", 5, 169, 168, {}},
    {"xface_anger.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 108, 107, {}},
    {"xface_beg.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 107, 106, {}},
    {"xface_disgust.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 107, 106, {}},
    {"xface_fear.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 107, 106, {}},
    {"xface_happy-for.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 107, 106, {}},
    {"xface_hate.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 107, 106, {}},
    {"xface_joy.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 108, 107, {}},
    {"xface_pride.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 107, 106, {}},
    {"xface_test.fap", "2.1", "C:\\Users\\balci\\Work\\FACE\\exml2fap\\files\\TempFile", 25, 43, 42, {}},
};

TEST(FapRealData, EveryFileParses) {
    SKIP_WITHOUT_REALDATA();
    std::size_t seen = 0;
    for (const RealFile& r : kRealFiles) {
        SCOPED_TRACE(r.file);
        const std::string path = kRealDir + "/" + r.file;
        const FapStream s = read_fap_file(path);
        EXPECT_EQ(s.version, r.version);
        EXPECT_EQ(s.name, r.name);
        EXPECT_EQ(s.fps, r.fps);
        EXPECT_EQ(s.frames.size(), r.frames);
        if (!s.frames.empty()) EXPECT_EQ(s.frames.back().number, r.last_number);
        std::vector<std::string> warnings;
        for (const std::string& w : r.warnings) warnings.push_back(path + ":" + w);
        EXPECT_EQ(s.warnings, warnings);
        ++seen;
    }
    // A new file in the folder must be added to the table above.
    std::size_t on_disk = 0;
    for (const auto& entry : fs::directory_iterator(kRealDir))
        on_disk += entry.path().extension() == ".fap";
    EXPECT_EQ(on_disk, seen);
}

struct Spot {
    const char* file;
    std::size_t frame;  // position in the stream
    int fap;
    bool transmitted;
    double value;
};

// Values read off the files' text (frame = values line number k).
TEST(FapRealData, SpotValues) {
    SKIP_WITHOUT_REALDATA();
    const Spot spots[] = {
        {"xface_anger.fap", 54, 3, true, 70},     {"xface_anger.fap", 54, 48, true, 761},
        {"xface_anger.fap", 54, 57, true, -14},   {"xface_anger.fap", 54, 21, false, 0},
        {"xface_beg.fap", 53, 19, false, 0},      {"xface_beg.fap", 53, 50, true, 7282},
        {"xface_test.fap", 42, 3, true, 80},      {"xface_test.fap", 42, 49, true, -3816},
        {"xface_fear.fap", 53, 3, true, 460},     {"xface_fear.fap", 53, 32, true, 50},
        {"vreng_jag.fap", 84, 48, true, -8290},   {"vreng_jag.fap", 84, 49, true, 34169},
        {"vreng_jag.fap", 84, 50, true, 4035},    {"vreng_jag.fap", 84, 19, true, -109},
        {"vreng_jag.fap", 168, 49, true, 9486},   {"vreng_jag.fap", 168, 59, true, -533},
        {"vreng_jag.fap", 0, 1, false, 0},        {"vreng_S100_fear.fap", 7, 31, true, 322},
        {"vreng_S100_fear.fap", 7, 52, true, -191}, {"vreng_S100_fear.fap", 7, 60, true, -69},
        {"vreng_S100_surp.fap", 14, 52, true, -997}, {"vreng_S100_surp.fap", 14, 3, false, 0},
        {"isir_1-Welcome_1.fap", 0, 1, true, 0},
    };
    for (const Spot& s : spots) {
        SCOPED_TRACE(std::string(s.file) + " frame " + std::to_string(s.frame) + " FAP " +
                     std::to_string(s.fap));
        const FapStream stream = read_fap_file(kRealDir + "/" + s.file);
        ASSERT_LT(s.frame, stream.frames.size());
        EXPECT_EQ(stream.frames[s.frame].number, static_cast<long long>(s.frame));
        EXPECT_EQ(stream.frames[s.frame].has(s.fap), s.transmitted);
        EXPECT_EQ(stream.frames[s.frame].get(s.fap), s.value);
    }
    // Greta's Java viseme as a single value: select1 only.
    const FapStream isir = read_fap_file(kRealDir + "/isir_1-Welcome_1.fap");
    EXPECT_EQ(isir.frames[0].viseme, Viseme{});
    EXPECT_EQ(isir.frames[0].transmitted_count(), 1);
}

TEST(FapRealData, RoundTrip) {
    SKIP_WITHOUT_REALDATA();
    for (const RealFile& r : kRealFiles) {
        SCOPED_TRACE(r.file);
        const FapStream s = read_fap_file(kRealDir + "/" + r.file);
        const std::string text = format_fap(s);
        const FapStream again = parse_fap(text, "again.fap");
        EXPECT_TRUE(same_content(s, again));
        EXPECT_TRUE(again.warnings.empty()) << again.warnings.front();
        // Writing is deterministic: the second write is byte-identical.
        EXPECT_EQ(format_fap(again), text);
    }
}

}  // namespace
}  // namespace emoface::fap
