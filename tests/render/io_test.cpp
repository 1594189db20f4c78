// Output: PNG/EXR round trips, no partial files on failure, videos and
// numbered sequences.
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/render/image_io.h"
#include "emoface/render/video_writer.h"

namespace {

namespace fs = std::filesystem;
using namespace emoface::render;

class TempDir {
public:
    TempDir() {
        path_ = fs::temp_directory_path() /
                ("emoface_render_io_" + std::to_string(::testing::UnitTest::GetInstance()
                                                           ->random_seed()) +
                 "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() { fs::remove_all(path_); }
    std::string file(const std::string& name) const { return (path_ / name).string(); }
    std::size_t count() const {
        return std::size_t(std::distance(fs::directory_iterator(path_), fs::directory_iterator()));
    }

private:
    fs::path path_;
};

ImageRGBA8 gradient(int w, int h) {
    ImageRGBA8 img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::uint8_t* p = img.at(x, y);
            p[0] = std::uint8_t(x * 255 / (w - 1));
            p[1] = std::uint8_t(y * 255 / (h - 1));
            p[2] = std::uint8_t((x * 7 + y * 13) % 256);
            p[3] = std::uint8_t(255 - (x + y) % 64);
        }
    return img;
}

std::string head(const std::string& path, int n) {
    std::ifstream f(path, std::ios::binary);
    std::string s(std::size_t(n), '\0');
    f.read(s.data(), n);
    return s;
}

TEST(ImageIo, PngRoundTripIsExact) {
    TempDir dir;
    const ImageRGBA8 img = gradient(37, 21);
    write_image(dir.file("a.png"), img);
    EXPECT_EQ(dir.count(), 1u) << "no temporary file left behind";
    const ImageRGBA8 back = read_image_rgba8(dir.file("a.png"));
    ASSERT_EQ(back.width, 37);
    ASSERT_EQ(back.height, 21);
    EXPECT_EQ(back.pixels, img.pixels);
    EXPECT_EQ(head(dir.file("a.png"), 4), "\x89PNG");
}

TEST(ImageIo, ExrRoundTripKeepsHalfPrecision) {
    TempDir dir;
    ImageRGBA32F img(5, 3);
    for (std::size_t i = 0; i < img.pixels.size(); ++i) img.pixels[i] = -2.0f + 0.37f * float(i);
    write_image(dir.file("n.exr"), img);
    const ImageRGBA32F back = read_image_rgba32f(dir.file("n.exr"));
    ASSERT_EQ(back.pixels.size(), img.pixels.size());
    for (std::size_t i = 0; i < img.pixels.size(); ++i)
        EXPECT_NEAR(back.pixels[i], img.pixels[i], std::fabs(img.pixels[i]) * 1e-3f + 1e-3f) << i;
}

TEST(ImageIo, FailuresLeaveNoFile) {
    TempDir dir;
    const ImageRGBA8 img = gradient(8, 8);
    // A folder that does not exist.
    EXPECT_THROW(write_image(dir.file("missing/a.png"), img), emoface::Error);
    // An extension no format claims.
    EXPECT_THROW(write_image(dir.file("a.notaformat"), img), emoface::InputError);
    // A malformed image.
    ImageRGBA8 bad = img;
    bad.pixels.resize(10);
    EXPECT_THROW(write_image(dir.file("bad.png"), bad), emoface::Error);
    EXPECT_EQ(dir.count(), 0u);
    // Reading what is not there, or not an image.
    EXPECT_THROW(read_image_rgba8(dir.file("none.png")), emoface::InputError);
    std::ofstream(dir.file("text.png")) << "not a png";
    EXPECT_THROW(read_image_rgba8(dir.file("text.png")), emoface::InputError);
}

TEST(ImageIo, OverwriteReplacesWholeFile) {
    TempDir dir;
    write_image(dir.file("a.png"), gradient(64, 64));
    write_image(dir.file("a.png"), gradient(4, 4));
    EXPECT_EQ(read_image_rgba8(dir.file("a.png")).width, 4);
    EXPECT_EQ(dir.count(), 1u);
}

struct VideoCase {
    const char* name;
    const char* file;
    // Magic bytes the finished file must have at offset 0 or 4.
    const char* magic;
    int magic_offset;
};

class Video : public ::testing::TestWithParam<VideoCase> {};

TEST_P(Video, WritesAFileOnlyWhenClosed) {
    const VideoCase& c = GetParam();
    TempDir dir;
    std::string final_path;
    {
        VideoWriter video(dir.file(c.file), 64, 48, 25.0);
        for (int i = 0; i < 10; ++i) video.write(gradient(64, 48));
        EXPECT_EQ(video.frames_written(), 10);
        EXPECT_FALSE(fs::exists(video.path())) << "nothing at the destination before close()";
        final_path = video.close();
        EXPECT_TRUE(video.codec() == "H.264" || video.codec() == "MJPG") << video.codec();
        std::printf("%s: %s\n", c.file, video.codec().c_str());
        if (video.codec() == "MJPG") EXPECT_EQ(fs::path(final_path).extension(), ".avi");
    }
    EXPECT_TRUE(fs::exists(final_path));
    EXPECT_EQ(dir.count(), 1u);
    if (fs::path(final_path).extension() == fs::path(c.file).extension())
        EXPECT_EQ(head(final_path, c.magic_offset + 4).substr(c.magic_offset), c.magic);
}

INSTANTIATE_TEST_SUITE_P(Containers, Video,
                         ::testing::Values(VideoCase{"mp4", "v.mp4", "ftyp", 4},
                                           VideoCase{"avi", "v.avi", "RIFF", 0}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(Video, AbandonedVideoLeavesNoFile) {
    TempDir dir;
    {
        VideoWriter video(dir.file("v.avi"), 32, 32, 10.0);
        video.write(gradient(32, 32));
    }
    EXPECT_EQ(dir.count(), 0u);
}

TEST(Video, BadArgumentsAreErrors) {
    TempDir dir;
    EXPECT_THROW(VideoWriter(dir.file("v.mov"), 32, 32, 10), emoface::InputError);
    EXPECT_THROW(VideoWriter(dir.file("v.avi"), 31, 32, 10), emoface::InputError);
    EXPECT_THROW(VideoWriter(dir.file("v.avi"), 32, 32, 0), emoface::InputError);
    VideoWriter video(dir.file("v.avi"), 32, 32, 10);
    EXPECT_THROW(video.write(gradient(16, 16)), emoface::Error);
}

TEST(FrameSequence, NumbersFramesFromThePattern) {
    TempDir dir;
    FrameSequenceWriter seq(dir.file("face_%04d.png"), 7);
    EXPECT_EQ(seq.write(gradient(8, 8)), dir.file("face_0007.png"));
    EXPECT_EQ(seq.write(gradient(8, 8)), dir.file("face_0008.png"));
    EXPECT_EQ(seq.next_index(), 9);
    EXPECT_EQ(read_image_rgba8(dir.file("face_0008.png")).pixels, gradient(8, 8).pixels);
    EXPECT_EQ(FrameSequenceWriter("a%%_%d.png").path_for(3), "a%_3.png");
}

TEST(FrameSequence, PatternsNeedExactlyOneIntegerConversion) {
    struct Bad {
        const char* pattern;
        const char* message;
    };
    const Bad bad[] = {
        {"face.png", "render: frame pattern 'face.png': needs exactly one %d (like face_%04d.png), found 0"},
        {"%d_%d.png", "render: frame pattern '%d_%d.png': needs exactly one %d (like face_%04d.png), found 2"},
        {"%s.png", "render: frame pattern '%s.png': only %d conversions (like %04d) are allowed, found one at character 1"},
        {"a%04x.png", "render: frame pattern 'a%04x.png': only %d conversions (like %04d) are allowed, found one at character 2"},
        {"%0999999d.png", "render: frame pattern '%0999999d.png': only %d conversions (like %04d) are allowed, found one at character 1"},
    };
    for (const Bad& b : bad) {
        try {
            FrameSequenceWriter w(b.pattern);
            ADD_FAILURE() << "accepted " << b.pattern;
        } catch (const emoface::InputError& e) {
            EXPECT_EQ(std::string(e.what()), b.message);
        }
    }
}

}  // namespace
