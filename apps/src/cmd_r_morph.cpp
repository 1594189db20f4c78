// emoface morph: the thesis's figure 6.4 (the transition from one key
// expression to another at t = 0, 0.25, 0.5, 0.75, 1) and its stage timings
// (table 6.1: allocate, upload, kernel, bump mapping, free).
// Rows of the sheet:
// The two keys are the thesis's emotion keys, made from the AU wrinkle
// library like every key (render::make_emotion_key: the union of the
// emotion's AUs' wrinkles at its layout), blended convexly as the thesis does.
//   1. the wrinkle map morphed with Beier-Neely onto the face's layout at t
//   2. the same two maps cross-dissolved, with no warp (the features of the
//      two keys sit in different places, so their wrinkles ghost)
//   3. the face at (1 - t) from + t to, bump-mapped with row 1's map
//   4. the same face with row 2's map
//   emoface morph --from anger --to surprise --steps 5 --out sheet.png
#include <algorithm>
#include <chrono>
#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include "command.h"
#include "emoface/common/error.h"
#include "emoface/common/timing.h"
#include "emoface/expression/emotion.h"
#include "emoface/morph/morph.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/image_io.h"
#include "session.h"
#include "sheet.h"

namespace {

using namespace emoface;
using namespace emoface::apps;

struct MorphArgs {
    std::string from = "anger", to = "surprise", out;
    int steps = 5, tile = 256;
    bool raw_map = false;
    SessionArgs session;
    MorphArgs() { session.options.wrinkle_size = 256; }  // the thesis's maps
};

// The key named: 0 neutral, 1 + emotion_index for an emotion.
int key_index(const std::string& name, const char* option) {
    if (name == "neutral") return 0;
    const auto e = expression::find_emotion(name);
    if (!e)
        fail<InputError>("morph: {} '{}': expected neutral, joy, sadness, anger, fear, disgust or surprise",
                         option, name);
    return expression::emotion_index(*e) + 1;
}

std::optional<expression::Emotion> key_emotion(int key) {
    if (key == 0) return std::nullopt;
    return expression::kEmotions[std::size_t(key - 1)];
}

expression::EmotionMix transition_mix(int from, int to, double t) {
    expression::EmotionMix m;
    if (from > 0) m.weights[std::size_t(from - 1)] += 1.0 - t;
    if (to > 0) m.weights[std::size_t(to - 1)] += t;
    return m;
}

// (1 - t) a + t b per texel, the normal renormalised as the morph does.
render::ImageRGBA8 cross_dissolve(const expression::NormalMap& a, const expression::NormalMap& b, float t) {
    render::ImageRGBA8 out(a.width, a.height);
    for (std::size_t i = 0; i + 3 < out.pixels.size(); i += 4) {
        float n[3];
        for (int c = 0; c < 3; ++c)
            n[c] = ((1.0f - t) * a.rgba[i + c] + t * b.rgba[i + c]) / 127.5f - 1.0f;
        const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (int c = 0; c < 3; ++c) {
            const float v = len > 1e-6f ? n[c] / len : (c == 2 ? 1.0f : 0.0f);
            out.pixels[i + c] = std::uint8_t(std::clamp(std::lround((v * 0.5f + 0.5f) * 255.0f), 0L, 255L));
        }
        out.pixels[i + 3] = std::uint8_t(std::lround((1.0f - t) * a.rgba[i + 3] + t * b.rgba[i + 3]));
    }
    return out;
}

morph::Layout key_layout(const Session& s, const render::WrinkleKey& key) {
    morph::Layout out;
    for (const auto& seg : expression::layout_segments(s.lines(), key.layout))
        out.push_back({seg.p.x, seg.p.y, seg.q.x, seg.q.y});
    return out;
}

void run_morph(const MorphArgs& a) {
    const int from = key_index(a.from, "--from");
    const int to = key_index(a.to, "--to");
    if (from == to) fail<InputError>("morph: --from and --to are both '{}': name two expressions", a.from);
    if (a.steps < 2 || a.steps > 16) fail<InputError>("morph: --steps {}: expected 2..16", a.steps);
    if (a.tile < 64 || a.tile > 1024) fail<InputError>("morph: --tile {}: expected 64..1024", a.tile);
    const SessionOptions so = a.session.resolve("morph", a.tile, a.tile);
    if (a.out.empty()) fail<InputError>("morph: --out sheet.png is required");
    split_output_path(a.out, "morph", "--out");
    render::check_image_output(a.out, "morph: --out " + a.out);
    OutputFile output(a.out, "morph");
    Session session(so);
    const int size = session.scene().wrinkle_texture().width();
    const render::WrinkleKey key_from = render::make_emotion_key(session.assets(), key_emotion(from), size);
    const render::WrinkleKey key_to = render::make_emotion_key(session.assets(), key_emotion(to), size);

    // The thesis's pipeline on two textures: [1] allocate, [2] upload, [3]
    // the kernel each frame, [4] free; a Morpher of its own so the stages are
    // those of the two-key morph alone.
    const morph::MorphParams params = session.scene().morph_params();
    std::vector<morph::KeyMap> maps(2);
    for (const auto& [map, key] : {std::pair{&maps[0], &key_from}, std::pair{&maps[1], &key_to}}) {
        map->pixels = key->map.rgba.data();
        map->layout = key_layout(session, *key);
        map->width = map->height = size;
    }
    auto morpher = std::make_unique<morph::Morpher>(size, size, morph::PixelFormat::Rgba8, std::move(maps), so.backend);
    const morph::SetupTimes setup = morpher->setup_times();

    auto shade = [&](const render::ImageRGBA8& m) {
        cv::Mat img = a.raw_map ? raw_normal_map(m) : shade_normal_map(m);
        if (img.cols != a.tile) cv::resize(img, img, cv::Size(a.tile, a.tile), 0, 0, cv::INTER_AREA);
        return img;
    };
    SheetRow bn{"Beier-Neely", {}, {}}, dissolve{"cross-dissolve", {}, {}};
    SheetRow bn_face{"face, Beier-Neely", {}, {}}, dissolve_face{"face, dissolve", {}, {}};
    std::vector<double> kernel_ms, bump_ms;
    render::ImageRGBA8 morphed(size, size);
    for (int i = 0; i < a.steps; ++i) {
        const double t = double(i) / double(a.steps - 1);
        const std::string caption = fmt::format("t = {:g}", t);
        const expression::FaceState state = session.face_state(transition_mix(from, to, t));

        // The face's layout at t (the target of the morph) and the face.
        session.update(state);
        const std::vector<float> weights = {float(1.0 - t), float(t)};
        auto k0 = Clock::now();
        morpher->morph_to_host(session.scene().target_layout(), weights, params, morphed.pixels.data());
        kernel_ms.push_back(ms_since(k0));
        bn.tiles.push_back(shade(morphed));
        bn.captions.push_back(caption);

        auto& platform = session.platform();
        // Figure 6.4 is drawn with the thesis's Blinn-Phong, bump-mapped with
        // row 1's map (the session's own keys are the AU keys).
        auto draw = session.draw_options(1.0f);
        draw.shading = render::Shading::Thesis;
        platform.make_current();
        session.scene().wrinkle_texture().upload(morphed.pixels.data());
        auto b0 = Clock::now();
        platform.begin_frame();
        session.draw(draw);
        platform.end_frame();
        bn_face.tiles.push_back(to_bgr(platform.read_rgba()));
        bump_ms.push_back(ms_since(b0));
        bn_face.captions.push_back(caption);

        const render::ImageRGBA8 blend = cross_dissolve(key_from.map, key_to.map, float(t));
        dissolve.tiles.push_back(shade(blend));
        dissolve.captions.push_back(caption);
        platform.make_current();
        session.scene().wrinkle_texture().upload(blend.pixels.data());
        platform.begin_frame();
        session.draw(draw);
        platform.end_frame();
        dissolve_face.tiles.push_back(to_bgr(platform.read_rgba()));
        dissolve_face.captions.push_back(caption);
    }
    const auto f0 = Clock::now();
    const morph::Backend used = morpher->backend();
    morpher.reset();
    const double free_ms = ms_since(f0);

    const std::string title = fmt::format("{} -> {}: wrinkle maps {}x{}, {} feature lines (thesis fig. 6.4)",
                                          a.from, a.to, size, size, session.lines().size());
    const cv::Mat sheet = contact_sheet(title, {bn, dissolve, bn_face, dissolve_face});
    write_bgr(output.path(), sheet);
    output.commit();

    const auto [kmin, kmax] = std::minmax_element(kernel_ms.begin(), kernel_ms.end());
    double bump = 0;
    for (double b : bump_ms) bump += b;
    bump /= double(bump_ms.size());
    fmt::print("morph: wrote {} ({}x{}: {} steps, rows Beier-Neely | cross-dissolve | face with each)\n", a.out,
               sheet.cols, sheet.rows, a.steps);
    fmt::print("morph: stage times, {} -> {}, {}x{} maps, {} lines, morph on {} (thesis table 6.1: GTX 480, "
               "256x256, 84 points)\n",
               a.from, a.to, size, size, session.lines().size(), morph::to_string(used));
    fmt::print("  [1] allocate               {:8.2f} ms   (thesis 11.67 ms)\n", setup.allocate_ms);
    fmt::print("  [2] upload (CPU -> device) {:8.2f} ms   (thesis 0.90 ms)\n", setup.upload_ms);
    fmt::print("  [3] kernel, per frame      {:8.2f} - {:.2f} ms   (thesis 31.81 - 32.05 ms)\n", *kmin, *kmax);
    fmt::print("  bump mapping (draw + read) {:8.2f} ms   (thesis 0.03 ms, draw only)\n", bump);
    fmt::print("  [4] free                   {:8.2f} ms\n", free_ms);
    fmt::print("  total ([1] + [2] + [3] + bump mapping) {:.2f} ms   (thesis 44.41 ms)\n",
               setup.allocate_ms + setup.upload_ms + *kmax + bump);
    fmt::print("morph: {}\n", session.description());
}

void add_morph_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "morph", "The thesis's figure 6.4: one expression's wrinkles morphing into another's at t = 0 .. 1 "
                 "(Beier-Neely next to a plain cross-dissolve), with the stage timings");
    auto a = std::make_shared<MorphArgs>();
    sub->add_option("--from", a->from, "Start expression (neutral, joy, sadness, anger, fear, disgust, surprise)")
        ->capture_default_str();
    sub->add_option("--to", a->to, "End expression")->capture_default_str();
    sub->add_option("--steps", a->steps, "Columns: t = 0, 1/(steps-1), .., 1 (2..16)")->capture_default_str();
    sub->add_option("-o,--out", a->out, "Output sheet (.png, ...); required");
    sub->add_option("--tile", a->tile, "Side of each picture on the sheet (64..1024)")->capture_default_str();
    sub->add_flag("--raw-map", a->raw_map, "Show the maps' encoded normals instead of lighting them");
    add_session_options(*sub, a->session);  // --wrinkle-size: 256 here, as in the thesis
    sub->callback([a] { run_morph(*a); });
}

}  // namespace

EMOFACE_COMMAND(add_morph_command)
