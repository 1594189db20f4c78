// emoface view: the interactive viewer (viewer.h) in a window.
//   emoface view                                  sliders for the six emotions
//   emoface view anim.fap                         plays the file (timeline; a capture CSV too)
//   emoface view --mix "0.7 anger + 0.3 fear" --wrinkles painted/
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
    apps::SessionArgs session;
    std::string size = "1280x720";
};

void add_view_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "view",
        "Open the interactive viewer: orbit/zoom with the mouse, emotion sliders, an animation file's timeline,\n"
        "wrinkles, feature points and lines, CPU/GPU morph (needs a display)");
    auto args = std::make_shared<ViewArgs>();
    sub->add_option("file", args->viewer.fap_path,
                    "Animation file to play (optional): FAP, or an OpenFace, Live Link Face or MediaPipe CSV");
    sub->add_option("--mix", args->viewer.mix, "Emotion mix the sliders start at, e.g. \"0.7 anger + 0.3 fear\"");
    sub->add_option("--size", args->size, "Window size WIDTHxHEIGHT")->capture_default_str();
    apps::add_session_options(*sub, args->session);
    apps::add_clamp_option(*sub, args->session);
    apps::add_viewer_options(*sub, args->viewer);
    sub->callback([args] {
        apps::ViewerOptions o = args->viewer;
        const auto [w, h] = apps::parse_size(args->size, "view");
        o.session = args->session.resolve("view", w, h);
        apps::run_viewer(o);
    });
}

}  // namespace

EMOFACE_COMMAND(add_view_command)
