#pragma once
// The interactive viewer: a GLFW window showing the face, with the mouse
// orbiting and zooming the camera (right-drag moves the light), sliders for
// the six emotion intensities, a FAP timeline (play/pause/scrub) when a file
// is loaded, toggles for wrinkles, feature points and lines, the morph
// backend, and the frame time. `emoface view`, and `emoface play` and
// `emoface mix` without --out, open it with the same session options
// (session.h) as the pictures they would write.
#include <string>

#include "session.h"

namespace emoface::apps {

struct ViewerOptions {
    // The face, its assets and the morph as every drawing command has them
    // (--face, --wrinkles, --data, ...); width x height is the window's.
    SessionOptions session;
    std::string command = "view";  // names the command in messages
    std::string fap_path;          // empty: no timeline, the sliders drive the face
    std::string mix;               // initial slider values, e.g. "0.7 anger + 0.3 fear"
    int quit_after_frames = 0;     // > 0: render this many frames, then close
    std::string screenshot;        // non-empty: the last frame is written here (PNG, ...)
    // The panel's toggles as the viewer starts.
    bool show_points = false, show_lines = false, show_labels = false, show_wrinkle_map = false;
};

// The viewer's own options (--points, --lines, --labels, --wrinkle-map,
// --quit-after, --screenshot) on `command`, into `options`. `out`: the
// command's --out, which they exclude (play and mix open the viewer only
// without it); nullptr for `view`.
void add_viewer_options(CLI::App& command, ViewerOptions& options, CLI::Option* out = nullptr);

// Runs the viewer until the window is closed (or quit_after_frames frames).
// Returns the process exit code (0). Throws emoface::EnvironmentError naming
// the fix when no display can be opened, emoface::InputError on bad options
// or files (checked before any window opens).
int run_viewer(const ViewerOptions& options);

}  // namespace emoface::apps
