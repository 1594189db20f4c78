// emoface wrinkles: writes the key wrinkle maps (neutral + one per wrinkling
// AU and side, named as key_weights reads them: AU6L, AU17, ...) and the
// feature layout each was made at, so an artist can replace any map with a
// painted one plus its layout (or write emotion keys: joy.png, ...).
#include <chrono>
#include <cstdio>
#include <filesystem>

#include "command.h"
#include "emoface/common/error.h"
#include "emoface/common/output_batch.h"
#include "emoface/expression/feature_layout.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/wrinkle_keys_io.h"
#include "session.h"

namespace emoface::apps {
namespace {

struct WrinklesArgs {
    std::string out;
    int size = 1024;
    std::string face = "default";
    std::string fdp;
    std::string data = EMOFACE_DATA_DIR;
    std::string layout = "projective";
};

void run_wrinkles(const WrinklesArgs& args) {
    render::check_wrinkle_map_size(args.size, "wrinkles: --size");
    namespace fs = std::filesystem;
    std::error_code ec;
    if (fs::exists(args.out, ec) && !fs::is_directory(args.out, ec))
        fail<InputError>("wrinkles: --out {}: expected a folder, found a file", args.out);
    const fs::path parent = fs::absolute(args.out).parent_path();
    if (!fs::is_directory(parent, ec))
        fail<InputError>("wrinkles: --out {}: folder {} does not exist", args.out, parent.string());
    // The maps and layouts appear together or not at all; the folder is made
    // (and proved writable) now, before the slow part.
    OutputBatch batch(args.out, "wrinkles: --out " + args.out);

    const auto layout = render::parse_wrinkle_layout(args.layout);
    if (!layout) fail<InputError>("wrinkles: --layout '{}': expected projective or anchored", args.layout);

    const auto start = std::chrono::steady_clock::now();
    SessionOptions face_options;
    face_options.face = args.face;
    face_options.fdp = args.fdp;
    face_options.data = args.data;
    render::FaceAssetsOptions asset_options;
    asset_options.wrinkle_map_size = args.size;
    asset_options.layout = *layout;
    const auto assets = render::load_face_assets(load_session_face(face_options), args.data, asset_options);

    std::string staging;
    for (const render::WrinkleKey& key : assets->keys) {
        staging = fs::path(batch.stage(key.name + ".png")).parent_path().string();
        batch.stage(key.name + ".layout.json");
    }
    render::write_wrinkle_keys(staging, assets->keys);
    batch.commit();
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("wrinkles: %zu maps of %dx%d and their layouts in %s (%.1f s)\n", assets->keys.size(),
                args.size, args.size, args.out.c_str(), seconds);
    for (const render::WrinkleKey& key : assets->keys)
        std::printf("  %s.png  %s.layout.json\n", key.name.c_str(), key.name.c_str());
}

void add_wrinkles_command(CLI::App& root) {
    auto args = std::make_shared<WrinklesArgs>();
    CLI::App* sub = root.add_subcommand(
        "wrinkles",
        "Write the key wrinkle maps (neutral + one per wrinkling Action Unit and side: AU1L, AU1R, ..., AU17;\n"
        "tangent-space normal maps, PNG) and the feature layout of each (JSON). Replace any map with a painted\n"
        "one plus its layout; a folder of emotion keys (neutral, joy, ..., surprise) works too.");
    sub->add_option("--out", args->out, "Output folder (created if missing; its parent must exist)")
        ->required();
    sub->add_option("--size", args->size, "Side of the square maps, 256..4096")->capture_default_str();
    sub->add_option("--face", args->face, "default, FILE.wfm (Candide-3) or FILE.obj")
        ->capture_default_str();
    sub->add_option("--fdp", args->fdp, "Feature points of an OBJ face (default: FILE.fdp.json)");
    sub->add_option("--data", args->data, "The project's data folder")->capture_default_str();
    sub->add_option("--layout", args->layout,
                    "Texture space of the maps: projective, or anchored (the face's own UVs: paint in UV space)")
        ->capture_default_str();
    sub->callback([args] { run_wrinkles(*args); });
}

}  // namespace

EMOFACE_COMMAND(add_wrinkles_command)

}  // namespace emoface::apps
