#include "progress.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <unistd.h>

#include <fmt/format.h>

namespace emoface::apps {

namespace {

std::string format_duration(double seconds) {
    const long s = std::lround(std::max(0.0, seconds));
    if (s < 60) return fmt::format("{} s", s);
    if (s < 3600) return fmt::format("{}:{:02d} min", s / 60, s % 60);
    return fmt::format("{}:{:02d} h", s / 3600, (s / 60) % 60);
}

}  // namespace

void FrameTimeAverage::add(double seconds, int frames) {
    if (frames <= 0) return;
    const double per_frame = seconds / frames;
    if (frames_ == 0) {
        mean_ = per_frame;
    } else {
        // n frames at once count as n steps of the average, so the result
        // does not depend on how often the caller reports.
        const double weight = 1.0 - std::pow(1.0 - alpha_, frames);
        mean_ += weight * (per_frame - mean_);
    }
    frames_ += frames;
}

ProgressBar::ProgressBar(std::string label, int total)
    : ProgressBar(std::move(label), total, isatty(fileno(stderr)) != 0) {}

ProgressBar::ProgressBar(std::string label, int total, bool enabled)
    : label_(std::move(label)),
      total_(std::max(total, 0)),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()),
      last_update_(start_),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() {
    if (line_open_) std::fputc('\n', stderr);
}

std::string ProgressBar::format(const std::string& label, int done, int total, double elapsed,
                                double seconds_per_frame, int bar_width) {
    done = std::clamp(done, 0, std::max(total, 0));
    const double fraction = total > 0 ? double(done) / total : 1.0;
    const int filled = int(std::floor(fraction * bar_width));
    std::string bar(std::size_t(filled), '#');
    bar.append(std::size_t(bar_width - filled), '.');
    const int digits = int(std::to_string(std::max(total, 0)).size());
    std::string line = fmt::format("{} [{}] {:>{}}/{}", label, bar, done, digits, total);
    if (done >= total && done > 0 && elapsed > 0) {
        line += fmt::format("  {:.1f} frames/s  {}", done / elapsed, format_duration(elapsed));
    } else if (done > 0 && seconds_per_frame > 0) {
        line += fmt::format("  {:.1f} frames/s  {} left", 1.0 / seconds_per_frame,
                            format_duration((total - done) * seconds_per_frame));
    }
    return line;
}

void ProgressBar::draw(int done) {
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const std::string line =
        format(label_, done, total_, elapsed, frame_time_.empty() ? 0.0 : frame_time_.seconds_per_frame());
    // Spaces wipe what is left of a longer previous line; no fixed width, so
    // a narrow terminal does not wrap the line (a wrapped line is not
    // redrawn in place: each redraw would leave a copy above).
    const std::size_t pad = drawn_width_ > line.size() ? drawn_width_ - line.size() : 0;
    std::fprintf(stderr, "\r%s%*s", line.c_str(), int(pad), "");
    std::fflush(stderr);
    line_open_ = true;
    drawn_done_ = done;
    drawn_width_ = line.size();
}

void ProgressBar::update(int done) {
    const auto now = std::chrono::steady_clock::now();
    if (done > done_)
        frame_time_.add(std::chrono::duration<double>(now - last_update_).count(), done - done_);
    last_update_ = now;
    done_ = done;
    if (!enabled_) return;
    // A few redraws a second: a terminal is slow and the eye no faster.
    if (line_open_ && done < total_ && now - last_draw_ < std::chrono::milliseconds(200)) return;
    last_draw_ = now;
    draw(done);
}

void ProgressBar::finish() {
    if (!enabled_) return;
    // update() already drew the last frame's line; drawing it again would
    // show the last line twice wherever \r does not return (logs, pipes
    // through `script`, terminals that wrapped it).
    if (drawn_done_ != done_) draw(done_);
    if (line_open_) std::fputc('\n', stderr);
    line_open_ = false;
}

}  // namespace emoface::apps
