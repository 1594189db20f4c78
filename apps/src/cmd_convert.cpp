// emoface convert IN OUT: any animation file (FAP, OpenFace, Live Link Face or
// MediaPipe CSV; expression/capture.h) as a FAP file, a Live Link Face ARKit
// CSV or an OpenFace-style AU CSV, so Xface and Greta can play captures and
// capture tools can read FAP animation.
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_checks.h"
#include "command.h"
#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/expression/capture.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/fap_io.h"

namespace {

namespace ex = emoface::expression;

struct ConvertArgs {
    std::string in, out, to, data = EMOFACE_DATA_DIR;
};

bool has_extension(const std::string& path, const std::string& ext) {
    if (path.size() < ext.size()) return false;
    for (std::size_t i = 0; i < ext.size(); ++i)
        if (std::tolower(static_cast<unsigned char>(path[path.size() - ext.size() + i])) != ext[i]) return false;
    return true;
}

// The output format: --to, else the extension's (.fap only: a .csv could be either CSV).
std::string output_format(const ConvertArgs& a) {
    if (!a.to.empty()) {
        if (a.to != "fap" && a.to != "arkit" && a.to != "openface")
            emoface::fail<emoface::InputError>("convert: --to '{}': expected fap, arkit or openface",
                                               emoface::echo_input(a.to, 40));
        return a.to;
    }
    if (has_extension(a.out, ".fap")) return "fap";
    if (has_extension(a.out, ".csv"))
        emoface::fail<emoface::InputError>("convert: {}: a .csv may be an ARKit (Live Link Face) or an OpenFace CSV: "
                                           "say which with --to arkit or --to openface",
                                           a.out);
    emoface::fail<emoface::InputError>("convert: {}: expected an output ending in .fap, or --to fap, arkit or "
                                       "openface",
                                       a.out);
}

void convert(const ConvertArgs& a) {
    const std::string to = output_format(a);
    emoface::apps::OutputFile out(a.out, "convert", "OUT");
    const ex::Animation in = ex::read_animation_file(a.in, a.data);
    if (in.stream.frames.empty()) emoface::fail<emoface::InputError>("convert: {}: the file has no frames", a.in);
    for (const std::string& w : in.stream.warnings) std::fprintf(stderr, "emoface: convert: warning: %s\n", w.c_str());

    std::string text;
    const char* written = "";
    std::string note;
    if (to == "fap") {
        // What Xface's reader takes (fap_io.h, for_xface); emoface reads it too.
        const emoface::fap::FapStream xface = emoface::fap::for_xface(in.stream);
        text = emoface::fap::format_fap(xface);
        written = "FAP";
        if (xface.fps != in.stream.fps)
            note = fmt::format(", resampled at {:g} fps: Xface reads whole frame rates", xface.fps);
    } else {
        const auto emotions = ex::load_emotion_profiles(a.data + "/expression/emotions.json");
        const auto visemes = ex::load_viseme_profiles(a.data + "/expression/visemes.json");
        const std::vector<ex::CaptureFrame> frames = ex::capture_frames(in.stream, emotions, visemes);
        if (to == "arkit") {
            const ex::ArkitShapes shapes = ex::load_arkit_shapes(a.data + "/expression/arkit.json", emotions.action_units);
            text = ex::format_arkit_csv(frames, in.stream.fps, shapes);
            written = "Live Link Face CSV";
        } else {
            text = ex::format_openface_csv(frames, in.stream.fps);
            written = "OpenFace-style AU CSV";
        }
    }
    emoface::write_file_atomically(out.path(), text, "convert");
    out.commit();
    fmt::print("{} ({}, {} frames at {:g} fps) -> {} ({}{})\n", a.in, ex::animation_format_name(in.format),
               in.stream.frames.size(), in.stream.fps, a.out, written, note);
}

void add_convert_command(CLI::App& root) {
    auto a = std::make_shared<ConvertArgs>();
    auto* sub = root.add_subcommand(
        "convert",
        "Convert an animation file (FAP, OpenFace 2.0 CSV, Live Link Face or MediaPipe blendshape CSV; told from "
        "its content) to a FAP file Xface reads (whole fps, frames from 0, integer values), a Live Link Face "
        "ARKit CSV or an OpenFace-style AU CSV");
    sub->add_option("in", a->in, "Animation file to read: FAP, or an OpenFace, Live Link Face or MediaPipe CSV")->required();
    sub->add_option("out", a->out, "File to write (.fap, or .csv with --to)")->required();
    sub->add_option("--to", a->to, "fap, arkit (Live Link Face CSV) or openface (AU CSV); default: from OUT's .fap");
    sub->add_option("--data", a->data, "The project's data folder (AU, ARKit, emotion and viseme tables)")
        ->capture_default_str();
    sub->callback([a] { convert(*a); });
}

}  // namespace

EMOFACE_COMMAND(add_convert_command)
