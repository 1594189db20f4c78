#include "emoface/render/video_writer.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstdlib>
#include <filesystem>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/common/output_batch.h"
#include "emoface/render/image_io.h"

namespace emoface::render {

struct VideoWriter::Impl {
    cv::VideoWriter writer;
    cv::Mat bgr;
};

namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

// OpenCV's and FFmpeg's own logging (tens of lines from libx264 or the
// container muxer when an open fails) silenced before the first open: a
// failure is summarised in one line of ours. OpenCV reads
// OPENCV_FFMPEG_LOGLEVEL when its FFmpeg backend loads; -8 is AV_LOG_QUIET.
// A value the user set is kept, for debugging.
void quiet_video_libraries() {
    static const bool done = [] {
        ::setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);
        cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
        return true;
    }();
    (void)done;
}

}  // namespace

void VideoWriter::check(const std::string& path, int width, int height, double fps) {
    const std::string shown = OutputBatch::shown_path(path);
    const std::string ext = lower_extension(path);
    if (ext != ".mp4" && ext != ".avi")
        fail<InputError>("render: {}: video output must end in .mp4 or .avi, got '{}'", shown, ext);
    if (width <= 0 || height <= 0 || width % 2 || height % 2)
        fail<InputError>("render: {}: video frames must have a positive even size, got {}x{}", shown, width,
                         height);
    if (!(fps >= kMinVideoFps && fps <= kMaxVideoFps))
        fail<InputError>("render: {}: frame rate must be {}..{} frames per second, got {}", shown, kMinVideoFps,
                         kMaxVideoFps, fps);
}

VideoWriter::VideoWriter(const std::string& path, int width, int height, double fps)
    : impl_(std::make_unique<Impl>()), path_(path), width_(width), height_(height) {
    check(path, width, height, fps);
    quiet_video_libraries();
    const std::string ext = lower_extension(path);

    const cv::Size size(width, height);
    if (ext == ".mp4") {
        // H.264 under the fourcc names OpenCV's FFmpeg backend accepts.
        for (const char* fourcc : {"avc1", "H264", "X264"}) {
            temp_path_ = temporary_path_for(path_);
            const int code = cv::VideoWriter::fourcc(fourcc[0], fourcc[1], fourcc[2], fourcc[3]);
            if (impl_->writer.open(temp_path_, cv::CAP_FFMPEG, code, fps, size, true)) {
                codec_ = "H.264";
                return;
            }
            discard_temporary(temp_path_);
        }
        path_ = std::filesystem::path(path_).replace_extension(".avi").string();
    }
    temp_path_ = temporary_path_for(path_);
    const int mjpg = cv::VideoWriter::fourcc('M', 'J', 'P', 'G');
    if (impl_->writer.open(temp_path_, mjpg, fps, size, true)) {
        codec_ = "MJPG";
        return;
    }
    discard_temporary(temp_path_);
    fail<EnvironmentError>("render: {}: OpenCV's VideoWriter could open neither an H.264 nor a Motion-JPEG "
                           "encoder for {}x{} at {:g} frames/s (install OpenCV with FFmpeg support)",
                           OutputBatch::shown_path(path), width, height, fps);
}

VideoWriter::~VideoWriter() {
    if (impl_ && impl_->writer.isOpened()) {
        impl_->writer.release();
        discard_temporary(temp_path_);
    }
}

void VideoWriter::write(const ImageRGBA8& frame) {
    if (!impl_->writer.isOpened()) fail("render: {}: the video is already closed", OutputBatch::shown_path(path_));
    if (frame.width != width_ || frame.height != height_ ||
        frame.pixels.size() != std::size_t(width_) * height_ * 4)
        fail("render: {}: frame {} is {}x{}, the video is {}x{}", OutputBatch::shown_path(path_), frames_, frame.width,
             frame.height, width_, height_);
    const cv::Mat rgba(height_, width_, CV_8UC4, const_cast<std::uint8_t*>(frame.pixels.data()));
    cv::cvtColor(rgba, impl_->bgr, cv::COLOR_RGBA2BGR);
    impl_->writer.write(impl_->bgr);
    ++frames_;
}

std::string VideoWriter::close() {
    if (!impl_->writer.isOpened()) fail("render: {}: the video is already closed", OutputBatch::shown_path(path_));
    impl_->writer.release();
    std::error_code ec;
    const auto size = std::filesystem::file_size(temp_path_, ec);
    if (ec || size == 0) {
        discard_temporary(temp_path_);
        fail("render: {}: the encoder wrote nothing", OutputBatch::shown_path(path_));
    }
    commit_temporary(temp_path_, path_, "render");
    return path_;
}

FrameSequenceWriter::FrameSequenceWriter(std::string pattern, int first_index)
    : pattern_(std::move(pattern)), next_(first_index) {
    int conversions = 0;
    for (std::size_t i = 0; i < pattern_.size(); ++i) {
        if (pattern_[i] != '%') continue;
        if (i + 1 < pattern_.size() && pattern_[i + 1] == '%') {
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        // Zero padding only: '-', '+' and ' ' would put spaces or signs in
        // file names.
        while (j < pattern_.size() && pattern_[j] == '0') ++j;
        while (j < pattern_.size() && std::isdigit(static_cast<unsigned char>(pattern_[j]))) ++j;
        if (j >= pattern_.size() || pattern_[j] != 'd' || j - i > 6)
            fail<InputError>("render: frame pattern '{}': only %d conversions (like %04d) are "
                             "allowed, found one at character {}",
                             pattern_, i + 1);
        ++conversions;
        i = j;
    }
    if (conversions != 1)
        fail<InputError>("render: frame pattern '{}': needs exactly one %d (like face_%04d.png), "
                         "found {}",
                         pattern_, conversions);
    // All frames in one folder: the number goes in the file name.
    if (std::filesystem::path(path_for(0)).parent_path() != std::filesystem::path(path_for(1)).parent_path())
        fail<InputError>("render: frame pattern '{}': the %d must be in the file name, not in a folder's",
                         pattern_);
    if (std::filesystem::path(path_for(0)).filename().empty())
        fail<InputError>("render: frame pattern '{}': expected a file name after the last '/'", pattern_);
}

std::string FrameSequenceWriter::path_for(int index) const {
    char buf[4096];
    const int n = std::snprintf(buf, sizeof buf, pattern_.c_str(), index);
    if (n < 0 || std::size_t(n) >= sizeof buf)
        fail<InputError>("render: frame pattern '{}' gives a path that is too long", pattern_);
    return buf;
}

std::string FrameSequenceWriter::write(const ImageRGBA8& frame) {
    const std::string path = path_for(next_);
    write_image(path, frame);
    ++next_;
    return path;
}

}  // namespace emoface::render
