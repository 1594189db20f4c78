// emoface view: the interactive viewer (viewer.h) in a window.
//   emoface view                                  sliders for the six emotions
//   emoface view anim.fap                         plays the file (timeline)
//   emoface view --mix "0.7 anger + 0.3 fear"
//   emoface view anim.fap --quit-after 60 --screenshot shot.png
#include <memory>
#include <string>

#include "command.h"
#include "session.h"
#include "viewer.h"

namespace {

using namespace emoface;

struct ViewArgs {
    apps::ViewerOptions viewer;
    std::string size = "1280x720", backend = "auto";
    bool no_wrinkles = false;
};

void add_view_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "view",
        "Open the interactive viewer: orbit/zoom with the mouse, emotion sliders, FAP timeline,\n"
        "wrinkles, feature points and lines, CPU/GPU morph (needs a display)");
    auto args = std::make_shared<ViewArgs>();
    sub->add_option("file", args->viewer.fap_path, "FAP file to play (optional)");
    sub->add_option("--mix", args->viewer.mix,
                    "Emotion mix the sliders start at, e.g. \"0.7 anger + 0.3 fear\"");
    sub->add_option("--face", args->viewer.face, "default, a Candide-3 FILE.wfm or FILE.obj")
        ->capture_default_str();
    sub->add_option("--fdp", args->viewer.fdp,
                    "Feature points of an .obj face (default: FILE.fdp.json beside it)");
    sub->add_option("--size", args->size, "Window size WIDTHxHEIGHT")->capture_default_str();
    sub->add_option("--backend", args->backend, "Morph backend: auto, cpu or cuda")
        ->capture_default_str();
    sub->add_option("--wrinkle-size", args->viewer.wrinkle_size,
                    "Side of the wrinkle maps (256..4096)")
        ->capture_default_str();
    sub->add_flag("--no-wrinkles", args->no_wrinkles, "Start with the wrinkle map off");
    sub->add_flag("--points", args->viewer.show_points, "Start with the feature points shown");
    sub->add_flag("--lines", args->viewer.show_lines, "Start with the morph's feature lines shown");
    sub->add_flag("--labels", args->viewer.show_labels,
                  "Start with the feature points shown with their labels (2.1 ... 11.6)");
    sub->add_option("--quit-after", args->viewer.quit_after_frames,
                    "Close after this many frames (0: when the window is closed)")
        ->check(CLI::NonNegativeNumber);
    sub->add_option("--screenshot", args->viewer.screenshot,
                    "Write the window's last frame to this image (.png, ...) on closing");
    sub->callback([args] {
        apps::ViewerOptions o = args->viewer;
        const auto [w, h] = apps::parse_size(args->size, "view");
        o.width = w;
        o.height = h;
        o.backend = apps::parse_backend(args->backend, "view");
        o.wrinkles = !args->no_wrinkles;
        apps::run_viewer(o);
    });
}

}  // namespace

EMOFACE_COMMAND(add_view_command)
