#pragma once
// The interactive viewer: a GLFW window showing the face, with the mouse
// orbiting and zooming the camera (right-drag moves the light), sliders for
// the six emotion intensities, a FAP timeline (play/pause/scrub) when a file
// is loaded, toggles for wrinkles, feature points and lines, the morph
// backend, and the frame time. `emoface view` and `emoface play` without
// --out open it.
#include <string>

#include "emoface/morph/morph.h"

namespace emoface::apps {

struct ViewerOptions {
    std::string fap_path;         // empty: no timeline, the sliders drive the face
    std::string face = "default";  // default | FILE.wfm | FILE.obj (with fdp)
    std::string fdp;              // feature points of an .obj face
    std::string mix;              // initial slider values, e.g. "0.7 anger + 0.3 fear"
    morph::Backend backend = morph::Backend::Auto;
    int width = 1280, height = 720;
    bool wrinkles = true;
    int quit_after_frames = 0;  // > 0: render this many frames, then close
    std::string screenshot;     // non-empty: the last frame is written here (PNG, ...)
    int wrinkle_size = 512;     // side of the key and morphed wrinkle maps, 256..4096
    // The overlay's toggles as the viewer starts.
    bool show_points = false, show_lines = false, show_labels = false;
};

// Runs the viewer until the window is closed (or quit_after_frames frames).
// Returns the process exit code (0). Throws emoface::EnvironmentError naming
// the fix when no display can be opened, emoface::InputError on bad options
// or files.
int run_viewer(const ViewerOptions& options);

}  // namespace emoface::apps
