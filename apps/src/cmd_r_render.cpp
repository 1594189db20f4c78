// emoface render: one still of the default face, headless, with its wrinkles.
//   emoface render --mix "0.7 anger + 0.3 fear" --out face.png
//   emoface render --fap anim.fap --frame 40 --out f40.png --side-by-side
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include "command.h"
#include "emoface/common/error.h"
#include "emoface/expression/emotion.h"
#include "emoface/expression/face_state.h"
#include "emoface/fap/fap_io.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/image_io.h"
#include "emoface/render/platform.h"

namespace {

using namespace emoface;

struct RenderArgs {
    std::string mix, fap, out, size = "512x512", backend = "auto", data = EMOFACE_DATA_DIR;
    long frame = 0;
    int map_size = 1024, samples = 4;
    double face_scale = 1.0;
    bool no_wrinkles = false, side_by_side = false, normalise = false;
};

std::pair<int, int> parse_size(const std::string& text) {
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') ||
        w < 16 || h < 16 || w > 8192 || h > 8192)
        fail<InputError>("render: --size '{}': expected WIDTHxHEIGHT, each 16..8192 (e.g. 1280x720)",
                         text);
    return {w, h};
}

morph::Backend parse_backend(const std::string& name) {
    if (name == "auto") return morph::Backend::Auto;
    if (name == "cpu") return morph::Backend::Cpu;
    if (name == "cuda") return morph::Backend::Cuda;
    fail<InputError>("render: --backend '{}': expected auto, cpu or cuda", name);
}

void run_render(const RenderArgs& a) {
    if (a.mix.empty() == a.fap.empty())
        fail<InputError>("render: give exactly one of --mix \"0.7 anger + 0.3 fear\" or --fap FILE");
    const auto [width, height] = parse_size(a.size);
    const morph::Backend backend = parse_backend(a.backend);
    if (!std::filesystem::is_directory(a.data + "/face"))
        fail<InputError>("render: --data {}: no face/ folder there (point it at the project's data/)",
                         a.data);
    // Check the output's folder before the slow part.
    const auto out_dir = std::filesystem::path(a.out).parent_path();
    if (!out_dir.empty() && !std::filesystem::is_directory(out_dir))
        fail<InputError>("render: --out {}: folder {} does not exist", a.out, out_dir.string());

    // The frame's state first: bad input fails before the face is built.
    expression::EmotionMix mix;
    std::unique_ptr<fap::FapStream> stream;
    if (!a.mix.empty()) {
        mix = expression::parse_emotion_mix(a.mix, a.normalise);
    } else {
        stream = std::make_unique<fap::FapStream>(fap::read_fap_file(a.fap));
        if (stream->frames.empty()) fail<InputError>("render: {}: the file has no frames", a.fap);
        if (a.frame < 0 || std::size_t(a.frame) >= stream->frames.size())
            fail<InputError>("render: --frame {}: {} has frames 0..{}", a.frame, a.fap,
                             stream->frames.size() - 1);
    }

    render::FaceAssetsOptions ao;
    ao.wrinkle_map_size = a.map_size;
    ao.face.resolution_scale = a.face_scale;
    const auto assets = render::load_default_face_assets(a.data, ao);
    const expression::FaceState state =
        stream ? expression::face_state(stream->resolved(std::size_t(a.frame)), assets->emotions,
                                        &assets->visemes)
               : expression::face_state(mix, assets->emotions);

    render::PlatformOptions po;
    po.width = a.side_by_side ? 2 * width : width;
    po.height = height;
    po.samples = a.samples;
    po.cuda_device = 0;
    render::HeadlessPlatform platform(po);
    spdlog::debug("render: {}", platform.description());
    render::FaceSceneOptions so;
    so.backend = backend;
    const auto scene = render::make_face_scene(platform, *assets, so);
    scene->update(state.faps, render::key_weights(state.mix));

    render::DrawOptions d;
    d.camera = scene->frontal_camera(float(width) / float(height));
    d.light = scene->portrait_light();
    platform.begin_frame();
    if (a.side_by_side) {
        d.viewport = {0, 0, width, height};
        scene->draw(d);  // left: with the wrinkle map
        d.viewport = {width, 0, width, height};
        d.wrinkles = false;
        scene->draw(d);  // right: without
    } else {
        d.wrinkles = !a.no_wrinkles;
        scene->draw(d);
    }
    platform.end_frame();
    render::write_image(a.out, platform.read_rgba());
    std::printf("render: wrote %s (%dx%d, %s, mix %s, morph on %s%s)\n", a.out.c_str(),
                po.width, po.height,
                a.side_by_side ? "with | without wrinkles"
                               : (a.no_wrinkles ? "without wrinkles" : "with wrinkles"),
                state.mix.to_string().c_str(), morph::to_string(scene->morpher().backend()),
                scene->uses_interop() ? ", CUDA-GL interop" : "");
}

void add_render_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "render", "Render one still of the default face (headless): an emotion mix or a FAP frame");
    auto args = std::make_shared<RenderArgs>();
    sub->add_option("--mix", args->mix, "Emotion mix, e.g. \"0.7 anger + 0.3 fear\"");
    sub->add_flag("--normalise", args->normalise, "Scale a mix summing over 1 down to 1");
    sub->add_option("--fap", args->fap, "FAP file to take a frame from");
    sub->add_option("--frame", args->frame, "Frame of --fap (0-based)");
    sub->add_option("--out", args->out, "Output image (.png, .exr, .jpg, ...)")->required();
    sub->add_option("--size", args->size, "Image size WIDTHxHEIGHT")->capture_default_str();
    sub->add_option("--map-size", args->map_size, "Wrinkle map side (256..4096)")
        ->capture_default_str();
    sub->add_option("--samples", args->samples, "Multisampling samples")
        ->check(CLI::Range(1, 16))
        ->capture_default_str();
    sub->add_option("--backend", args->backend, "Morph backend: auto, cpu or cuda")
        ->capture_default_str();
    sub->add_option("--face-scale", args->face_scale, "Mesh resolution of the default face")
        ->check(CLI::Range(0.1, 2.0))
        ->capture_default_str();
    sub->add_flag("--no-wrinkles", args->no_wrinkles, "Draw without the wrinkle map");
    sub->add_flag("--side-by-side", args->side_by_side,
                  "Two pictures: with the wrinkle map (left) and without (right)");
    sub->add_option("--data", args->data, "The project's data folder")->capture_default_str();
    sub->callback([args] { run_render(*args); });
}

}  // namespace

EMOFACE_COMMAND(add_render_command)
