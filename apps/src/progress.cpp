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

ProgressBar::ProgressBar(std::string label, int total)
    : ProgressBar(std::move(label), total, isatty(fileno(stderr)) != 0) {}

ProgressBar::ProgressBar(std::string label, int total, bool enabled)
    : label_(std::move(label)),
      total_(std::max(total, 0)),
      enabled_(enabled),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() {
    if (drawn_) std::fputc('\n', stderr);
}

std::string ProgressBar::format(const std::string& label, int done, int total, double seconds,
                                int bar_width) {
    done = std::clamp(done, 0, std::max(total, 0));
    const double fraction = total > 0 ? double(done) / total : 1.0;
    const int filled = int(std::floor(fraction * bar_width));
    std::string bar(std::size_t(filled), '#');
    bar.append(std::size_t(bar_width - filled), '.');
    const int digits = int(std::to_string(std::max(total, 0)).size());
    std::string line = fmt::format("{} [{}] {:>{}}/{}", label, bar, done, digits, total);
    if (done > 0 && seconds > 0) {
        const double rate = done / seconds;
        line += fmt::format("  {:.1f} frames/s", rate);
        if (done < total) line += "  " + format_duration((total - done) / rate) + " left";
        else line += "  " + format_duration(seconds);
    }
    return line;
}

void ProgressBar::draw(int done) {
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    // Pad to wipe a longer previous line.
    std::fprintf(stderr, "\r%-78s", format(label_, done, total_, seconds).c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressBar::update(int done) {
    done_ = done;
    if (!enabled_) return;
    const auto now = std::chrono::steady_clock::now();
    // A few redraws a second: a terminal is slow and the eye no faster.
    if (drawn_ && done < total_ && now - last_draw_ < std::chrono::milliseconds(200)) return;
    last_draw_ = now;
    draw(done);
}

void ProgressBar::finish() {
    if (!enabled_) return;
    draw(done_);
    std::fputc('\n', stderr);
    drawn_ = false;
}

}  // namespace emoface::apps
