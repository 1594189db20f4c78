#pragma once
// The one way tests run the built `emoface` binary: argument vector in (no
// shell, so paths need no quoting), exit code, stdout and stderr out, with a
// time limit. Either to the end (run_emoface) or in the background while the
// test drives it (EmofaceProcess, e.g. a viewer on a virtual display).
#include <sys/types.h>

#include <string>
#include <utility>
#include <vector>

namespace emoface::testing {

struct RunOptions {
    std::vector<std::string> unset_env;                       // e.g. {"DISPLAY", "WAYLAND_DISPLAY"}
    std::vector<std::pair<std::string, std::string>> set_env;  // e.g. {{"DISPLAY", ":93"}}
    std::string working_dir;                                  // empty: the test's own
    double timeout_seconds = 300;  // run_emoface's limit; then killed: timed_out, exit_code -1
};

// A run with no display at all (DISPLAY and WAYLAND_DISPLAY unset), and one
// on the X display `display` (":93").
RunOptions without_display();
RunOptions on_display(const std::string& display);

struct CommandResult {
    int exit_code = -1;  // -1 when killed by a signal or the time limit
    bool timed_out = false;
    std::string out, err;
};

// `first` followed by `rest`: builds one argument list from shared pieces
// (e.g. the small-size options every drawing test passes).
std::vector<std::string> args_with(std::vector<std::string> first, const std::vector<std::string>& rest);

// A started `emoface ARGS`. The binary keeps ASan's checks but runs without
// LeakSanitizer: it links GL drivers, OpenImageIO and OpenCV, whose one-time
// allocations outlive exit. The destructor kills a process still running.
class EmofaceProcess {
public:
    explicit EmofaceProcess(const std::vector<std::string>& args, const RunOptions& options = {});
    ~EmofaceProcess();
    EmofaceProcess(const EmofaceProcess&) = delete;
    EmofaceProcess& operator=(const EmofaceProcess&) = delete;

    // Waits for the end, `seconds` from now at most (then kills it), and
    // returns what it printed. Call once.
    CommandResult wait(double seconds);
    // What it wrote to stderr so far (for a failure message while it runs).
    std::string err_so_far() const;

private:
    pid_t pid_ = -1;
    std::string dir_;  // holds the stdout and stderr files
};

// Runs `emoface ARGS` to the end.
CommandResult run_emoface(const std::vector<std::string>& args, const RunOptions& options = {});

}  // namespace emoface::testing
