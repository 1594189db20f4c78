// VideoWriter read back through libavformat: each container's streams and
// codecs, the frame count and every frame's time, the sound's length and where
// a click in it lands (offset, slices), slices joined by FFmpeg's concat
// demuxer, and bad sound files refused before anything is written.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "emoface/common/error.h"
#include "emoface/render/video_writer.h"
#include "media_probe.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using namespace emoface::render;
using emoface::testing::decode_sound;
using emoface::testing::first_loud;
using emoface::testing::Media;
using emoface::testing::MediaStream;
using emoface::testing::probe_media;
using emoface::testing::ScratchDir;
using emoface::testing::write_test_wav;

ImageRGBA8 frame_of(int w, int h, int k) {
    ImageRGBA8 img(w, h);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            std::uint8_t* p = &img.pixels[(std::size_t(y) * w + x) * 4];
            p[0] = std::uint8_t(x * 255 / w);
            p[1] = std::uint8_t((y + 3 * k) * 255 / (h + 3 * 20));
            p[2] = std::uint8_t(k * 12);
            p[3] = 255;
        }
    return img;
}

// Writes `frames` frames of 64x48 and returns the file's path.
std::string write_video(const std::string& path, int frames, const VideoOptions& options) {
    VideoWriter video(path, 64, 48, options);
    for (int k = 0; k < frames; ++k) video.write(frame_of(64, 48, int(options.first_frame) + k));
    return video.close();
}

VideoOptions options(double fps, const std::string& audio = "", double offset = 0, std::int64_t first = 0) {
    VideoOptions o;
    o.fps = fps;
    o.audio = audio;
    o.audio_offset = offset;
    o.first_frame = first;
    return o;
}

std::size_t files_in(const fs::path& dir) {
    return std::size_t(std::distance(fs::directory_iterator(dir), fs::directory_iterator()));
}

struct ContainerCase {
    const char* name;
    const char* file;
    const char* video_codec;  // FFmpeg's names, as the file declares them
    const char* audio_codec;
};

class Containers : public ::testing::TestWithParam<ContainerCase> {};

TEST_P(Containers, HoldTheFramesAndTheSoundForAsLong) {
    const ContainerCase& c = GetParam();
    ScratchDir dir;
    write_test_wav(dir.path("tone.wav"), 2.0);
    const std::string file = write_video(dir.path(c.file), 10, options(25, dir.path("tone.wav")));
    EXPECT_EQ(file, dir.path(c.file));
    const Media m = probe_media(file);
    ASSERT_EQ(m.streams.size(), 2u);
    const MediaStream* v = m.first(AVMEDIA_TYPE_VIDEO);
    const MediaStream* a = m.first(AVMEDIA_TYPE_AUDIO);
    ASSERT_TRUE(v && a);
    EXPECT_EQ(v->codec, c.video_codec);
    EXPECT_EQ(a->codec, c.audio_codec);
    EXPECT_EQ(v->width, 64);
    EXPECT_EQ(v->height, 48);
    EXPECT_EQ(v->pts.size(), 10u);
    EXPECT_NEAR(v->seconds(), 0.4, 1e-3);
    // The sound ends with the last frame although the WAV is longer.
    EXPECT_NEAR(a->seconds(), 0.4, 1.0 / 25);
    EXPECT_EQ(a->channels, 1);
    EXPECT_EQ(files_in(dir.dir()), 2u) << "the WAV and the video, no temporary";
}

INSTANTIATE_TEST_SUITE_P(
    Video, Containers,
    ::testing::Values(ContainerCase{"mp4", "v.mp4", "h264", "aac"}, ContainerCase{"mkv", "v.mkv", "h264", "aac"},
                      ContainerCase{"webm", "v.webm", "vp9", "opus"},
                      ContainerCase{"avi", "v.avi", "mjpeg", "pcm_s16le"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(Video, WithoutSoundHasOneStream) {
    ScratchDir dir;
    const Media m = probe_media(write_video(dir.path("v.mp4"), 5, options(10)));
    ASSERT_EQ(m.streams.size(), 1u);
    EXPECT_EQ(m.streams[0].codec, "h264");
    EXPECT_EQ(m.streams[0].pts.size(), 5u);
}

// Frame k is at exactly k / fps, also for rates that are no whole number of
// milliseconds or frames per second.
TEST(Video, EveryFrameKeepsItsTime) {
    for (const double fps : {25.0, 30.0, 29.97, 1000.0 / 3}) {
        ScratchDir dir;
        const Media m = probe_media(write_video(dir.path("v.mp4"), 12, options(fps)));
        const MediaStream* v = m.first(AVMEDIA_TYPE_VIDEO);
        ASSERT_TRUE(v);
        ASSERT_EQ(v->pts.size(), 12u) << fps;
        for (std::size_t k = 0; k < 12; ++k) EXPECT_NEAR(v->time(k), double(k) / fps, 1e-9) << fps << " frame " << k;
        EXPECT_NEAR(v->seconds(), 12 / fps, 1e-9) << fps;
    }
}

// A click at 0.5 s of the sound plays at 0.5 s + offset of the animation,
// and a file starting at the animation's frame A has it A / fps earlier.
TEST(Video, TheSoundLinesUpWithTheAnimation) {
    ScratchDir dir;
    write_test_wav(dir.path("click.wav"), 2.0, 0.5);
    struct Case {
        double offset;
        std::int64_t first_frame;
        double click;  // seconds into the file
    };
    for (const Case& c : {Case{0, 0, 0.5}, Case{0.25, 0, 0.75}, Case{-0.2, 0, 0.3}, Case{0, 10, 0.1},
                          Case{0.1, 5, 0.4}}) {
        const std::string file = write_video(dir.path("v.mp4"), 25, options(25, dir.path("click.wav"), c.offset,
                                                                           c.first_frame));
        int rate = 0;
        const std::vector<float> sound = decode_sound(file, rate);
        EXPECT_EQ(rate, 48000);
        EXPECT_NEAR(first_loud(sound, rate), c.click, 0.003) << "offset " << c.offset << ", first frame "
                                                            << c.first_frame;
        EXPECT_NEAR(double(sound.size()) / rate, 1.0, 1.0 / 25);
    }
}

// Sound sampled at a rate the encoder lacks, or with more than two channels,
// is resampled and mixed down.
TEST(Video, OtherRatesAndChannelsAreConverted) {
    ScratchDir dir;
    write_test_wav(dir.path("a.wav"), 1.0, 0.2, 11025, 3);
    const std::string file = write_video(dir.path("v.webm"), 10, options(25, dir.path("a.wav")));
    const Media m = probe_media(file);
    const MediaStream* a = m.first(AVMEDIA_TYPE_AUDIO);
    ASSERT_TRUE(a);
    EXPECT_EQ(a->sample_rate, 48000);  // Opus
    EXPECT_EQ(a->channels, 2);
    int rate = 0;
    const std::vector<float> sound = decode_sound(file, rate);
    EXPECT_NEAR(first_loud(sound, rate), 0.2, 0.005);
}

// Pieces written with first_frame join, through FFmpeg's concat demuxer, to
// the whole: every frame, the sound as long, the click at the same time.
TEST(Video, SlicesJoinToTheWhole) {
    ScratchDir dir;
    write_test_wav(dir.path("click.wav"), 3.0, 0.5);
    const std::string whole = write_video(dir.path("whole.mp4"), 20, options(25, dir.path("click.wav"), 0.1));
    write_video(dir.path("a.mp4"), 7, options(25, dir.path("click.wav"), 0.1, 0));
    write_video(dir.path("b.mp4"), 13, options(25, dir.path("click.wav"), 0.1, 7));
    std::ofstream(dir.path("list.txt")) << "file '" << dir.path("a.mp4") << "'\nfile '" << dir.path("b.mp4") << "'\n";

    const Media joined = probe_media(dir.path("list.txt"), "concat");
    const Media one = probe_media(whole);
    ASSERT_EQ(joined.streams.size(), 2u);
    const MediaStream* v = joined.first(AVMEDIA_TYPE_VIDEO);
    ASSERT_TRUE(v);
    ASSERT_EQ(v->pts.size(), 20u);
    for (std::size_t k = 0; k < 20; ++k) EXPECT_NEAR(v->time(k), double(k) / 25, 1e-3) << "frame " << k;
    EXPECT_NEAR(v->seconds(), one.first(AVMEDIA_TYPE_VIDEO)->seconds(), 1e-3);

    // Sound lengths as the containers give them (decoders add the last AAC
    // frame's padding): 0.28 s + 0.52 s = 0.8 s at 48 kHz, to the sample.
    const auto samples = [](const Media& m) {
        const MediaStream* s = m.first(AVMEDIA_TYPE_AUDIO);
        return s ? std::llround(s->seconds() * s->sample_rate) : -1;
    };
    EXPECT_EQ(samples(probe_media(dir.path("a.mp4"))), 13440);
    EXPECT_EQ(samples(probe_media(dir.path("b.mp4"))), 24960);
    EXPECT_EQ(samples(one), 38400);
    EXPECT_NEAR(joined.first(AVMEDIA_TYPE_AUDIO)->seconds(), 0.8, 1.0 / 25);

    int rate = 0, whole_rate = 0;
    const std::vector<float> a = decode_sound(dir.path("a.mp4"), rate);
    const std::vector<float> b = decode_sound(dir.path("b.mp4"), rate);
    const std::vector<float> w = decode_sound(whole, whole_rate);
    EXPECT_LT(first_loud(a, rate), 0) << "the click comes after the first piece";
    EXPECT_NEAR(first_loud(b, rate) + 0.28, first_loud(w, whole_rate), 0.003);
    EXPECT_NEAR(first_loud(w, whole_rate), 0.6, 0.003);
}

struct BadSound {
    const char* name;
    const char* file;      // in the scratch folder
    const char* contents;  // nullptr: no such file
    const char* message;   // a part of the one-line message
};

class BadSounds : public ::testing::TestWithParam<BadSound> {};

TEST_P(BadSounds, AreRefusedBeforeAnythingIsWritten) {
    const BadSound& c = GetParam();
    ScratchDir dir;
    if (c.contents) std::ofstream(dir.path(c.file), std::ios::binary) << c.contents;
    const std::size_t before = files_in(dir.dir());
    try {
        VideoWriter video(dir.path("v.mp4"), 64, 48, options(25, dir.path(c.file)));
        FAIL() << "accepted " << c.file;
    } catch (const emoface::InputError& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find(c.file), std::string::npos) << what;
        EXPECT_NE(what.find(c.message), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
    EXPECT_THROW(VideoWriter::check(dir.path("v.mp4"), 64, 48, options(25, dir.path(c.file))), emoface::InputError);
    EXPECT_EQ(files_in(dir.dir()), before);
}

INSTANTIATE_TEST_SUITE_P(
    Video, BadSounds,
    ::testing::Values(BadSound{"Missing", "none.wav", nullptr, "no such file"},
                      BadSound{"Empty", "empty.wav", "", "expected a sound file FFmpeg reads"},
                      BadSound{"Text", "notes.mp3", "this is not sound at all, just words\n", "expected"},
                      BadSound{"TruncatedWav", "short.wav", "RIFF\x24\x00\x00\x00WAVEfmt ", "expected"}),
    [](const auto& info) { return std::string(info.param.name); });

TEST(Video, AVideoWithoutSoundIsRefusedAsSound) {
    ScratchDir dir;
    write_video(dir.path("silent.mp4"), 3, options(25));
    try {
        VideoWriter video(dir.path("v.mp4"), 64, 48, options(25, dir.path("silent.mp4")));
        FAIL() << "accepted a file without sound";
    } catch (const emoface::InputError& e) {
        EXPECT_NE(std::string(e.what()).find("expected a sound stream, found none"), std::string::npos) << e.what();
    }
}

TEST(Video, BadOptionsAreInputErrors) {
    ScratchDir dir;
    auto crf = [](int value) {
        VideoOptions o = options(25);
        o.crf = value;
        return o;
    };
    const std::string mp4 = dir.path("v.mp4");
    EXPECT_THROW(VideoWriter::check(dir.path("v.mov"), 32, 32, options(25)), emoface::InputError);
    EXPECT_THROW(VideoWriter::check(mp4, 31, 32, options(25)), emoface::InputError);
    EXPECT_THROW(VideoWriter::check(mp4, 32, 32, options(0)), emoface::InputError);
    EXPECT_THROW(VideoWriter::check(mp4, 32, 32, crf(52)), emoface::InputError);
    EXPECT_NO_THROW(VideoWriter::check(mp4, 32, 32, crf(51)));
    EXPECT_NO_THROW(VideoWriter::check(dir.path("v.webm"), 32, 32, crf(63)));
    EXPECT_THROW(VideoWriter::check(dir.path("v.webm"), 32, 32, crf(64)), emoface::InputError);
    EXPECT_THROW(VideoWriter::check(dir.path("v.avi"), 32, 32, crf(10)), emoface::InputError);
    EXPECT_THROW(VideoWriter::check(mp4, 32, 32, options(25, "", std::nan(""))), emoface::InputError);
    EXPECT_EQ(files_in(dir.dir()), 0u);
}

// A lower crf keeps more: a larger file of the same frames.
TEST(Video, CrfSetsTheQuality) {
    ScratchDir dir;
    VideoOptions fine = options(25), coarse = options(25);
    fine.crf = 10;
    coarse.crf = 40;
    const auto size = [&](const std::string& name, const VideoOptions& o) {
        VideoWriter video(dir.path(name), 64, 48, o);
        EXPECT_EQ(video.crf(), o.crf);
        for (int k = 0; k < 10; ++k) video.write(frame_of(64, 48, k));
        return fs::file_size(video.close());
    };
    EXPECT_GT(size("fine.mp4", fine), size("coarse.mp4", coarse));
}

// Destroyed without close(), its encoder thread mid-file: no file, no
// temporary.
TEST(Video, AbandonedVideoLeavesNoFile) {
    ScratchDir dir;
    write_test_wav(dir.path("tone.wav"), 1.0);
    {
        VideoWriter video(dir.path("v.mp4"), 64, 48, options(25, dir.path("tone.wav")));
        for (int k = 0; k < 3; ++k) video.write(frame_of(64, 48, k));
    }
    EXPECT_EQ(files_in(dir.dir()), 1u) << "only the WAV";
}

}  // namespace
