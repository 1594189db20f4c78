#pragma once
// A one-line progress bar on stderr for long renders:
//   play [##########..........]  53/107  12.4 frames/s  4 s left
// Redrawn in place (carriage return) at most a few times a second; silent
// when stderr is not a terminal (logs and tests stay clean). The rate and
// the time left come from a moving average of the frame time, so one slow
// frame (the first, a page fault, a busy neighbour) does not swing them.
#include <chrono>
#include <string>

namespace emoface::apps {

// Seconds per frame as an exponential moving average: each new frame moves
// the average a fraction `alpha` of the way to its own time.
class FrameTimeAverage {
public:
    explicit FrameTimeAverage(double alpha = 0.1) : alpha_(alpha) {}
    // `frames` more frames took `seconds` together (frames > 0). The first
    // call sets the average; later ones weigh each of their frames by alpha.
    void add(double seconds, int frames);
    bool empty() const { return frames_ == 0; }
    double seconds_per_frame() const { return mean_; }

private:
    double alpha_;
    double mean_ = 0;
    long frames_ = 0;
};

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
    // Draws the final state unless it is already on screen, and ends the line.
    void finish();

    bool enabled() const { return enabled_; }
    // The line for `done` of `total` after `elapsed` seconds, with
    // `seconds_per_frame` the averaged frame time (0: not known yet) giving
    // the rate and the time left; a finished bar shows the overall rate and
    // the elapsed time instead. No carriage return: for tests.
    static std::string format(const std::string& label, int done, int total, double elapsed,
                              double seconds_per_frame, int bar_width = 24);

private:
    void draw(int done);

    std::string label_;
    int total_;
    bool enabled_;
    bool line_open_ = false;  // a line is drawn and not yet ended
    int done_ = 0, drawn_done_ = -1;
    std::size_t drawn_width_ = 0;  // characters of the line on screen
    FrameTimeAverage frame_time_;
    std::chrono::steady_clock::time_point start_, last_update_, last_draw_;
};

}  // namespace emoface::apps
