#pragma once
// A one-line progress bar on stderr for long renders:
//   play [##########..........]  53/107  12.4 frames/s  4 s left
// Redrawn in place (carriage return) at most a few times a second; silent
// when stderr is not a terminal (logs and tests stay clean).
#include <chrono>
#include <string>

namespace emoface::apps {

class ProgressBar {
public:
    // `enabled`: draw at all; by default when stderr is a terminal.
    ProgressBar(std::string label, int total);
    ProgressBar(std::string label, int total, bool enabled);
    ~ProgressBar();  // ends the line if one was drawn
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    // `done` units finished (0..total).
    void update(int done);
    // Draws the final state and ends the line.
    void finish();

    bool enabled() const { return enabled_; }
    // The line for `done` after `seconds` (no carriage return): for tests.
    static std::string format(const std::string& label, int done, int total, double seconds,
                              int bar_width = 24);

private:
    void draw(int done);

    std::string label_;
    int total_;
    bool enabled_;
    bool drawn_ = false;
    int done_ = 0;
    std::chrono::steady_clock::time_point start_, last_draw_;
};

}  // namespace emoface::apps
