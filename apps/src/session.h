#pragma once
// What every drawing command (play, mix, inspect, morph) and the viewer share:
// a face and its assets (render::load_face_assets: rig, profiles, feature
// lines, and the seven key wrinkle maps, generated once or read from a
// --wrinkles folder), a GL platform (headless, or a window the caller made)
// and the FaceScene that draws one frame of it.
//
//   Session s(options);                       // headless, options.width x height
//   auto state = s.face_state(stream.resolved(k));
//   render::ImageRGBA8 img = s.render_frame(state);
//
// The viewer passes its own WindowPlatform and draws with its own camera:
//   Session s(options, &window);
//   s.update(state); window.begin_frame(); s.draw(opts); window.end_frame();
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "emoface/expression/emotion.h"
#include "emoface/expression/face_state.h"
#include "emoface/fap/fap_stream.h"
#include "emoface/morph/morph.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/face_scene.h"
#include "emoface/render/image.h"
#include "emoface/render/platform.h"
#include "au_label.h"
#include "cli_checks.h"

namespace CLI {
class App;
class Option;
}  // namespace CLI

namespace emoface::apps {

struct SessionOptions {
    // "default" (the generated face of data/face), a Candide-3 FILE.wfm, or
    // FILE.obj with its feature points in `fdp` (default: FILE.fdp.json
    // beside it, as `emoface face` writes it).
    std::string face = "default";
    std::string fdp;
    std::string data = EMOFACE_DATA_DIR;  // the project's data/ folder
    morph::Backend backend = morph::Backend::Auto;
    // Exact, or the morph's grid-interpolated fast mode (morph.h): the
    // commands that play in time (play, view) take fast by default, the
    // pictures (mix, inspect, morph) exact.
    morph::Accuracy morph_accuracy = morph::Accuracy::Exact;
    int wrinkle_size = 512;  // side of the key and morphed wrinkle maps, 256..4096
    bool wrinkles = true;    // false: draw with geometric normals only
    // Skin (data/render/skin.json's model and light rig) or the thesis's
    // Blinn-Phong (5.5.1) under the portrait light alone.
    render::Shading shading = render::Shading::Skin;
    // The wrinkle maps' texture space: projective (the default face), or
    // anchored (the mesh's own UVs; maps painted in UV space).
    render::WrinkleLayout layout = render::WrinkleLayout::Projective;
    // The picture's size (headless), or the viewer window's.
    int width = 640;
    int height = 480;
    int samples = 4;
    // Headless pictures: two of width x height side by side, with the
    // wrinkle maps (left) and without (right), one pose.
    bool side_by_side = false;
    // The width of a rendered picture: width, or twice it side by side.
    int picture_width() const { return side_by_side ? 2 * width : width; }
    // For reports: "" (with wrinkles), ", without wrinkles" or ", with | without wrinkles".
    const char* wrinkles_note() const {
        return side_by_side ? ", with | without wrinkles" : wrinkles ? "" : ", without wrinkles";
    }
    // The default face's mesh resolution (1 = face.json's) and base-colour
    // size (0 = face.json's): smaller loads faster (tests, quick looks).
    // A folder of key wrinkle maps with their layouts (as `emoface wrinkles`
    // writes it, possibly with painted maps): used instead of generating them.
    std::string wrinkle_folder;
    double face_resolution = 1.0;
    int texture_size = 0;
    // FAPs clamped to the face's range (data/expression/fap_ranges.json);
    // false (--no-clamp) plays a file's values raw.
    bool clamp_faps = true;
    // The occlusion and the key's shadows baked again on each picture's pose
    // (FaceScene::bake_light_on_pose: about a second a picture): the
    // pictures (mix, inspect; morph's thesis shading has neither) do; what
    // plays in time keeps the rest shape's.
    bool light_on_pose = false;
};

// The options every drawing command (play, mix, inspect, morph) and `view`
// share, as they come from the command line: --face, --fdp, --backend,
// --wrinkle-size, --samples, --no-wrinkles, --wrinkles, --face-resolution,
// --texture-size, --data, --layout; the commands that write pictures (play,
// mix) add --side-by-side.
struct SessionArgs {
    SessionOptions options;
    std::string backend = "auto";
    // --morph-accuracy exact | fast; empty: the command's default
    // (morph_accuracy_for()).
    std::string morph_accuracy;
    std::string layout = "projective";
    std::string shading = "skin";
    bool no_wrinkles = false;
    bool no_clamp = false;
    // Checks and resolves them (InputError starting `command: `); width and
    // height are the headless platform's.
    SessionOptions resolve(const std::string& command, int width, int height) const;
};
void add_session_options(CLI::App& command, SessionArgs& args);
// --side-by-side (with | without wrinkles), for the commands that write
// pictures; returned so a command can tie it to its --out.
CLI::Option* add_side_by_side_option(CLI::App& command, SessionArgs& args);
// --no-clamp, for the commands that play FAP files (play, inspect, view).
void add_clamp_option(CLI::App& command, SessionArgs& args);

// Wall-clock milliseconds of loading, once per session.
struct LoadTimes {
    double face_ms = 0;      // build or read the mesh and feature points
    double rig_ms = 0;       // the rig's influence weights
    double profiles_ms = 0;  // emotion/viseme profiles, feature lines, wrinkle spec
    double keys_ms = 0;      // the seven key wrinkle maps
    double platform_ms = 0;  // GL context (headless only; 0 for a caller's window)
    double scene_ms = 0;     // FaceScene: meshes, textures, morph setup (allocate + upload)
    double total() const {
        return face_ms + rig_ms + profiles_ms + keys_ms + platform_ms + scene_ms;
    }
};

// Wall-clock milliseconds of one frame's stages.
struct FrameTimes {
    render::FrameStageTimes scene;  // rig, layout, morph, uv, tangents, upload
    double draw_ms = 0;             // the GL draw: in render_frame() up to a glFinish (the GPU's
                                    // work included), in draw() its submission only
    double readback_ms = 0;         // resolve + read RGBA
    double total_ms = 0;            // the whole render_frame()
    // The process's CPU time (user + sys, every thread: llvmpipe's
    // rasterisers too) over the whole render_frame(): on a loaded machine
    // the wall clock counts other programs' turns, this does not.
    double cpu_ms = 0;
};

// Sums frame times to report means.
struct FrameTimeTotals {
    FrameTimes sum;
    int frames = 0;
    void add(const FrameTimes& t);
    FrameTimes mean() const;
};

// The CPU time of the whole process so far (user + sys, every thread), ms.
double process_cpu_ms();
// The 1-minute load average ("" where unknown): a wall-clock figure on a
// shared machine is read with it.
std::string load_average();

// Lines of "stage   mean ms" for a report: loading, then per frame.
std::string format_times(const LoadTimes& load, const FrameTimeTotals& frames);


// Reads an animation file of any known format for playing (a FAP file or a
// capture CSV, expression/capture.h; `data` holds the AU and ARKit tables:
// the command's --data, no default, so none reads the built-in tables behind
// its user's back); InputError when it has no frames or its frame rate is not
// positive.
fap::FapStream load_fap_stream(const std::string& path, const std::string& data);

// The morph accuracy a command takes when --morph-accuracy is not given:
// fast for the commands that play frames in time (play, view; their
// frames differ from exact ones by far less than a golden's tolerance, see
// tests/apps/realtime_test.cpp), exact for the pictures.
morph::Accuracy morph_accuracy_for(const std::string& command);

// "auto" | "cpu" | "cuda"; InputError otherwise.
morph::Backend parse_backend(const std::string& text, const std::string& command);
// Throws EnvironmentError "COMMAND: no display for WHAT (DISPLAY is not
// set): HEADLESS, or run it ..." when no window can be opened (neither
// DISPLAY nor WAYLAND_DISPLAY set); `headless` names the way without one.
void require_display(const std::string& command, const std::string& what, const std::string& headless);

class Session {
public:
    // Loads the face and its assets and opens the platform: a headless one
    // of options.width x height, or `window` (made by the caller, which must
    // outlive the session). Throws InputError for a bad face or data folder,
    // EnvironmentError when no GL context (or, for --backend cuda, no GPU)
    // can be had.
    explicit Session(const SessionOptions& options, render::Platform* window = nullptr);
    ~Session();
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    // The state a FAP frame shows (pass a resolved or sampled frame).
    expression::FaceState face_state(const fap::FapFrame& frame) const;
    // The state a mix shows: its profiles' FAPs and the mix for the wrinkles.
    expression::FaceState face_state(const expression::EmotionMix& mix) const;

    // Poses the scene: rig, layout, morph of the keys by the state's mix.
    void update(const expression::FaceState& state);
    // Draws into the platform's bound framebuffer (call begin_frame first).
    void draw(const render::DrawOptions& options);
    // The frontal camera and portrait light for this aspect ratio, wrinkles
    // as the options say.
    render::DrawOptions draw_options(float aspect) const;
    // update + begin_frame + draw (frontal, whole target; with
    // options.side_by_side: with wrinkles left, without right) + end_frame +
    // read.
    render::ImageRGBA8 render_frame(const expression::FaceState& state);

    // The current (morphed) wrinkle map, RGBA8 normal map, rows top first.
    render::ImageRGBA8 wrinkle_map() const;
    // The current pose's feature points in face space (absent: nullopt).
    const std::array<std::optional<glm::vec3>, expression::kFeatureCount>& feature_points() const { return points_; }
    // The feature points projected by `camera` to pixel coordinates of a
    // width x height image (x right, y DOWN from the top row); nullopt for
    // absent points and those behind the camera.
    std::array<std::optional<glm::vec2>, expression::kFeatureCount> screen_points(const render::Camera& camera, int width,
                                                           int height) const;
    // The current layout L*: feature points in wrinkle-map coordinates
    // (normalised, y down).
    const expression::FeatureLayout& layout() const { return scene_->layout(); }
    // The morph's feature lines (pairs of feature-point indices).
    const std::vector<expression::FeatureLine>& lines() const { return assets_->lines; }

    // Rebuilds the scene on another morph backend (keys are reused).
    void set_backend(morph::Backend backend);
    morph::Backend backend() const { return scene_->morpher().backend(); }
    void set_wrinkles(bool on) { options_.wrinkles = on; }
    void set_shading(render::Shading shading) { options_.shading = shading; }
    render::Shading shading() const { return options_.shading; }
    // The skin model's parameters and light rig (data/render/skin.json).
    const render::SkinShading& skin() const { return skin_; }
    bool wrinkles() const { return options_.wrinkles; }

    const SessionOptions& options() const { return options_; }
    const render::FaceAssets& assets() const { return *assets_; }
    render::FaceScene& scene() { return *scene_; }
    render::Platform& platform() { return *platform_; }
    // "default face (12345 vertices), morph on CPU" and the like.
    std::string description() const;

    const LoadTimes& load_times() const { return load_; }
    const FrameTimes& last_frame_times() const { return last_; }
    const FrameTimeTotals& frame_totals() const { return totals_; }

private:
    void make_scene();

    SessionOptions options_;
    std::unique_ptr<render::FaceAssets> assets_;
    render::SkinShading skin_;  // data/render/skin.json
    std::unique_ptr<render::Platform> owned_platform_;
    render::Platform* platform_ = nullptr;
    std::unique_ptr<render::FaceScene> scene_;
    std::array<std::optional<glm::vec3>, expression::kFeatureCount> points_{};
    LoadTimes load_;
    FrameTimes last_;
    FrameTimeTotals totals_;
};

// Loads the face named by options.face / options.fdp (no rig, no keys).
expression::Face load_session_face(const SessionOptions& options);

}  // namespace emoface::apps
