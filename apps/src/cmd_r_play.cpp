// emoface play: a FAP file on a face, rendered headless into a video or a
// frame sequence, or shown in the viewer when there is no --out.
//   emoface play data/fap/demo_tour.fap --out out/demo.mp4 --size 640x480
//   emoface play anim.fap --out frames/%04d.png --frames 0:50
//   emoface play speech.fap --out talk.mp4 --audio speech.wav
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>

#include <fmt/format.h>

#include "clamp_warning.h"
#include "command.h"
#include "emoface/common/error.h"
#include "emoface/common/output_batch.h"
#include "emoface/render/image_io.h"
#include "emoface/render/video_writer.h"
#include "progress.h"
#include "session.h"
#include "viewer.h"

namespace {

using namespace emoface;
using namespace emoface::apps;

struct PlayArgs {
    std::string fap, out, size = "1280x720", frames, audio;
    double fps = 0, audio_offset = 0;
    int crf = -1;
    bool fps_given = false, frames_given = false;  // given, if only as ''
    bool audio_given = false, audio_offset_given = false, crf_given = false;
    SessionArgs session;
    ViewerOptions viewer;  // without --out
};

// The frames [first, end) of a --frames A:B slice of `count` frames. B is
// exclusive (as in Python), so 0:50 and 50:107 together are 0:107 = all;
// either side may be left out (":50", "50:"). Messages quote the user's
// text ('60:') so it never runs into the message's own colon.
std::pair<int, int> parse_slice(const std::string& text, int count) {
    if (text.empty()) return {0, count};
    const auto colon = text.find(':');
    if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
        fail<InputError>("play: --frames '{}': expected A:B (first frame, end frame exclusive), "
                         "e.g. 0:50, 50: or :50",
                         text);
    auto number = [&](const std::string& part, int fallback) {
        if (part.empty()) return fallback;
        if (part.find_first_not_of("0123456789") != std::string::npos || part.size() > 9)
            fail<InputError>("play: --frames '{}': expected A:B of frame numbers, '{}' is not one", text,
                             part);
        return std::stoi(part);
    };
    const int a = number(text.substr(0, colon), 0);
    const int b = number(text.substr(colon + 1), count);
    const std::string frames = fmt::format("the animation has frames 0..{}", count - 1);
    if (a >= count)
        fail<InputError>("play: --frames '{}': first frame {} is past the end ({})", text, a, frames);
    if (b > count)
        fail<InputError>("play: --frames '{}': end {} is past the end ({}; the end is exclusive, so at "
                         "most {})",
                         text, b, frames, count);
    if (a >= b)
        fail<InputError>("play: --frames '{}': expected A < B (the end frame B is exclusive)", text);
    return {a, b};
}

enum class OutKind { Video, Sequence };

OutKind output_kind(const std::string& out) {
    const auto dot = out.find_last_of('.');
    std::string ext = dot == std::string::npos ? "" : out.substr(dot);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (render::VideoWriter::has_video_extension(out)) {
        if (out.find('%') != std::string::npos)
            fail<InputError>("play: --out {}: a video name has no %d (that is for frame sequences)", out);
        return OutKind::Video;
    }
    if (out.find('%') != std::string::npos) return OutKind::Sequence;
    fail<InputError>("play: --out {}: expected a video ({}) or a frame pattern such as frames/%04d.png", out,
                     render::VideoWriter::extensions());
}

// Frame i of the output at output rate `fps` (the stream's own rate: frame
// i of the file). `resolved`: the stream with the untransmitted-FAP rule
// applied to every frame, so one frame needs no walk back.
fap::FapFrame frame_at(const fap::FapStream& resolved, double fps, int i) {
    if (fps == resolved.fps) return resolved.frames[std::size_t(i)];
    const double position = double(i) * resolved.fps / fps;
    const auto k = std::size_t(std::floor(position));
    if (k + 1 >= resolved.frames.size()) return resolved.frames.back();
    // Interpolate between frames k and k + 1 as FapStream::sample does.
    fap::FapStream two;
    two.fps = resolved.fps;
    two.frames = {resolved.frames[k], resolved.frames[k + 1]};
    return two.sample((position - double(k)) / resolved.fps);
}

// "--audio, --crf": the options only a video file takes, as given; "" for none.
std::string video_only_options(const PlayArgs& a) {
    std::string given;
    for (const auto& [is_given, name] : {std::pair{a.audio_given, "--audio"},
                                         std::pair{a.audio_offset_given, "--audio-offset"},
                                         std::pair{a.crf_given, "--crf"}})
        if (is_given) given += (given.empty() ? "" : ", ") + std::string(name);
    return given;
}

// The viewer on the file, with every session option given.
void run_viewer_for(const PlayArgs& a) {
    // The viewer plays the whole file at its own rate, scrubbed and paced by
    // its timeline: options that shape a written animation are refused
    // rather than silently ignored.
    if (a.fps_given || a.frames_given)
        fail<InputError>("play: {} shape{} the animation written with --out; the viewer plays the whole file at "
                         "its own rate (its timeline scrubs and sets the pace)",
                         a.fps_given && a.frames_given ? "--fps and --frames" : a.fps_given ? "--fps" : "--frames",
                         a.fps_given && a.frames_given ? "" : "s");
    if (const std::string video_only = video_only_options(a); !video_only.empty())
        fail<InputError>("play: {} belong{} to a video written with --out; the viewer plays no sound", video_only,
                         video_only.find(' ') == std::string::npos ? "s" : "");
    ViewerOptions v = a.viewer;
    v.command = "play";
    v.fap_path = a.fap;
    const auto [width, height] = parse_size(a.size, "play");
    v.session = a.session.resolve("play", width, height);
    run_viewer(v);
}

std::string file_name(const std::string& path) { return std::filesystem::path(path).filename().string(); }

void run_play(const PlayArgs& a) {
    // Bad input fails before anything slow happens or is written.
    const fap::FapStream stream = load_fap_stream(a.fap, a.session.options.data);
    if (a.fps_given)
        check_in_range("play", "--fps", a.fps, render::kMinVideoFps, render::kMaxVideoFps, " frames per second");
    if (a.crf_given) check_in_range("play", "--crf", a.crf, 0, 63, " (H.264 0..51, VP9 0..63)");
    if (a.audio_given && a.audio.empty())
        fail<InputError>("play: --audio '': expected a sound file (WAV, MP3, OGG... anything FFmpeg decodes)");
    if (a.audio_offset_given) {
        if (!a.audio_given) fail<InputError>("play: --audio-offset shifts the sound of --audio, which is not given");
        check_in_range("play", "--audio-offset", a.audio_offset, -86400.0, 86400.0, " seconds");
    }
    if (a.out.empty()) {
        run_viewer_for(a);
        return;
    }
    const std::string what = "play: --out " + a.out;
    const auto [width, height] = parse_size(a.size, "play");
    const SessionOptions so = a.session.resolve("play", width, height);
    const OutKind kind = output_kind(a.out);
    if (kind == OutKind::Video && (width % 2 || height % 2))
        fail<InputError>("play: --size {}: a video needs an even width and height", a.size);

    const double fps = a.fps_given ? a.fps : stream.fps;
    const int count = a.fps_given
                          ? std::max(1, int(std::lround(double(stream.frames.size()) * fps / stream.fps)))
                          : int(stream.frames.size());
    if (a.frames_given && a.frames.empty())
        fail<InputError>("play: --frames '': expected A:B (first frame, end frame exclusive), e.g. 0:50, 50: or :50");
    const auto [first, end] = parse_slice(a.frames, count);

    std::unique_ptr<render::FrameSequenceWriter> sequence;
    std::string folder;
    render::VideoOptions video_options;
    video_options.fps = fps;
    video_options.crf = a.crf_given ? a.crf : -1;
    video_options.audio = a.audio;
    video_options.audio_offset = a.audio_offset;
    // A slice's sound is the stretch under its frames: slices join exactly.
    video_options.first_frame = first;
    if (kind == OutKind::Video) {
        // Opens the sound file and decodes its first frame.
        render::VideoWriter::check(a.out, so.picture_width(), height, video_options);
        folder = split_output_path(a.out, "play", "--out").first;
    } else {
        if (const std::string video_only = video_only_options(a); !video_only.empty())
            fail<InputError>("{}: {} need{} a video ({}), not a frame pattern", what, video_only,
                             video_only.find(' ') == std::string::npos ? "s" : "", render::VideoWriter::extensions());
        sequence = std::make_unique<render::FrameSequenceWriter>(a.out, first);
        render::check_image_output(sequence->path_for(first), what);
        folder = std::filesystem::path(sequence->path_for(first)).parent_path().string();
        // A folder where a frame should go fails now, not after rendering.
        std::error_code ec;
        for (int i = first; i < end; ++i)
            if (std::filesystem::is_directory(sequence->path_for(i), ec))
                fail<InputError>("{}: frame {} would be {}, which is a folder", what, i, sequence->path_for(i));
    }
    // Last of the checks: it makes a missing output folder (removed again
    // if the command fails) and proves it can be written.
    OutputBatch batch(folder, what);
    const fap::FapStream resolved = fap::resolve_untransmitted(stream);
    // Once, before the slow part; the rig clamps each frame as it plays.
    if (so.clamp_faps) warn_clamped_faps("play", a.fap, resolved, so.data);

    Session session(so);

    std::unique_ptr<render::VideoWriter> video;
    if (kind == OutKind::Video)
        video = std::make_unique<render::VideoWriter>(batch.stage(file_name(a.out)), so.picture_width(), height,
                                                      video_options);

    ProgressBar progress("play", end - first);
    for (int i = first; i < end; ++i) {
        const expression::FaceState state = session.face_state(frame_at(resolved, fps, i));
        render::ImageRGBA8 image = session.render_frame(state);
        // Encoded on the writer's thread while the next frame renders.
        if (video) video->write(std::move(image));
        else render::write_image(batch.stage(file_name(sequence->path_for(i))), image);
        progress.update(i - first + 1);
    }
    progress.finish();
    if (video) video->close();
    batch.commit();

    const std::string slice =
        (first == 0 && end == count) ? "" : fmt::format(" (frames {}..{} of {})", first, end - 1, count);
    if (video) {
        std::string container = std::filesystem::path(a.out).extension().string().substr(1);
        std::transform(container.begin(), container.end(), container.begin(),
                       [](unsigned char c) { return char(std::toupper(c)); });
        const std::string quality = video->crf() >= 0 ? fmt::format(" (crf {})", video->crf()) : "";
        const std::string sound =
            a.audio.empty() ? ""
                            : fmt::format(", {} sound from {}{}", video->audio_codec(), a.audio,
                                          a.audio_offset != 0 ? fmt::format(" at {:+g} s", a.audio_offset) : "");
        fmt::print("play: wrote {}: {} frames{} {}x{} at {:g} frames/s, {} {}{}{}{}\n",
                   batch.destination(file_name(a.out)), end - first, slice, so.picture_width(), height, fps,
                   video->codec(), container, quality, sound, so.wrinkles_note());
    } else {
        fmt::print("play: wrote {} .. {}: {} frames{} {}x{}{}\n", sequence->path_for(first),
                   sequence->path_for(end - 1), end - first, slice, so.picture_width(), height, so.wrinkles_note());
    }
    fmt::print("play: {}\n{}", session.description(),
               format_times(session.load_times(), session.frame_totals()));
}

void add_play_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "play",
        "Play an animation file (FAP, or an OpenFace, Live Link Face or MediaPipe CSV) on a face: headless "
        "into a video or frame sequence with --out, else in the viewer");
    auto a = std::make_shared<PlayArgs>();
    sub->add_option("file", a->fap,
                    "Animation file: MPEG-4 FAP (.fap), OpenFace 2.0 CSV, Live Link Face (ARKit) CSV or MediaPipe "
                    "blendshape CSV, told from its content")
        ->required();
    CLI::Option* out = sub->add_option("-o,--out", a->out,
                    "Video (.mp4 or .mkv: H.264 + AAC; .webm: VP9 + Opus; .avi: Motion-JPEG + PCM) or "
                    "frame pattern (frames/%04d.png, numbered by frame). Without it: the viewer");
    sub->add_option("--size", a->size, "Frame size WIDTHxHEIGHT")->capture_default_str();
    CLI::Option* fps = sub->add_option(
        "--fps", a->fps, "Output frame rate, 0.1..1000 (default: the file's); the animation is resampled");
    CLI::Option* frames = sub->add_option("--frames", a->frames,
                    "Render the slice A:B of the output frames, B exclusive (0:50 then 50:107 "
                    "together make 0:107); frame patterns are numbered by frame");
    CLI::Option* audio = sub->add_option("--audio", a->audio,
                    "Sound for the video (WAV, MP3, OGG, FLAC... anything FFmpeg decodes), starting with "
                    "frame 0; cut or padded with silence to the video's length");
    CLI::Option* audio_offset = sub->add_option("--audio-offset", a->audio_offset,
                    "Seconds the sound starts after the animation (negative: its start is cut)");
    CLI::Option* crf = sub->add_option("--crf", a->crf,
                    "Video quality, lower is better and larger: H.264 0..51 (default 20), VP9 0..63 "
                    "(default 31)");
    add_session_options(*sub, a->session);
    add_side_by_side_option(*sub, a->session);
    add_clamp_option(*sub, a->session);
    add_viewer_options(*sub, a->viewer, out);
    sub->callback([a, fps, frames, audio, audio_offset, crf] {
        a->fps_given = fps->count() > 0;
        a->frames_given = frames->count() > 0;
        a->audio_given = audio->count() > 0;
        a->audio_offset_given = audio_offset->count() > 0;
        a->crf_given = crf->count() > 0;
        run_play(*a);
    });
}

}  // namespace

EMOFACE_COMMAND(add_play_command)
