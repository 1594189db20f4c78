#pragma once
// Animation output (target emoface::render_io): a video file through
// FFmpeg's libraries (libavformat, libavcodec, libswscale, libswresample),
// with an optional sound track, or a numbered sequence of still images.
// Neither leaves a partial file: the video is written under a temporary name
// and renamed by close(); each still is written and renamed on its own.
//
// Containers, by the path's extension:
//   .mp4   H.264 (libx264) + AAC, the index at the front (faststart)
//   .mkv   H.264 (libx264) + AAC
//   .webm  VP9 (libvpx-vp9) + Opus (libopus)
//   .avi   Motion-JPEG + 16-bit PCM
// Frame n of a file is shown at n / fps, in a time base of exactly 1 / fps
// (a rational: 25, 29.97 = 2997/100, ...), so every frame keeps the time its
// animation gives it. FFmpeg's own logging is silenced (a failure is one line
// of ours) unless EMOFACE_FFMPEG_LOGLEVEL names one of its levels (e.g. 32).
#include <cstdint>
#include <memory>
#include <string>

#include "emoface/render/image.h"

namespace emoface::render {

// The frame rates written: lower or higher than this is a slip, not a wish.
inline constexpr double kMinVideoFps = 0.1, kMaxVideoFps = 1000.0;
// Far above any real sound track (an hour of 48 kHz stereo WAV is 660 MiB).
inline constexpr std::uint64_t kMaxAudioFileBytes = std::uint64_t(4) << 30;

struct VideoOptions {
    double fps = 25;
    // Constant rate factor (quality; lower is better, larger files): H.264
    // 0..51, VP9 0..63; -1 takes kDefaultCrf of the codec. Motion-JPEG has
    // none (a value other than -1 is an InputError).
    int crf = -1;
    // A sound file (anything FFmpeg decodes: WAV, MP3, OGG, FLAC, a video's
    // sound track...) muxed under the frames; empty: no sound.
    std::string audio;
    // Seconds the sound starts after the animation's frame 0 (negative: its
    // first seconds are cut). Where it does not reach, there is silence; it
    // ends with the last frame.
    double audio_offset = 0;
    // The animation's frame that this file's frame 0 is (play --frames A:B
    // gives A): the file's sound is the stretch under these frames, so the
    // pieces of one animation carry consecutive, non-overlapping samples.
    std::int64_t first_frame = 0;
};

class VideoWriter {
public:
    VideoWriter(const std::string& path, int width, int height, const VideoOptions& options);
    VideoWriter(const std::string& path, int width, int height, double fps)
        : VideoWriter(path, width, height, with_fps(fps)) {}
    // The checks the constructor makes on its arguments, for a command to
    // make before any slow work: InputError for an extension not listed
    // above, an odd or empty size, a frame rate outside
    // kMinVideoFps..kMaxVideoFps, a crf outside the codec's range, a sound
    // file that is missing, not a regular file, or has no sound FFmpeg
    // decodes (its first frame is decoded), or an offset that is not finite.
    static void check(const std::string& path, int width, int height, const VideoOptions& options);
    // ".mp4, .mkv, .webm, .avi": for messages.
    static const char* extensions();
    static bool has_video_extension(const std::string& path);
    ~VideoWriter();  // without close(): the temporary file is removed
    VideoWriter(const VideoWriter&) = delete;
    VideoWriter& operator=(const VideoWriter&) = delete;

    // Frames must have the size given to the constructor. They are encoded
    // on the writer's own thread (a few frames queued), so the caller
    // renders the next frame meanwhile; an encoder failure is thrown by the
    // next write() or by close().
    void write(const ImageRGBA8& frame);
    void write(ImageRGBA8&& frame);
    // Finishes the file (the sound padded with silence or cut to end with
    // the last frame) and moves it to path(); returns path().
    std::string close();

    const std::string& path() const { return path_; }
    // "H.264", "VP9" or "MJPG".
    const std::string& codec() const { return codec_; }
    // "AAC", "Opus", "PCM", or "" without sound.
    const std::string& audio_codec() const { return audio_codec_; }
    // The crf used (-1 for Motion-JPEG).
    int crf() const { return crf_; }
    int frames_written() const { return frames_; }

private:
    static VideoOptions with_fps(double fps) {
        VideoOptions o;
        o.fps = fps;
        return o;
    }
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::string path_, temp_path_, codec_, audio_codec_;
    int width_, height_, frames_ = 0, crf_ = -1;
    bool closed_ = false;
};

// Writes frame i to the printf-style pattern with one integer conversion,
// e.g. "out/face_%04d.png" -> out/face_0000.png, out/face_0001.png, ...
class FrameSequenceWriter {
public:
    // Throws emoface::InputError unless the pattern has exactly one %d
    // conversion (flags and width allowed), in the file name, and no other
    // %, except %%.
    explicit FrameSequenceWriter(std::string pattern, int first_index = 0);
    // Writes the next frame; returns its path.
    std::string write(const ImageRGBA8& frame);
    std::string path_for(int index) const;
    int next_index() const { return next_; }

private:
    std::string pattern_;
    int next_;
};

}  // namespace emoface::render
