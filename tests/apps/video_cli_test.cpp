// `emoface play --out VIDEO --audio SOUND` end to end, the files read back
// through libavformat (tests/render/media_probe.h): H.264 + AAC of matching
// length, a millisecond-stamped FAP file's frame times kept, a capture CSV
// played as a video, --frames slices that join to the whole with their sound,
// and bad sound files or options refused with one line, exit 2 and nothing
// written.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../render/media_probe.h"
#include "support/run_emoface.h"
#include "support/scratch_dir.h"

namespace {

namespace fs = std::filesystem;
using emoface::testing::args_with;
using emoface::testing::CommandResult;
using emoface::testing::decode_sound;
using emoface::testing::first_loud;
using emoface::testing::Media;
using emoface::testing::MediaStream;
using emoface::testing::probe_media;
using emoface::testing::run_emoface;
using emoface::testing::write_test_wav;
using Args = std::vector<std::string>;

const std::string kTour = std::string(EMOFACE_DATA_DIR) + "/fap/tour.fap";  // 50 frames at 25 frames/s
// Small and coarse: the suite checks files, not looks.
const Args kSmall = {"--size",    "96x72", "--wrinkle-size", "256", "--samples", "1", "--face-resolution", "0.5",
                     "--texture-size", "256"};

class PlayVideo : public ::testing::Test {
protected:
    void SetUp() override { fs::create_directories(out_dir()); }
    fs::path out_dir() const { return scratch_.dir() / "out"; }
    std::string out(const std::string& name) const { return (out_dir() / name).string(); }
    std::vector<std::string> outputs() const {
        std::vector<std::string> names;
        for (const auto& e : fs::directory_iterator(out_dir())) names.push_back(e.path().filename().string());
        std::sort(names.begin(), names.end());
        return names;
    }
    std::string wav(const std::string& name, double seconds, double tone_from = 0) const {
        const std::string path = scratch_.path(name);
        write_test_wav(path, seconds, tone_from);
        return path;
    }

    emoface::testing::ScratchDir scratch_;
};

std::int64_t sound_samples(const Media& m) {
    const MediaStream* s = m.first(AVMEDIA_TYPE_AUDIO);
    return s ? std::llround(s->seconds() * s->sample_rate) : -1;
}

TEST_F(PlayVideo, WritesH264AndAacOfMatchingLength) {
    const std::string tone = wav("tone.wav", 3.0);
    const CommandResult r = run_emoface(args_with({"play", kTour, "--fps", "10", "--out", out("a.mp4"), "--audio", tone}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("20 frames 96x72 at 10 frames/s, H.264 MP4 (crf 20), AAC sound from " + tone),
              std::string::npos)
        << r.out;
    const Media m = probe_media(out("a.mp4"));
    ASSERT_EQ(m.streams.size(), 2u);
    const MediaStream* v = m.first(AVMEDIA_TYPE_VIDEO);
    const MediaStream* a = m.first(AVMEDIA_TYPE_AUDIO);
    ASSERT_TRUE(v && a);
    EXPECT_EQ(v->codec, "h264");
    EXPECT_EQ(a->codec, "aac");
    EXPECT_EQ(v->pts.size(), 20u);
    EXPECT_NEAR(v->seconds(), 2.0, 1e-6);
    EXPECT_NEAR(a->seconds(), v->seconds(), 0.1);  // within a frame at 10 frames/s
    EXPECT_EQ(outputs(), std::vector<std::string>{"a.mp4"});
}

// Frames numbered in milliseconds (0, 33, 67, ...) at 30 frames/s: frame k
// plays at k / 30 s, which is its number in milliseconds, rounded.
TEST_F(PlayVideo, AMillisecondStampedFileKeepsItsFrameTimes) {
    std::string fap = "2.1 stamped 30 8\n";
    std::vector<long long> stamps;
    for (int k = 0; k < 8; ++k) {
        stamps.push_back(std::llround(k * 1000.0 / 30));
        std::string mask;
        for (int fap_number = 1; fap_number <= 68; ++fap_number) mask += fap_number == 3 ? "1 " : "0 ";
        fap += mask + "\n" + std::to_string(stamps.back()) + " " + std::to_string(k * 60) + "\n";
    }
    const std::string file = scratch_.write("stamped.fap", fap);
    const CommandResult r = run_emoface(args_with({"play", file, "--out", out("s.mp4")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const Media m = probe_media(out("s.mp4"));
    const MediaStream* v = m.first(AVMEDIA_TYPE_VIDEO);
    ASSERT_TRUE(v);
    ASSERT_EQ(v->pts.size(), 8u);
    for (std::size_t k = 0; k < 8; ++k) {
        EXPECT_NEAR(v->time(k), double(k) / 30, 1e-9) << "frame " << k;
        EXPECT_NEAR(v->time(k) * 1000, double(stamps[k]), 0.5) << "frame " << k;
    }
}

// Issue 14's acceptance: a hand-written OpenFace 2.0 CSV (a smile growing, the
// older header's leading spaces) plays as a video at its rows' rate.
TEST_F(PlayVideo, ACaptureCsvPlaysAsAVideo) {
    std::string csv = "frame, face_id, timestamp, confidence, success, pose_Rx, pose_Ry, pose_Rz, AU06_r, AU12_r\n";
    for (int k = 0; k < 6; ++k)
        csv += std::to_string(k + 1) + ", 0, " + std::to_string(k * 0.04) + ", 0.98, 1, 0, 0.05, 0, " +
               std::to_string(k * 0.6) + ", " + std::to_string(k * 0.8) + "\n";
    const std::string file = scratch_.write("smile.csv", csv);
    const CommandResult r = run_emoface(args_with({"play", file, "--out", out("c.mp4")}, kSmall));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_NE(r.out.find("6 frames 96x72 at 25 frames/s, H.264 MP4"), std::string::npos) << r.out;
    const Media m = probe_media(out("c.mp4"));
    ASSERT_EQ(m.streams.size(), 1u);
    const MediaStream* v = m.first(AVMEDIA_TYPE_VIDEO);
    ASSERT_TRUE(v);
    EXPECT_EQ(v->codec, "h264");
    EXPECT_EQ(v->pts.size(), 6u);
    EXPECT_NEAR(v->seconds(), 0.24, 1e-6);
}

// --frames 0:4 and 4:10 with the same sound and offset, joined by FFmpeg's
// concat demuxer (README), give the frames and the sound of 0:10.
TEST_F(PlayVideo, SlicesWithSoundJoinToTheWhole) {
    const std::string click = wav("click.wav", 3.0, 0.5);
    for (const auto& [slice, name] : {std::pair{"0:4", "a.mp4"}, {"4:10", "b.mp4"}, {"0:10", "whole.mp4"}}) {
        const CommandResult r = run_emoface(args_with(
            {"play", kTour, "--fps", "10", "--frames", slice, "--out", out(name), "--audio", click, "--audio-offset", "0.2"},
            kSmall));
        ASSERT_EQ(r.exit_code, 0) << slice << ": " << r.err;
    }
    const std::string list = scratch_.write("list.txt", "file '" + out("a.mp4") + "'\nfile '" + out("b.mp4") + "'\n");
    const Media joined = probe_media(list, "concat");
    const Media whole = probe_media(out("whole.mp4"));
    ASSERT_TRUE(joined.first(AVMEDIA_TYPE_VIDEO) && whole.first(AVMEDIA_TYPE_VIDEO));
    EXPECT_EQ(joined.first(AVMEDIA_TYPE_VIDEO)->pts.size(), 10u);
    EXPECT_NEAR(joined.first(AVMEDIA_TYPE_VIDEO)->seconds(), whole.first(AVMEDIA_TYPE_VIDEO)->seconds(), 1e-3);
    // 0.4 s + 0.6 s of sound, to the sample.
    EXPECT_EQ(sound_samples(probe_media(out("a.mp4"))) + sound_samples(probe_media(out("b.mp4"))),
              sound_samples(whole));
    EXPECT_EQ(sound_samples(whole), 48000);
    // The click, 0.5 s into the sound, 0.2 s late: at 0.7 s of the whole,
    // 0.3 s into the second piece.
    int rate = 0;
    const std::vector<float> w = decode_sound(out("whole.mp4"), rate);
    EXPECT_NEAR(first_loud(w, rate), 0.7, 0.003);
    const std::vector<float> b = decode_sound(out("b.mp4"), rate);
    EXPECT_NEAR(first_loud(b, rate), 0.3, 0.003);
}

struct BadSound {
    const char* name;
    Args args;            // SOUND, NOTSOUND and OUT/ stand for files of the test
    const char* message;  // a part of the one line on stderr
};

class PlayVideoBadSound : public PlayVideo, public ::testing::WithParamInterface<BadSound> {};

TEST_P(PlayVideoBadSound, ExitsTwoWithOneLineAndWritesNothing) {
    const BadSound& c = GetParam();
    Args args = c.args;
    for (std::string& a : args) {
        if (a == "SOUND") a = wav("tone.wav", 1.0);
        else if (a == "NOTSOUND") a = scratch_.write("notes.wav", "these are words, not sound\n");
        else if (a.rfind("OUT/", 0) == 0) a = out(a.substr(4));
    }
    const CommandResult r = run_emoface(args_with(args, kSmall));
    EXPECT_EQ(r.exit_code, 2) << c.name << "\nstdout: " << r.out << "\nstderr: " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.name << "\nstderr: " << r.err;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
    EXPECT_TRUE(outputs().empty()) << c.name;
}

INSTANTIATE_TEST_SUITE_P(
    Table, PlayVideoBadSound,
    ::testing::Values(
        BadSound{"Missing", {"play", kTour, "--out", "OUT/a.mp4", "--audio", "OUT/none.wav"}, "none.wav: expected a regular file"},
        BadSound{"NotSound", {"play", kTour, "--out", "OUT/a.mp4", "--audio", "NOTSOUND"}, "notes.wav: expected"},
        BadSound{"Empty", {"play", kTour, "--out", "OUT/a.mp4", "--audio", ""}, "--audio '': expected a sound file"},
        BadSound{"FramePattern", {"play", kTour, "--out", "OUT/f%04d.png", "--audio", "SOUND"},
                 "--audio needs a video (.mp4, .mkv, .webm, .avi), not a frame pattern"},
        BadSound{"OffsetWithoutSound", {"play", kTour, "--out", "OUT/a.mp4", "--audio-offset", "1"},
                 "--audio-offset shifts the sound of --audio, which is not given"},
        BadSound{"OffsetNotFinite", {"play", kTour, "--out", "OUT/a.mp4", "--audio", "SOUND", "--audio-offset", "inf"},
                 "--audio-offset"},
        BadSound{"CrfTooHigh", {"play", kTour, "--out", "OUT/a.mp4", "--crf", "52"}, "expected a crf of 0..51 for H.264"},
        BadSound{"CrfNegative", {"play", kTour, "--out", "OUT/a.webm", "--crf", "-1"}, "--crf -1: expected 0..63"},
        BadSound{"CrfForMotionJpeg", {"play", kTour, "--out", "OUT/a.avi", "--crf", "20"}, ".avi video has no crf"}),
    [](const auto& info) { return std::string(info.param.name); });

}  // namespace
