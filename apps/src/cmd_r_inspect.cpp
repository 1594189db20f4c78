// emoface inspect: the 84 feature points (labelled 2.1 .. 11.6) and the
// morph's feature lines, over the render (left) and over the current wrinkle
// map (right), for one FAP frame or one emotion mix. With a display and no
// --out, an OpenCV window where the frame is stepped with keys.
//   emoface inspect data/fap/demo_tour.fap --frame 120 --out overlay.png
//   emoface inspect --mix "0.7 anger + 0.3 fear" --out overlay.png
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <fmt/format.h>
#include <opencv2/highgui.hpp>
#include <opencv2/imgproc.hpp>

#include "au_label.h"
#include "clamp_warning.h"
#include "command.h"
#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"
#include "emoface/render/image_io.h"
#include "session.h"
#include "sheet.h"

namespace {

using namespace emoface;
using namespace emoface::apps;

struct InspectArgs {
    std::string fap, mix, out, size = "720x720", keys;
    long frame = 0;
    bool raw_map = false, no_labels = false, normalise = false;
    bool out_given = false;  // if only as ''
    SessionArgs session;
};

struct View {
    bool raw_map = false;
    bool labels = true;
};

// `text` cut short with "..." where it is wider than `width` pixels at `scale`
// (put_label's font and outline), so a title stays inside the picture.
std::string fit_text(const std::string& text, int width, double scale) {
    auto fits = [&](const std::string& t) {
        int baseline = 0;
        return cv::getTextSize(t, cv::FONT_HERSHEY_SIMPLEX, scale, 3, &baseline).width <= width;
    };
    if (fits(text)) return text;
    std::string cut = text;
    while (!cut.empty() && !fits(cut + "...")) cut.pop_back();
    return cut + "...";
}

// The picture: a title band over [render + overlay | wrinkle map + overlay].
cv::Mat inspect_picture(Session& session, const expression::FaceState& state, const FrameTitle& title,
                        const View& view) {
    const render::ImageRGBA8 frame = session.render_frame(state);
    const int w = frame.width, h = frame.height;
    cv::Mat left = to_bgr(frame);
    const auto camera = session.draw_options(float(w) / float(h)).camera;
    draw_feature_overlay(left, session.screen_points(camera, w, h), session.lines(), view.labels);

    const render::ImageRGBA8 map = session.wrinkle_map();
    cv::Mat right = view.raw_map ? raw_normal_map(map) : shade_normal_map(map);
    if (right.rows != h) cv::resize(right, right, cv::Size(h, h), 0, 0, cv::INTER_AREA);
    draw_feature_overlay(right, layout_pixels(session.layout(), right.cols, right.rows), session.lines(),
                         view.labels);

    // Two title lines (frame_title): what the face shows, then the rest.
    const int gap = 6, band = 48;
    cv::Mat out(h + band, w + gap + right.cols, CV_8UC3, cv::Scalar(38, 34, 32));
    left.copyTo(out(cv::Rect(0, band, w, h)));
    right.copyTo(out(cv::Rect(w + gap, band, right.cols, h)));
    put_label(out, fit_text(title.first, out.cols - 12, 0.5), cv::Point(6, 20), 0.5);
    put_label(out, fit_text(title.second, out.cols - 12, 0.45), cv::Point(6, 40), 0.45);
    const std::string map_caption =
        fmt::format("wrinkle map {}x{} ({})", map.width, map.height, view.raw_map ? "encoded normals" : "lit");
    put_label(out, map_caption, cv::Point(w + gap + 6, band + h - 8), 0.45);
    return out;
}

void run_inspect(const InspectArgs& a) {
    if (!a.fap.empty() && !a.mix.empty())
        fail<InputError>("inspect: give a FAP file (with --frame N) or --mix, not both");
    std::optional<fap::FapStream> stream;
    expression::EmotionMix mix;
    if (!a.fap.empty()) {
        stream = fap::resolve_untransmitted(load_fap_stream(a.fap, a.session.options.data));
        if (a.frame < 0 || std::size_t(a.frame) >= stream->frames.size())
            fail<InputError>("inspect: --frame {}: {} has frames 0..{}", a.frame, a.fap, stream->frames.size() - 1);
    } else {
        if (a.frame != 0) fail<InputError>("inspect: --frame is for a FAP file");
        if (!a.mix.empty()) mix = expression::parse_emotion_mix(a.mix, a.normalise);
    }
    const auto [width, height] = parse_size(a.size, "inspect");
    const SessionOptions so = a.session.resolve("inspect", width, height);
    const bool window = !a.out_given;
    std::optional<OutputFile> output;
    if (window) {
        require_display("inspect", "the window", "give --out overlay.png to write the picture instead");
    } else {
        split_output_path(a.out, "inspect", "--out");
        render::check_image_output(a.out, "inspect: --out " + a.out);
        output.emplace(a.out, "inspect");
    }

    if (stream && so.clamp_faps) warn_clamped_faps("inspect", a.fap, *stream, so.data);
    Session session(so);

    View view;
    view.raw_map = a.raw_map;
    view.labels = !a.no_labels;
    long frame = a.frame;
    auto state_now = [&] {
        return stream ? session.face_state(stream->frames[std::size_t(frame)]) : session.face_state(mix);
    };
    auto title_now = [&](const expression::FaceState& s) {
        if (!stream) return frame_title("", s, &mix);
        return frame_title(fmt::format("{} frame {}/{}", std::filesystem::path(a.fap).filename().string(), frame,
                                       stream->frames.size() - 1),
                           s);
    };

    if (!window) {
        const auto state = state_now();
        const cv::Mat picture = inspect_picture(session, state, title_now(state), view);
        write_bgr(output->path(), picture);
        output->commit();
        fmt::print("inspect: wrote {} ({}x{}: render | wrinkle map, {} feature points, {} feature lines)\n", a.out,
                   picture.cols, picture.rows,
                   std::count_if(session.feature_points().begin(), session.feature_points().end(),
                                 [](const auto& p) { return bool(p); }),
                   session.lines().size());
        fmt::print("inspect: {}\n{}", session.description(),
                   format_times(session.load_times(), session.frame_totals()));
        return;
    }

    const std::string name = "emoface inspect";
    cv::namedWindow(name, cv::WINDOW_AUTOSIZE);
    fmt::print("inspect: keys: right/left or d/a step a frame, D/A ten, m encoded/lit map, l labels, "
               "s save inspect_N.png, q or Esc quit\n");
    const long last = stream ? long(stream->frames.size()) - 1 : 0;
    std::size_t scripted = 0;
    for (;;) {
        const auto state = state_now();
        const cv::Mat picture = inspect_picture(session, state, title_now(state), view);
        cv::imshow(name, picture);
        int key;
        if (scripted < a.keys.size()) {
            cv::waitKey(1);  // lets the window show the picture
            key = static_cast<unsigned char>(a.keys[scripted++]);
        } else {
            key = cv::waitKeyEx(0);
            if (key < 0 || cv::getWindowProperty(name, cv::WND_PROP_VISIBLE) < 1) break;
        }
        const int low = key & 0xFFFF;
        if (low == 'q' || low == 27) break;
        if (low == 'd' || low == 0xFF53 || key == 83) frame = std::min(last, frame + 1);
        else if (low == 'a' || low == 0xFF51 || key == 81) frame = std::max(0L, frame - 1);
        else if (low == 'D') frame = std::min(last, frame + 10);
        else if (low == 'A') frame = std::max(0L, frame - 10);
        else if (low == 'm') view.raw_map = !view.raw_map;
        else if (low == 'l') view.labels = !view.labels;
        else if (low == 's') {
            const std::string path = fmt::format("inspect_{}.png", frame);
            write_bgr(path, picture);
            fmt::print("inspect: wrote {}\n", path);
        }
    }
    cv::destroyWindow(name);
    fmt::print("inspect: {}\n{}", session.description(),
               format_times(session.load_times(), session.frame_totals()));
}

void add_inspect_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "inspect",
        "The 84 feature points (labelled) and the morph's feature lines over the render and the "
        "wrinkle map, side by side; without --out, a window stepping through the frames");
    auto a = std::make_shared<InspectArgs>();
    sub->add_option("file", a->fap,
                    "Animation file: FAP, or an OpenFace, Live Link Face or MediaPipe CSV (optional; else --mix, "
                    "else neutral)");
    sub->add_option("--frame", a->frame, "Frame of the animation file (0-based)")->capture_default_str();
    sub->add_option("--mix", a->mix, "Emotion mix instead of an animation file, e.g. \"0.7 anger + 0.3 fear\"");
    sub->add_flag("--normalise", a->normalise, "Scale a mix summing over 1 down to 1");
    CLI::Option* out = sub->add_option("-o,--out", a->out, "Output picture (.png, ...); without it: a window");
    sub->add_option("--size", a->size, "Render size WIDTHxHEIGHT (the map is shown HEIGHT square)")
        ->capture_default_str();
    sub->add_flag("--raw-map", a->raw_map, "Show the map's encoded normals instead of lighting it");
    sub->add_flag("--no-labels", a->no_labels, "Dots and lines only");
    sub->add_option("--keys", a->keys, "Window: press these keys first (e.g. \"dDsq\"; for scripts and tests)");
    add_session_options(*sub, a->session);
    add_clamp_option(*sub, a->session);
    sub->callback([a, out] {
        a->out_given = out->count() > 0;
        run_inspect(*a);
    });
}

}  // namespace

EMOFACE_COMMAND(add_inspect_command)
