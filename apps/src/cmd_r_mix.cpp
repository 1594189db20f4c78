// emoface mix: the face showing an emotion mixture, as one still or as a
// contact sheet of the mix at intensities 0, 0.25, 0.5, 0.75 and 1.
//   emoface mix "0.7 anger + 0.3 fear" --out face.png
//   emoface mix surprise --sheet --out surprise_sheet.png
#include <memory>
#include <string>

#include <fmt/format.h>

#include "command.h"
#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"
#include "emoface/render/image_io.h"
#include "session.h"
#include "sheet.h"
#include "viewer.h"

namespace {

using namespace emoface;
using namespace emoface::apps;

struct MixArgs {
    std::string mix, out, size;
    bool sheet = false, normalise = false;
    bool out_given = false, size_given = false;  // given, if only as ''
    SessionArgs session;
    ViewerOptions viewer;  // without --out
};

constexpr double kSheetIntensities[] = {0.0, 0.25, 0.5, 0.75, 1.0};

expression::EmotionMix scaled(const expression::EmotionMix& mix, double s) {
    expression::EmotionMix m;
    for (std::size_t e = 0; e < m.weights.size(); ++e) m.weights[e] = mix.weights[e] * s;
    return m;
}

void run_mix(const MixArgs& a) {
    const expression::EmotionMix mix = expression::parse_emotion_mix(a.mix, a.normalise);
    const auto size_or = [&](const char* fallback) { return a.size_given ? a.size : std::string(fallback); };
    if (!a.out_given) {
        // The viewer, its sliders at the mix, with every session option given.
        ViewerOptions v = a.viewer;
        v.command = "mix";
        v.mix = mix.to_string();
        const auto [width, height] = parse_size(size_or("1280x720"), "mix");
        v.session = a.session.resolve("mix", width, height);
        run_viewer(v);
        return;
    }
    const auto [width, height] = parse_size(size_or(a.sheet ? "320x320" : "720x720"), "mix");
    const SessionOptions so = a.session.resolve("mix", width, height);
    split_output_path(a.out, "mix", "--out");
    render::check_image_output(a.out, "mix: --out " + a.out);
    OutputFile output(a.out, "mix");
    Session session(so);

    if (!a.sheet) {
        render::write_image(output.path(), session.render_frame(session.face_state(mix)));
        output.commit();
        fmt::print("mix: wrote {} ({}x{}, {}{})\n", a.out, so.picture_width(), height, mix.to_string(),
                   so.wrinkles_note());
    } else {
        SheetRow row;
        for (double s : kSheetIntensities) {
            row.tiles.push_back(to_bgr(session.render_frame(session.face_state(scaled(mix, s)))));
            row.captions.push_back(fmt::format("intensity {:g}", s));
        }
        const cv::Mat sheet = contact_sheet(fmt::format("{}  at intensity 0 .. 1", mix.to_string()), {row});
        write_bgr(output.path(), sheet);
        output.commit();
        fmt::print("mix: wrote {} ({}x{}: {} at intensities 0, 0.25, 0.5, 0.75, 1)\n", a.out, sheet.cols,
                   sheet.rows, mix.to_string());
    }
    fmt::print("mix: {}\n{}", session.description(), format_times(session.load_times(), session.frame_totals()));
}

void add_mix_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "mix", "Show an emotion mixture, e.g. \"0.7 anger + 0.3 fear\": a still (--out) or a contact "
               "sheet of intensities 0..1 (--sheet); without --out, in the viewer");
    auto a = std::make_shared<MixArgs>();
    sub->add_option("mix", a->mix,
                    "Emotion mix: \"0.7 anger + 0.3 fear\", \"joy=0.5, surprise=0.2\", \"sadness\" (joy, "
                    "sadness, anger, fear, disgust, surprise; weights sum to at most 1)")
        ->required();
    CLI::Option* out =
        sub->add_option("-o,--out", a->out, "Output image (.png, .jpg, .exr, ...); without it: the viewer");
    sub->add_flag("--sheet", a->sheet, "A contact sheet of the mix at intensities 0, 0.25, 0.5, 0.75, 1");
    sub->add_flag("--normalise", a->normalise, "Scale a mix summing over 1 down to 1");
    CLI::Option* size = sub->add_option("--size", a->size, "Picture (or sheet tile) size WIDTHxHEIGHT (default 720x720; "
                                       "320x320 a tile with --sheet; 1280x720 the viewer's window)");
    add_session_options(*sub, a->session);
    add_side_by_side_option(*sub, a->session);
    add_viewer_options(*sub, a->viewer, out);
    sub->callback([a, out, size] {
        a->out_given = out->count() > 0;
        a->size_given = size->count() > 0;
        run_mix(*a);
    });
}

}  // namespace

EMOFACE_COMMAND(add_mix_command)
