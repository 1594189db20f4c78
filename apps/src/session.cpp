#include "session.h"

#include "emoface/render/wrinkle_keys_io.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>
#include <spdlog/spdlog.h>

#include "emoface/common/error.h"
#include "emoface/common/timing.h"
#include "emoface/expression/capture.h"
#include "emoface/expression/default_face.h"
#include "emoface/expression/face_io.h"
#include "emoface/fap/fap_io.h"
#include "emoface/render/image_io.h"

namespace emoface::apps {

namespace {

bool ends_with(const std::string& s, const std::string& suffix) {
    if (s.size() < suffix.size()) return false;
    return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
        return std::tolower(static_cast<unsigned char>(a)) == std::tolower(static_cast<unsigned char>(b));
    });
}

void add_times(render::FrameStageTimes& a, const render::FrameStageTimes& b, double scale = 1.0) {
    a.rig_ms += scale * b.rig_ms;
    a.layout_ms += scale * b.layout_ms;
    a.morph_ms += scale * b.morph_ms;
    a.uv_ms += scale * b.uv_ms;
    a.tangents_ms += scale * b.tangents_ms;
    a.upload_ms += scale * b.upload_ms;
}

}  // namespace

// --- small shared helpers ---------------------------------------------------

double process_cpu_ms() {
    timespec t{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
}

std::string load_average() {
    std::ifstream in("/proc/loadavg");
    std::string one;
    if (!(in >> one)) return "";
    return one;
}


void FrameTimeTotals::add(const FrameTimes& t) {
    add_times(sum.scene, t.scene);
    sum.draw_ms += t.draw_ms;
    sum.readback_ms += t.readback_ms;
    sum.total_ms += t.total_ms;
    sum.cpu_ms += t.cpu_ms;
    ++frames;
}

FrameTimes FrameTimeTotals::mean() const {
    FrameTimes m;
    if (frames == 0) return m;
    const double s = 1.0 / frames;
    add_times(m.scene, sum.scene, s);
    m.draw_ms = sum.draw_ms * s;
    m.readback_ms = sum.readback_ms * s;
    m.total_ms = sum.total_ms * s;
    m.cpu_ms = sum.cpu_ms * s;
    return m;
}

std::string format_times(const LoadTimes& load, const FrameTimeTotals& frames) {
    std::string out = fmt::format(
        "  load {:.0f} ms: face {:.0f}, rig {:.0f}, profiles + lines {:.0f}, wrinkle keys {:.0f}, "
        "GL context {:.0f}, scene {:.0f}\n",
        load.total(), load.face_ms, load.rig_ms, load.profiles_ms, load.keys_ms, load.platform_ms,
        load.scene_ms);
    if (frames.frames > 0) {
        const FrameTimes m = frames.mean();
        const std::string load = load_average();
        out += fmt::format("  per frame, mean of {}: {:.1f} ms ({:.1f} frames/s); CPU {:.1f} ms (user + sys, all "
                           "threads){}\n",
                           frames.frames, m.total_ms, m.total_ms > 0 ? 1000.0 / m.total_ms : 0.0, m.cpu_ms,
                           load.empty() ? "" : "; load average " + load);
        out += fmt::format(
            "    rig {:.2f} | layout {:.2f} | morph {:.2f} | wrinkle UVs {:.2f} | tangents {:.2f} | "
            "upload {:.2f} | draw {:.2f} | read back {:.2f}\n"
            "    (wall clock; draw runs to a glFinish, so it holds the rasterisation (llvmpipe: on the "
            "CPU) and any GPU morph still running; read back: resolve + read RGBA)\n",
            m.scene.rig_ms, m.scene.layout_ms, m.scene.morph_ms, m.scene.uv_ms, m.scene.tangents_ms,
            m.scene.upload_ms, m.draw_ms, m.readback_ms);
    }
    return out;
}

fap::FapStream load_fap_stream(const std::string& path, const std::string& data) {
    fap::FapStream stream = expression::read_animation_file(path, data).stream;
    if (stream.frames.empty()) fail<InputError>("fap: {}: the file has no frames", path);
    if (!(stream.fps > 0)) fail<InputError>("fap: {}: frame rate {} is not positive", path, stream.fps);
    return stream;
}

morph::Backend parse_backend(const std::string& text, const std::string& command) {
    if (text == "auto") return morph::Backend::Auto;
    if (text == "cpu") return morph::Backend::Cpu;
    if (text == "cuda") return morph::Backend::Cuda;
    fail<InputError>("{}: --backend '{}': expected auto, cpu or cuda", command, text);
}

namespace {
bool plays_in_time(const std::string& command) { return command == "play" || command == "view"; }
}  // namespace

morph::Accuracy morph_accuracy_for(const std::string& command) {
    return plays_in_time(command) ? morph::Accuracy::Fast : morph::Accuracy::Exact;
}

SessionOptions SessionArgs::resolve(const std::string& command, int width, int height) const {
    SessionOptions o = options;
    o.backend = parse_backend(backend, command);
    if (morph_accuracy.empty()) o.morph_accuracy = morph_accuracy_for(command);
    else if (morph_accuracy == "exact") o.morph_accuracy = morph::Accuracy::Exact;
    else if (morph_accuracy == "fast") o.morph_accuracy = morph::Accuracy::Fast;
    else fail<InputError>("{}: --morph-accuracy '{}': expected exact or fast", command, morph_accuracy);
    const auto kind = render::parse_wrinkle_layout(layout);
    if (!kind) fail<InputError>("{}: --layout '{}': expected projective or anchored", command, layout);
    o.layout = *kind;
    if (shading == "skin") o.shading = render::Shading::Skin;
    else if (shading == "thesis") o.shading = render::Shading::Thesis;
    else fail<InputError>("{}: --shading '{}': expected skin or thesis", command, shading);
    o.wrinkles = !no_wrinkles;
    o.clamp_faps = !no_clamp;
    // Thesis shading has neither the occlusion nor the key's shadows.
    o.light_on_pose = !plays_in_time(command) && o.shading == render::Shading::Skin;
    o.width = width;
    o.height = height;
    render::check_wrinkle_map_size(o.wrinkle_size, command + ": --wrinkle-size");
    if (o.side_by_side && !o.wrinkles)
        fail<InputError>("{}: --side-by-side draws with and without wrinkles: leave out --no-wrinkles", command);
    check_in_range(command, "--face-resolution", o.face_resolution, 0.1, 2.0);
    if (o.texture_size != 0) check_in_range(command, "--texture-size", o.texture_size, 64, 8192, " (0: face.json's)");
    return o;
}

void add_session_options(CLI::App& sub, SessionArgs& a) {
    SessionOptions& o = a.options;
    sub.add_option("--face", o.face, "default, a Candide-3 FILE.wfm, or FILE.obj (with --fdp)")
        ->capture_default_str();
    sub.add_option("--fdp", o.fdp, "Feature points of an .obj face (default: FILE.fdp.json beside it)");
    sub.add_option("--backend", a.backend, "Morph backend: auto, cpu or cuda")->capture_default_str();
    sub.add_option("--morph-accuracy", a.morph_accuracy,
                   "Wrinkle morph: exact, or fast (lines summed on a grid and interpolated away from them); "
                   "default: fast for play and view, exact for pictures");
    sub.add_option("--wrinkle-size", o.wrinkle_size, "Side of the wrinkle maps (256..4096)")->capture_default_str();
    sub.add_option("--samples", o.samples, "Multisampling samples")->check(CLI::Range(1, 16))->capture_default_str();
    sub.add_flag("--no-wrinkles", a.no_wrinkles, "Draw without the wrinkle maps");
    sub.add_option("--shading", a.shading,
                   "skin (scattering, two-lobe sheen, pores, light rig of data/render/skin.json) or "
                   "thesis (the thesis's Blinn-Phong)")
        ->capture_default_str();
    sub.add_option("--wrinkles", o.wrinkle_folder,
                   "Folder of key wrinkle maps + layouts (as `emoface wrinkles` writes; maps may be painted)");
    sub.add_option("--face-resolution", o.face_resolution,
                   "Mesh resolution of the default face (0.1..2; smaller loads and draws faster)")
        ->capture_default_str();
    sub.add_option("--texture-size", o.texture_size, "Base-colour image side of the default face (0: face.json's)")
        ->capture_default_str();
    sub.add_option("--data", o.data, "The project's data folder")->capture_default_str();
    sub.add_option("--layout", a.layout,
                   "Texture space of the wrinkle maps: projective (frontal projection, the default face) "
                   "or anchored (the mesh's own UVs, for maps painted in UV space)")
        ->capture_default_str();
}

CLI::Option* add_side_by_side_option(CLI::App& sub, SessionArgs& a) {
    return sub.add_flag("--side-by-side", a.options.side_by_side,
                        "Two pictures of each pose side by side: with the wrinkle maps (left) and without "
                        "(right); the output is twice as wide as --size");
}

void add_clamp_option(CLI::App& sub, SessionArgs& a) {
    sub.add_flag("--no-clamp", a.no_clamp,
                 "Play FAP values raw, beyond the face's range (data/expression/fap_ranges.json) too, "
                 "instead of clamping them (the mesh may tear or fold)");
}

void require_display(const std::string& command, const std::string& what, const std::string& headless) {
    const char* display = std::getenv("DISPLAY");
    const char* wayland = std::getenv("WAYLAND_DISPLAY");
    if ((display && *display) || (wayland && *wayland)) return;
    fail<EnvironmentError>("{}: no display for {} (DISPLAY is not set): {}, or run it in a desktop session, "
                           "over `ssh -X`, or under a virtual X server (`xvfb-run -a emoface {} ...`)",
                           command, what, headless, command);
}

expression::Face load_session_face(const SessionOptions& o) {
    if (o.face.empty() || o.face == "default") {
        if (!o.fdp.empty()) fail<InputError>("session: --fdp is for an .obj face, not the default face");
        if (!std::filesystem::is_directory(o.data + "/face"))
            fail<InputError>("session: data folder {}: no face/ there (point --data at the project's data/)",
                             o.data);
        expression::DefaultFaceOptions fo;
        fo.resolution_scale = o.face_resolution;
        fo.texture_size = o.texture_size;
        return expression::make_default_face(o.data + "/face", fo);
    }
    // Missing: the hint; there but a FIFO, a device, a link loop: the readers say which.
    std::error_code ec;
    if (!std::filesystem::exists(o.face, ec) && !ec)
        fail<InputError>("session: --face {}: no such file (expected default, FILE.wfm or FILE.obj)", o.face);
    if (ends_with(o.face, ".wfm")) {
        if (!o.fdp.empty()) fail<InputError>("session: --fdp is for an .obj face, not a Candide-3 .wfm");
        return expression::load_candide3(o.face);
    }
    if (ends_with(o.face, ".obj")) {
        std::string fdp = o.fdp;
        if (fdp.empty()) {
            fdp = o.face.substr(0, o.face.size() - 4) + ".fdp.json";
            if (!std::filesystem::exists(fdp, ec) && !ec)
                fail<InputError>("session: --face {}: give its feature points with --fdp FILE.json "
                                 "(looked for {})",
                                 o.face, fdp);
        } else if (!std::filesystem::exists(fdp, ec) && !ec) {
            fail<InputError>("session: --fdp {}: no such file", fdp);
        }
        expression::Face face = expression::load_obj_with_fdp(o.face, fdp);
        if (face.base_colour.empty() && !face.base_colour_file.empty()) {
            const render::ImageRGBA8 img = render::read_image_rgba8(face.base_colour_file);
            face.base_colour.width = img.width;
            face.base_colour.height = img.height;
            face.base_colour.rgba = img.pixels;
        }
        return face;
    }
    fail<InputError>("session: --face {}: expected default, a Candide-3 .wfm or an .obj file", o.face);
}

// --- Session -----------------------------------------------------------------

Session::Session(const SessionOptions& options, render::Platform* window) : options_(options) {
    if (options_.backend == morph::Backend::Cuda && !morph::cuda_available())
        fail<EnvironmentError>("session: --backend cuda: {} (use --backend cpu or auto)",
                               morph::cuda_device_description());

    auto t = Clock::now();
    expression::Face face = load_session_face(options_);
    load_.face_ms = ms_since(t);

    render::FaceAssetsOptions ao;
    ao.wrinkle_map_size = options_.wrinkle_size;
    ao.layout = options_.layout;
    ao.clamp_faps = options_.clamp_faps;
    if (!options_.wrinkle_folder.empty())
        ao.read_keys = [folder = options_.wrinkle_folder](const std::vector<expression::FeatureLine>& lines) {
            return render::read_wrinkle_keys(folder, lines);
        };
    assets_ = render::load_face_assets(std::move(face), options_.data, ao);
    skin_ = render::load_skin_shading(options_.data + "/render/skin.json");
    // Read maps have their own size.
    options_.wrinkle_size = assets_->keys.front().map.width;
    load_.rig_ms = assets_->times.rig_ms;
    load_.profiles_ms = assets_->times.profiles_ms;
    load_.keys_ms = assets_->times.keys_ms;

    t = Clock::now();
    if (window) {
        platform_ = window;
    } else {
        render::PlatformOptions po;
        po.width = options_.picture_width();
        po.height = options_.height;
        po.samples = options_.samples;
        // With CUDA, the EGL device that is the morph's GPU (interop).
        if (options_.backend != morph::Backend::Cpu) po.cuda_device = 0;
        owned_platform_ = std::make_unique<render::HeadlessPlatform>(po);
        platform_ = owned_platform_.get();
        load_.platform_ms = ms_since(t);
    }
    spdlog::debug("session: {}", platform_->description());
    spdlog::debug("session: CUDA device for the morph: {}", morph::cuda_device_description());

    t = Clock::now();
    make_scene();
    load_.scene_ms = ms_since(t);
}

Session::~Session() {
    scene_.reset();
    owned_platform_.reset();
}

void Session::make_scene() {
    platform_->make_current();
    scene_.reset();
    render::FaceSceneOptions so;
    so.backend = options_.backend;
    so.morph.accuracy = options_.morph_accuracy;
    scene_ = render::make_face_scene(*platform_, *assets_, so);
    // The scene starts neutral.
    const auto fp = assets_->rig->feature_points(expression::FapValues{});
    for (int i = 0; i < expression::kFeatureCount; ++i)
        points_[std::size_t(i)] =
            assets_->face.feature_points[std::size_t(i)].present
                ? std::optional<glm::vec3>(glm::vec3(float(fp[i][0]), float(fp[i][1]), float(fp[i][2])))
                : std::nullopt;
}

void Session::set_backend(morph::Backend backend) {
    if (backend == morph::Backend::Cuda && !morph::cuda_available())
        fail<EnvironmentError>("session: CUDA backend: {} (use the CPU backend)",
                               morph::cuda_device_description());
    options_.backend = backend;
    make_scene();
}

expression::FaceState Session::face_state(const fap::FapFrame& frame) const {
    return expression::face_state(frame, assets_->emotions, &assets_->visemes);
}

expression::FaceState Session::face_state(const expression::EmotionMix& mix) const {
    return expression::face_state(mix, assets_->emotions);
}

void Session::update(const expression::FaceState& state) {
    scene_->update(state.faps, render::key_weights(assets_->keys, state));
    last_.scene = scene_->last_times();
    const auto fp = assets_->rig->feature_points(state.faps);
    for (int i = 0; i < expression::kFeatureCount; ++i)
        if (points_[std::size_t(i)])
            points_[std::size_t(i)] = glm::vec3(float(fp[i][0]), float(fp[i][1]), float(fp[i][2]));
}

void Session::draw(const render::DrawOptions& options) {
    const auto t = Clock::now();
    scene_->draw(options);
    last_.draw_ms = ms_since(t);
}

render::DrawOptions Session::draw_options(float aspect) const {
    render::DrawOptions d;
    d.camera = scene_->frontal_camera(aspect);
    d.light = scene_->portrait_light();
    d.wrinkles = options_.wrinkles;
    d.shading = options_.shading;
    d.skin = skin_;
    return d;
}

render::ImageRGBA8 Session::render_frame(const expression::FaceState& state) {
    const auto t0 = Clock::now();
    const double cpu0 = process_cpu_ms();
    if (options_.light_on_pose) scene_->bake_light_on_pose(state.faps);
    update(state);
    platform_->begin_frame();
    render::DrawOptions d = draw_options(float(options_.width) / float(options_.height));
    if (options_.side_by_side) {
        // One pose, one camera: the halves differ only where the wrinkle
        // maps change the shading.
        d.viewport = {0, 0, options_.width, options_.height};
        d.wrinkles = true;
        draw(d);
        const double with_ms = last_.draw_ms;
        d.viewport = {options_.width, 0, options_.width, options_.height};
        d.wrinkles = false;
        draw(d);
        last_.draw_ms += with_ms;
    } else {
        draw(d);
    }
    // The draw's GPU work counts as draw, not as read back (which would
    // otherwise wait for it): on llvmpipe that is the rasterisation, on a GPU
    // also a CUDA morph still running. The read back follows at once, so
    // waiting here loses no overlap.
    const auto f = Clock::now();
    scene_->finish();
    last_.draw_ms += ms_since(f);
    const auto t = Clock::now();
    platform_->end_frame();
    render::ImageRGBA8 image = platform_->read_rgba();
    last_.readback_ms = ms_since(t);
    last_.total_ms = ms_since(t0);
    last_.cpu_ms = process_cpu_ms() - cpu0;
    totals_.add(last_);
    return image;
}

render::ImageRGBA8 Session::wrinkle_map() const {
    platform_->make_current();
    render::WrinkleTexture& tex = scene_->wrinkle_texture();
    render::ImageRGBA8 out(tex.width(), tex.height());
    if (tex.format() != render::TexelFormat::RGBA8)
        fail<Error>("session: the wrinkle texture is not RGBA8");
    tex.download(out.pixels.data());
    return out;
}

std::array<std::optional<glm::vec2>, expression::kFeatureCount> Session::screen_points(const render::Camera& camera, int width,
                                                                int height) const {
    std::array<std::optional<glm::vec2>, expression::kFeatureCount> out{};
    const glm::mat4 m = camera.projection * camera.view;
    for (std::size_t i = 0; i < out.size(); ++i) {
        if (!points_[i]) continue;
        const glm::vec4 c = m * glm::vec4(*points_[i], 1.0f);
        if (!(c.w > 0.0f)) continue;
        const float x = c.x / c.w, y = c.y / c.w;
        out[i] = glm::vec2((x * 0.5f + 0.5f) * float(width), (0.5f - y * 0.5f) * float(height));
    }
    return out;
}

std::string Session::description() const {
    const auto& f = assets_->face;
    return fmt::format("{} face ({} vertices, {} triangles), {} feature lines, wrinkle maps {}x{}, morph on {}{}{}",
                       f.name.empty() ? options_.face : f.name, f.vertex_count(), f.mesh.n_faces(),
                       assets_->lines.size(), options_.wrinkle_size, options_.wrinkle_size,
                       morph::to_string(scene_->morpher().backend()),
                       options_.morph_accuracy == morph::Accuracy::Fast ? " (fast)" : "",
                       scene_->uses_interop() ? " (CUDA-GL interop)" : "");
}

}  // namespace emoface::apps
