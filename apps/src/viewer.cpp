// The interactive viewer (viewer.h): a GLFW window (render::WindowPlatform),
// the face drawn by a Session, and a Dear ImGui panel (Debian's libimgui-dev,
// whose .a has the GLFW and OpenGL 3 backends built in).
//
// Each frame: events -> controls -> (when something changed) the face's state
// -> Session::update (rig, layout, morph) -> draw the face into the
// platform's framebuffer -> feature points and lines and the panel on top
// (ImGui) -> end_frame (resolve, blit to the window, swap). The screenshot is
// that framebuffer, so it shows what the window showed.
#include "viewer.h"

#include "clamp_warning.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cfloat>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <glm/geometric.hpp>
#include <spdlog/spdlog.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"
#include "emoface/fap/fap_stream.h"
#include "emoface/fap/feature_points.h"
#include "emoface/render/image_io.h"
#include "emoface/render/platform.h"
#include "au_label.h"
#include "session.h"
#include "viewer_controls.h"

namespace emoface::apps {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t) {
    return std::chrono::duration<double>(Clock::now() - t).count();
}

// How to get the picture without a window, per command that opens the viewer.
std::string headless_way(const std::string& command) {
    if (command == "mix") return "give --out face.png to write the picture instead";
    if (command == "play") return "give --out out.mp4 to render headless instead";
    return "to render without a window use `emoface play FILE.fap --out out.mp4`";
}

// Opens the window, turning GLFW's failure into a message that names the fix.
std::unique_ptr<render::WindowPlatform> open_window(const ViewerOptions& o) {
    require_display(o.command, "the viewer", headless_way(o.command));
    render::PlatformOptions po;
    po.width = o.session.width;
    po.height = o.session.height;
    po.samples = o.session.samples;
    po.title = "emoface view (loading)";
    po.vsync = true;
    try {
        return std::make_unique<render::WindowPlatform>(po);
    } catch (const EnvironmentError& e) {
        const char* display = std::getenv("DISPLAY");
        fail<EnvironmentError>(
            "{}: cannot open a window on DISPLAY={} ({}): check that the X server runs and "
            "lets you connect (xauth), or {}",
            o.command, display ? display : "", e.what(), headless_way(o.command));
    }
}

// Dear ImGui for one window; shut down before the window goes.
class ImGuiLayer {
public:
    explicit ImGuiLayer(GLFWwindow* window) {
        IMGUI_CHECKVERSION();
        ImGui::CreateContext();
        ImGuiIO& io = ImGui::GetIO();
        io.IniFilename = nullptr;  // no imgui.ini left in the working folder
        ImGui::StyleColorsDark();
        ImGui::GetStyle().WindowRounding = 4.0f;
        if (!ImGui_ImplGlfw_InitForOpenGL(window, true) || !ImGui_ImplOpenGL3_Init("#version 330 core")) {
            ImGui::DestroyContext();
            fail<EnvironmentError>("view: Dear ImGui could not start on this OpenGL context");
        }
    }
    ~ImGuiLayer() {
        ImGui_ImplOpenGL3_Shutdown();
        ImGui_ImplGlfw_Shutdown();
        ImGui::DestroyContext();
    }
    ImGuiLayer(const ImGuiLayer&) = delete;
    ImGuiLayer& operator=(const ImGuiLayer&) = delete;

    void begin() {
        ImGui_ImplOpenGL3_NewFrame();
        ImGui_ImplGlfw_NewFrame();
        ImGui::NewFrame();
    }
    // Draws into whatever framebuffer is bound (the platform's draw target).
    void end() {
        ImGui::Render();
        ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }
};

// A frame saying what is being loaded, shown while the Session builds.
void draw_loading_frame(render::WindowPlatform& window, ImGuiLayer& gui, const std::string& what) {
    window.poll_events();
    window.begin_frame();
    gui.begin();
    const ImVec2 size = ImGui::GetIO().DisplaySize;
    ImGui::GetBackgroundDrawList()->AddRectFilled(ImVec2(0, 0), size, IM_COL32(41, 43, 48, 255));
    ImGui::SetNextWindowPos(ImVec2(size.x * 0.5f, size.y * 0.5f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    ImGui::Begin("loading", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_AlwaysAutoResize |
                     ImGuiWindowFlags_NoInputs);
    ImGui::TextUnformatted(what.c_str());
    ImGui::End();
    gui.end();
    window.end_frame();
}

const std::array<const char*, 3> kBackendNames{"auto", "CPU", "CUDA"};

ImU32 region_colour(const std::string& region) {
    // A stable colour per region of the feature-line table.
    static const std::array<ImU32, 8> palette{
        IM_COL32(255, 196, 64, 220), IM_COL32(96, 200, 255, 220), IM_COL32(255, 112, 160, 220),
        IM_COL32(128, 255, 128, 220), IM_COL32(200, 150, 255, 220), IM_COL32(255, 150, 90, 220),
        IM_COL32(90, 240, 220, 220),  IM_COL32(240, 240, 120, 220)};
    std::size_t h = 0;
    for (char c : region) h = h * 131 + static_cast<unsigned char>(c);
    return palette[h % palette.size()];
}

// The panel's width; its text wraps at it.
constexpr float kPanelWidth = 380.0f;

// Greyed text (help, status), wrapped at the panel's edge instead of cut off.
void disabled_wrapped(const std::string& text) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImGui::GetStyle().Colors[ImGuiCol_TextDisabled]);
    ImGui::TextWrapped("%s", text.c_str());
    ImGui::PopStyleColor();
}

// An error in red, wrapped.
void error_wrapped(const std::string& text) {
    ImGui::PushStyleColor(ImGuiCol_Text, ImVec4(1, 0.4f, 0.4f, 1));
    ImGui::TextWrapped("%s", text.c_str());
    ImGui::PopStyleColor();
}

class Viewer {
public:
    Viewer(const ViewerOptions& options, render::WindowPlatform& window, ImGuiLayer& gui,
           Session& session, std::optional<fap::FapStream> stream, const expression::EmotionMix& mix)
        : options_(options), window_(window), gui_(gui), session_(session), stream_(std::move(stream)) {
        for (expression::Emotion e : expression::kEmotions)
            sliders_[std::size_t(expression::emotion_index(e))] = float(mix[e]);
        mix_aus_ = mix.aus;
        driven_by_file_ = stream_.has_value() && options.mix.empty();
        playing_ = driven_by_file_;
        wrinkles_ = options.session.wrinkles;
        thesis_shading_ = options.session.shading == render::Shading::Thesis;
        show_points_ = options.show_points || options.show_labels;
        show_lines_ = options.show_lines;
        show_labels_ = options.show_labels;
        backend_choice_ = int(options.session.backend);
        cuda_ok_ = morph::cuda_available();
        reset_view();
    }

    // Runs until the window closes or quit_after_frames frames were shown.
    void run() {
        auto last = Clock::now();
        int frames = 0;
        // From the fourth frame on (the first ones compile shaders and show
        // the loading panel): wall clock and CPU time, for the closing line.
        constexpr int kSettled = 3;
        Clock::time_point settled_at;
        double settled_cpu_ms = 0;
        while (!window_.should_close()) {
            if (frames == kSettled) {
                settled_at = Clock::now();
                settled_cpu_ms = process_cpu_ms();
            }
            // Idle (nothing plays, changes or is dragged): sleep until an
            // event comes, or a few times a second, instead of spinning.
            const bool busy = (playing_ && stream_) || dirty_ || frames < 3 || ImGui::IsAnyMouseDown() ||
                              options_.quit_after_frames > 0;
            if (busy)
                window_.poll_events();
            else
                glfwWaitEventsTimeout(0.25);
            const auto start = Clock::now();
            const double dt = std::chrono::duration<double>(start - last).count();
            last = start;
            if (playing_ && stream_) advance(dt);
            render_frame();
            // What a frame costs (update, draw, present), not the idle wait.
            const double work = seconds_since(start);
            frame_seconds_ = frames == 0 ? work : 0.9 * frame_seconds_ + 0.1 * work;
            history_[history_at_++ % history_.size()] = float(work * 1000.0);
            // The title says "loading" until the face and the panel are on
            // screen (ImGui shows a new window from its second frame on).
            if (frames == 2) glfwSetWindowTitle(window_.window(), title().c_str());
            ++frames;
            if (options_.quit_after_frames > 0 && frames >= options_.quit_after_frames) break;
        }
        if (frames > kSettled) {
            const int n = frames - kSettled;
            const double wall_ms = seconds_since(settled_at) * 1000.0;
            const std::string load = load_average();
            std::printf("%s: %d frames after the first %d: %.1f ms a frame (%.1f frames/s), CPU %.1f ms a frame "
                        "(user + sys, all threads)%s\n",
                        options_.command.c_str(), n, kSettled, wall_ms / n, wall_ms > 0 ? 1000.0 * n / wall_ms : 0.0,
                        (process_cpu_ms() - settled_cpu_ms) / n, load.empty() ? "" : ("; load average " + load).c_str());
        }
    }

private:
    std::string title() const {
        std::string what = stream_ ? (options_.fap_path) : "emotion mix";
        return fmt::format("emoface view: {}", what);
    }

    void reset_view() {
        const float aspect = float(window_.width()) / float(std::max(window_.height(), 1));
        const render::Camera frontal = session_.scene().frontal_camera(aspect, 20.0f);
        const auto& mesh = session_.assets().face.mesh;
        glm::vec3 lo(1e30f), hi(-1e30f);
        for (auto v : mesh.vertices()) {
            const auto& p = mesh.point(v);
            lo = glm::min(lo, glm::vec3(p[0], p[1], p[2]));
            hi = glm::max(hi, glm::vec3(p[0], p[1], p[2]));
        }
        camera_ = OrbitCamera::around(frontal, lo, hi, 20.0f);
        light_ = LightControl::from(session_.scene().portrait_light());
    }

    void advance(double dt) {
        const double duration = double(stream_->frames.size() - 1) / stream_->fps;
        time_ += dt * double(speed_);
        if (time_ > duration) {
            if (loop_ && duration > 0) {
                time_ = std::fmod(time_, duration);
            } else {
                time_ = duration;
                playing_ = false;
            }
        }
        dirty_ = true;
    }

    expression::EmotionMix slider_mix() const {
        expression::EmotionMix mix;
        double sum = 0;
        for (float w : sliders_) sum += double(w);
        // Float rounding of the slider rule can leave the sum a hair over 1.
        const double scale = sum > 1.0 ? 1.0 / sum : 1.0;
        for (std::size_t i = 0; i < sliders_.size(); ++i) mix.weights[i] = double(sliders_[i]) * scale;
        mix.aus = mix_aus_;
        return mix;
    }

    void update_face() {
        if (driven_by_file_ && stream_) {
            state_ = session_.face_state(stream_->sample(time_));
            // The sliders follow the file's mix (moving one takes over).
            for (std::size_t i = 0; i < sliders_.size(); ++i) sliders_[i] = float(state_.mix.weights[i]);
        } else {
            state_ = session_.face_state(slider_mix());
        }
        const auto t = Clock::now();
        session_.update(state_);
        update_ms_ = seconds_since(t) * 1000.0;
        dirty_ = false;
    }

    void handle_mouse() {
        const ImGuiIO& io = ImGui::GetIO();
        if (io.WantCaptureMouse) return;
        const float dx = io.MouseDelta.x, dy = io.MouseDelta.y;
        // A drag counts from the frame after the press: the press frame's
        // delta is the pointer's travel before the button went down.
        auto dragging = [](ImGuiMouseButton b) {
            return ImGui::IsMouseDragging(b, 0.0f) && !ImGui::IsMouseClicked(b);
        };
        if (dragging(ImGuiMouseButton_Left)) camera_.orbit(dx, dy);
        if (dragging(ImGuiMouseButton_Right)) light_.drag(dx, dy);
        if (dragging(ImGuiMouseButton_Middle)) camera_.pan(dx, dy, io.DisplaySize.y);
        if (io.MouseWheel != 0.0f) camera_.zoom(io.MouseWheel);
        if (!io.WantCaptureKeyboard) {
            if (ImGui::IsKeyPressed(GLFW_KEY_R, false)) reset_view();
            if (ImGui::IsKeyPressed(GLFW_KEY_SPACE, false) && stream_) toggle_play();
            if (ImGui::IsKeyPressed(GLFW_KEY_ESCAPE, false)) glfwSetWindowShouldClose(window_.window(), 1);
        }
    }

    void toggle_play() {
        playing_ = !playing_;
        if (playing_) {
            driven_by_file_ = true;
            const double duration = double(stream_->frames.size() - 1) / stream_->fps;
            if (time_ >= duration) time_ = 0;
        }
        dirty_ = true;
    }

    void render_frame() {
        window_.make_current();
        // ImGui's frame opens before the face is updated (the panel's controls
        // decide what the face shows) and closes after the face is drawn.
        gui_.begin();
        handle_mouse();
        draw_panel();
        if (dirty_ || first_) update_face();
        first_ = false;

        const int w = window_.width(), h = window_.height();
        render::DrawOptions d;
        d.camera = camera_.camera(float(w) / float(std::max(h, 1)));
        d.light = session_.scene().portrait_light();
        d.light.position = light_.direction();
        d.wrinkles = wrinkles_;
        d.shading = thesis_shading_ ? render::Shading::Thesis : render::Shading::Skin;
        d.skin = session_.skin();
        window_.begin_frame();
        const auto t = Clock::now();
        session_.draw(d);
        draw_ms_ = seconds_since(t) * 1000.0;
        if (show_points_ || show_lines_) draw_feature_overlay(d.camera, w, h);
        gui_.end();
        window_.end_frame();
    }

    // The feature points and lines of the current pose, projected with the
    // camera; points on the far side of the head (their vertex normal turned
    // away) are left out so the overlay reads like the surface.
    void draw_feature_overlay(const render::Camera& camera, int width, int height) {
        const auto screen = session_.screen_points(camera, width, height);
        const ImGuiIO& io = ImGui::GetIO();
        const ImVec2 scale(io.DisplayFramebufferScale.x > 0 ? 1.0f / io.DisplayFramebufferScale.x : 1.0f,
                           io.DisplayFramebufferScale.y > 0 ? 1.0f / io.DisplayFramebufferScale.y : 1.0f);
        const auto& face = session_.assets().face;
        const auto& scene = session_.scene();
        const glm::vec3 eye = camera_.eye();
        std::array<bool, expression::kFeatureCount> visible{};
        for (std::size_t i = 0; i < screen.size(); ++i) {
            if (!screen[i]) continue;
            const int v = face.feature_points[i].vertex;
            if (v >= 0 && v < int(scene.mesh().n_vertices())) {
                const auto s = scene.surface_point(v);  // posed on either geometry device
                visible[i] = glm::dot(s.normal, eye - s.position) > 0.0f;
            } else {
                visible[i] = true;
            }
        }
        ImDrawList* dl = ImGui::GetBackgroundDrawList();
        auto at = [&](std::size_t i) { return ImVec2(screen[i]->x * scale.x, screen[i]->y * scale.y); };
        if (show_lines_)
            for (const auto& line : session_.lines()) {
                const auto a = std::size_t(line.from), b = std::size_t(line.to);
                if (a < screen.size() && b < screen.size() && visible[a] && visible[b])
                    dl->AddLine(at(a), at(b), region_colour(line.region), 1.5f);
            }
        if (show_points_)
            for (std::size_t i = 0; i < screen.size(); ++i) {
                if (!visible[i]) continue;
                dl->AddCircleFilled(at(i), 2.5f, IM_COL32(255, 60, 40, 255));
                if (show_labels_) {
                    const std::string id(fap::feature_points()[i].id);
                    dl->AddText(ImVec2(at(i).x + 3, at(i).y - 13), IM_COL32(255, 255, 210, 230),
                                id.c_str());
                }
            }
    }

    void draw_panel() {
        // The panel fits its content, at a fixed width (long lines wrap), and
        // at most the window's height: below that it scrolls instead of
        // running off the window's bottom edge.
        const float height = ImGui::GetIO().DisplaySize.y;
        ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowSizeConstraints(ImVec2(kPanelWidth, 0), ImVec2(kPanelWidth, std::max(64.0f, height - 16)));
        // A small window starts with the panel folded, so the face shows.
        ImGui::SetNextWindowCollapsed(window_.width() < 800, ImGuiCond_FirstUseEver);
        ImGui::SetNextWindowBgAlpha(0.82f);
        ImGui::Begin("emoface", nullptr, ImGuiWindowFlags_AlwaysAutoResize);
        frame_time_section();
        if (stream_) timeline_section();
        emotion_section();
        display_section();
        backend_section();
        ImGui::SetNextItemOpen(options_.show_wrinkle_map, ImGuiCond_Once);
        if (ImGui::CollapsingHeader("Wrinkle map")) wrinkle_map_section();
        ImGui::Separator();
        disabled_wrapped(stream_ ? "left-drag orbit, wheel zoom, middle-drag pan, right-drag light, R reset view, "
                                   "space play/pause, Esc quit"
                                 : "left-drag orbit, wheel zoom, middle-drag pan, right-drag light, R reset view, "
                                   "Esc quit");
        ImGui::End();
    }

    void frame_time_section() {
        const double ms = frame_seconds_ * 1000.0;
        ImGui::Text("frame %.1f ms (%.0f frames/s at most)", ms, ms > 0 ? 1000.0 / ms : 0.0);
        const auto& s = session_.scene().last_times();
        ImGui::Text("update %.1f ms, draw %.1f ms (submission)", update_ms_, draw_ms_);
        disabled_wrapped(fmt::format("rig {:.1f}  layout {:.1f}  morph {:.1f}  uv {:.1f}  tangents {:.1f}  upload {:.1f}",
                                     s.rig_ms, s.layout_ms, s.morph_ms, s.uv_ms, s.tangents_ms, s.upload_ms));
        ImGui::PlotLines("##frame ms", history_.data(), int(history_.size()),
                         int(history_at_ % history_.size()), "frame ms", 0.0f, FLT_MAX,
                         ImVec2(-1, 32));
    }

    void timeline_section() {
        if (!ImGui::CollapsingHeader("FAP file", ImGuiTreeNodeFlags_DefaultOpen)) return;
        const int last = int(stream_->frames.size()) - 1;
        const double fps = stream_->fps;
        ImGui::TextWrapped("%s: %d frames at %.4g frames/s", options_.fap_path.c_str(), last + 1, fps);
        if (ImGui::Button(playing_ ? "Pause" : "Play")) toggle_play();
        ImGui::SameLine();
        if (ImGui::Button("|<")) {
            time_ = 0;
            driven_by_file_ = true;
            dirty_ = true;
        }
        ImGui::SameLine();
        ImGui::Checkbox("loop", &loop_);
        ImGui::SameLine();
        ImGui::SetNextItemWidth(-1);
        ImGui::SliderFloat("##speed", &speed_, 0.1f, 2.0f, "speed %.2fx");
        int frame = int(std::floor(time_ * fps + 1e-6));
        ImGui::SetNextItemWidth(-1);
        if (ImGui::SliderInt("##frame", &frame, 0, last, "frame %d")) {
            time_ = double(frame) / fps;
            driven_by_file_ = true;
            dirty_ = true;
        }
        ImGui::TextWrapped("%.2f s / %.2f s, mix %s", time_, double(last) / fps,
                    expression::mix_source_name(state_.mix_source));
        if (!driven_by_file_) {
            ImGui::TextColored(ImVec4(1, 0.8f, 0.4f, 1), "the sliders drive the face");
            ImGui::SameLine();
            if (ImGui::SmallButton("back to the file")) {
                driven_by_file_ = true;
                dirty_ = true;
            }
        }
    }

    void emotion_section() {
        if (!ImGui::CollapsingHeader("Emotions", ImGuiTreeNodeFlags_DefaultOpen)) return;
        for (expression::Emotion e : expression::kEmotions) {
            const int i = expression::emotion_index(e);
            float value = sliders_[std::size_t(i)];
            ImGui::SetNextItemWidth(200);
            if (ImGui::SliderFloat(expression::emotion_name(e), &value, 0.0f, 1.0f, "%.2f")) {
                // Dragging a slider while a file plays takes the face over.
                driven_by_file_ = false;
                playing_ = false;
                scaled_others_ = set_emotion_slider(sliders_, i, value);
                dirty_ = true;
            }
        }
        float sum = 0;
        for (float w : sliders_) sum += w;
        char overlay[64];
        std::snprintf(overlay, sizeof overlay, "sum %.2f, neutral %.2f", sum, std::max(0.0f, 1.0f - sum));
        ImGui::ProgressBar(std::min(sum, 1.0f), ImVec2(-1, 0), overlay);
        if (scaled_others_ && sum >= 0.999f)
            ImGui::TextColored(ImVec4(1, 0.8f, 0.4f, 1), "sum at 1: the other sliders were scaled down");
        // The box shows the mix the sliders show (a file's fitted mix
        // included), except while it is being typed in.
        if (!mix_box_active_) std::snprintf(mix_text_, sizeof mix_text_, "%s", mix_label(slider_mix()).c_str());
        ImGui::SetNextItemWidth(200);
        const bool entered =
            ImGui::InputText("mix", mix_text_, sizeof mix_text_, ImGuiInputTextFlags_EnterReturnsTrue);
        mix_box_active_ = ImGui::IsItemActive();
        if (entered) {
            try {
                const expression::EmotionMix m = expression::parse_emotion_mix(mix_text_, true);
                session_.face_state(m);  // an AU the face's table lacks is refused here, not mid-frame
                for (std::size_t i = 0; i < sliders_.size(); ++i) sliders_[i] = float(m.weights[i]);
                mix_aus_ = m.aus;
                driven_by_file_ = false;
                playing_ = false;
                mix_error_.clear();
                dirty_ = true;
            } catch (const Error& e) {
                mix_error_ = e.what();
            }
        }
        ImGui::SameLine();
        if (ImGui::Button("neutral")) {
            sliders_.fill(0.0f);
            mix_aus_ = {};
            driven_by_file_ = false;
            playing_ = false;
            dirty_ = true;
        }
        // The AUs of the face shown (a file's frame, or the sliders' mix).
        ImGui::TextWrapped("AUs: %s", au_label(state_.aus).c_str());
        if (!mix_error_.empty()) error_wrapped(mix_error_);
    }

    void display_section() {
        if (!ImGui::CollapsingHeader("Display", ImGuiTreeNodeFlags_DefaultOpen)) return;
        ImGui::Checkbox("wrinkles", &wrinkles_);
        ImGui::SameLine();
        ImGui::Checkbox("thesis shading", &thesis_shading_);
        ImGui::Checkbox("feature points", &show_points_);
        ImGui::Checkbox("feature lines", &show_lines_);
        ImGui::SameLine();
        ImGui::BeginDisabled(!show_points_);
        ImGui::Checkbox("labels", &show_labels_);
        ImGui::EndDisabled();
        // The light's angles are read beside their sliders: ImGui writes a
        // slider's value in its middle, where the handle covers it at 0 deg.
        float az = light_.azimuth * 57.29578f, el = light_.elevation * 57.29578f;
        ImGui::SetNextItemWidth(200);
        if (ImGui::SliderFloat("##light azimuth", &az, -180.0f, 180.0f, "")) light_.azimuth = az / 57.29578f;
        ImGui::SameLine();
        ImGui::Text("light azimuth %+.0f deg", double(az));
        ImGui::SetNextItemWidth(200);
        if (ImGui::SliderFloat("##light elevation", &el, -85.0f, 85.0f, "")) light_.elevation = el / 57.29578f;
        ImGui::SameLine();
        ImGui::Text("elevation %+.0f deg", double(el));
        if (ImGui::Button("reset view")) reset_view();
    }

    void backend_section() {
        if (!ImGui::CollapsingHeader("Morph backend", ImGuiTreeNodeFlags_DefaultOpen)) return;
        int choice = backend_choice_;
        for (int b = 0; b < 3; ++b) {
            if (b > 0) ImGui::SameLine();
            ImGui::BeginDisabled(b == int(morph::Backend::Cuda) && !cuda_ok_);
            ImGui::RadioButton(kBackendNames[std::size_t(b)], &choice, b);
            ImGui::EndDisabled();
        }
        if (choice != backend_choice_) {
            try {
                session_.set_backend(morph::Backend(choice));
                backend_choice_ = choice;
                backend_error_.clear();
                dirty_ = true;
            } catch (const Error& e) {
                backend_error_ = e.what();
            }
        }
        ImGui::Text("morph on %s%s", morph::to_string(session_.backend()),
                    session_.scene().uses_interop() ? " (CUDA-GL interop)" : "");
        if (!cuda_ok_) disabled_wrapped("CUDA: " + morph::cuda_device_description());
        if (!backend_error_.empty()) error_wrapped(backend_error_);
    }

    void wrinkle_map_section() {
        // The morphed wrinkle map (rows top first, as ImGui's v runs) with L*.
        const render::WrinkleTexture& tex = session_.scene().wrinkle_texture();
        const float side = ImGui::GetContentRegionAvail().x;
        const ImVec2 origin = ImGui::GetCursorScreenPos();
        ImGui::Image(reinterpret_cast<ImTextureID>(static_cast<std::uintptr_t>(tex.gl_texture())),
                     ImVec2(side, side * float(tex.height()) / float(tex.width())));
        const auto& layout = session_.layout();
        ImDrawList* dl = ImGui::GetWindowDrawList();
        const float h = side * float(tex.height()) / float(tex.width());
        // L* points outside the map (the crown, the neck) are cut at its edge.
        dl->PushClipRect(origin, ImVec2(origin.x + side, origin.y + h), true);
        for (int i = 0; i < expression::kFeatureCount; ++i)
            if (layout.present[std::size_t(i)])
                dl->AddCircleFilled(ImVec2(origin.x + layout.points[std::size_t(i)].x * side,
                                           origin.y + layout.points[std::size_t(i)].y * h),
                                    1.5f, IM_COL32(255, 60, 40, 255));
        dl->PopClipRect();
    }

    const ViewerOptions& options_;
    render::WindowPlatform& window_;
    ImGuiLayer& gui_;
    Session& session_;
    std::optional<fap::FapStream> stream_;

    expression::FaceState state_;
    std::array<float, 6> sliders_{};
    bool scaled_others_ = false;
    // The AU terms of the mix given (--mix "0.6 joy + 0.3 AU4") or typed in
    // the box: shown on top of the sliders' emotions until "neutral".
    expression::AuIntensities mix_aus_;
    char mix_text_[128] = {};
    bool mix_box_active_ = false;
    std::string mix_error_, backend_error_;

    OrbitCamera camera_;
    LightControl light_;
    bool thesis_shading_ = false;  // the thesis's Blinn-Phong instead of the skin model
    bool wrinkles_ = true, show_points_ = false, show_lines_ = false, show_labels_ = false;
    int backend_choice_ = 0;
    bool cuda_ok_ = false;

    bool driven_by_file_ = false, playing_ = false, loop_ = true;
    float speed_ = 1.0f;
    double time_ = 0;

    bool dirty_ = true, first_ = true;
    double frame_seconds_ = 0, update_ms_ = 0, draw_ms_ = 0;
    std::array<float, 120> history_{};
    std::size_t history_at_ = 0;
};

}  // namespace

void add_viewer_options(CLI::App& sub, ViewerOptions& o, CLI::Option* out) {
    const std::string which = out ? "Viewer (without --out): " : "";
    CLI::Option* const added[] = {
        sub.add_flag("--points", o.show_points, which + "start with the feature points shown"),
        sub.add_flag("--lines", o.show_lines, which + "start with the morph's feature lines shown"),
        sub.add_flag("--labels", o.show_labels,
                     which + "start with the feature points shown with their labels (2.1 ... 11.6)"),
        sub.add_flag("--wrinkle-map", o.show_wrinkle_map,
                     which + "start with the morphed wrinkle map (and L*) shown in the panel"),
        sub.add_option("--quit-after", o.quit_after_frames,
                       which + "close after this many frames (0: when the window is closed)")
            ->check(CLI::NonNegativeNumber),
        sub.add_option("--screenshot", o.screenshot,
                       which + "write the window's last frame to this image (.png, ...) on closing"),
    };
    // Given with --out they would be ignored: say so instead.
    if (out)
        for (CLI::Option* option : added) option->excludes(out);
}

int run_viewer(const ViewerOptions& options) {
    const std::string& command = options.command;
    // Bad input fails before anything opens.
    const SessionOptions& so = options.session;
    if (so.width < 64 || so.height < 64 || so.width > 8192 || so.height > 8192)
        fail<InputError>("{}: window size {}x{}: expected 64..8192 on each side", command, so.width, so.height);
    if (so.side_by_side)
        fail<InputError>("{}: --side-by-side is for pictures written with --out, not the viewer", command);
    if (options.quit_after_frames < 0)
        fail<InputError>("{}: --quit-after {}: expected a frame count >= 0", command, options.quit_after_frames);
    std::optional<fap::FapStream> stream;
    if (!options.fap_path.empty()) stream = fap::resolve_untransmitted(load_fap_stream(options.fap_path, so.data));
    const expression::EmotionMix mix =
        options.mix.empty() ? expression::EmotionMix{} : expression::parse_emotion_mix(options.mix);
    std::error_code ec;  // a FIFO, a device, a link loop: the face readers say which
    if (so.face != "default" && !std::filesystem::exists(so.face, ec) && !ec)
        fail<InputError>("{}: --face {}: no such file (expected default, FILE.wfm or FILE.obj)", command, so.face);
    if (!so.fdp.empty() && !std::filesystem::exists(so.fdp, ec) && !ec)
        fail<InputError>("{}: --fdp {}: no such file", command, so.fdp);
    if (!so.wrinkle_folder.empty() && !std::filesystem::is_directory(so.wrinkle_folder))
        fail<InputError>("{}: --wrinkles {}: no such folder (expected one `emoface wrinkles --out` wrote)", command,
                         so.wrinkle_folder);
    std::optional<OutputFile> screenshot;
    if (!options.screenshot.empty()) {
        split_output_path(options.screenshot, command, "--screenshot");
        render::check_image_output(options.screenshot, command + ": --screenshot " + options.screenshot);
        screenshot.emplace(options.screenshot, command, "--screenshot");
    }
    if (so.backend == morph::Backend::Cuda && !morph::cuda_available())
        fail<EnvironmentError>("{}: --backend cuda: {} (use --backend cpu or auto)", command,
                               morph::cuda_device_description());

    auto window = open_window(options);
    if (stream && so.clamp_faps) warn_clamped_faps(command, options.fap_path, *stream, so.data);
    auto gui = std::make_unique<ImGuiLayer>(window->window());
    draw_loading_frame(*window, *gui, "loading the face and its wrinkle maps ...");

    Session session(so, window.get());
    spdlog::debug("{}: {} on {}", command, session.description(), window->description());

    {
        Viewer viewer(options, *window, *gui, session, std::move(stream), mix);
        viewer.run();
    }
    if (!options.screenshot.empty()) {
        window->make_current();
        render::write_image(screenshot->path(), window->read_rgba());
        screenshot->commit();
        std::printf("%s: wrote %s (%dx%d, the window's last frame)\n", command.c_str(), options.screenshot.c_str(),
                    window->width(), window->height());
    }
    gui.reset();  // before the session and window it draws into
    return 0;
}

}  // namespace emoface::apps
