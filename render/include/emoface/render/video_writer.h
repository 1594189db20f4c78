#pragma once
// Animation output (target emoface::render_io): a video file through OpenCV's
// VideoWriter (its and FFmpeg's own logging silenced: failures are one line), or a numbered sequence of still images. Neither leaves a
// partial file: the video is written under a temporary name and renamed by
// close(); each still is written and renamed on its own.
#include <memory>
#include <string>

#include "emoface/render/image.h"

namespace emoface::render {

// The frame rates written: FFmpeg's encoders get no time base below about
// 0.01 frames/s through OpenCV; this low or this high is a slip, not a wish.
inline constexpr double kMinVideoFps = 0.1, kMaxVideoFps = 1000.0;

class VideoWriter {
public:
    // `path` ending in .mp4: H.264 when OpenCV's backend has an encoder for
    // it, else Motion-JPEG in an .avi next to it (path() tells which);
    // ending in .avi: Motion-JPEG. Other extensions are an InputError.
    VideoWriter(const std::string& path, int width, int height, double fps);
    // The checks the constructor makes on its arguments, for a command to
    // make before any slow work: InputError for another extension, an odd or
    // empty size, or a frame rate outside kMinVideoFps..kMaxVideoFps.
    static void check(const std::string& path, int width, int height, double fps);
    ~VideoWriter();  // without close(): the temporary file is removed
    VideoWriter(const VideoWriter&) = delete;
    VideoWriter& operator=(const VideoWriter&) = delete;

    // Frames must have the size given to the constructor.
    void write(const ImageRGBA8& frame);
    // Finishes the file and moves it to path(); returns path().
    std::string close();

    const std::string& path() const { return path_; }
    // "H.264" or "MJPG".
    const std::string& codec() const { return codec_; }
    int frames_written() const { return frames_; }

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    std::string path_, temp_path_, codec_;
    int width_, height_, frames_ = 0;
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
