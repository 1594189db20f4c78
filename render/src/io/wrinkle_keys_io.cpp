#include "emoface/render/wrinkle_keys_io.h"

#include <algorithm>
#include <filesystem>

#include "emoface/common/error.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/image_io.h"

namespace emoface::render {

namespace {

// The box of the pixels that are not flat skin; the whole map has none.
expression::WrinkleRegion painted_region(const expression::NormalMap& map) {
    int x0 = map.width, y0 = map.height, x1 = -1, y1 = -1;
    for (int y = 0; y < map.height; ++y)
        for (int x = 0; x < map.width; ++x) {
            const std::uint8_t* p = &map.rgba[(std::size_t(y) * map.width + x) * 4];
            if (p[0] == 128 && p[1] == 128 && p[2] == 255 && p[3] == 255) continue;
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
    if (x1 < 0) return {glm::vec2(0.0f), glm::vec2(0.0f)};
    return {{float(x0) / map.width, float(y0) / map.height}, {float(x1 + 1) / map.width, float(y1 + 1) / map.height}};
}

}  // namespace

void write_wrinkle_keys(const std::string& folder, const std::vector<WrinkleKey>& keys) {
    namespace fs = std::filesystem;
    for (const WrinkleKey& key : keys) {
        const std::string stem = (fs::path(folder) / key.name).string();
        ImageRGBA8 image(key.map.width, key.map.height);
        image.pixels = key.map.rgba;
        write_image(stem + ".png", image);
        expression::save_layout(key.layout, stem + ".layout.json");
    }
}

std::vector<WrinkleKey> read_wrinkle_keys(const std::string& folder,
                                          const std::vector<expression::FeatureLine>& lines) {
    namespace fs = std::filesystem;
    if (!fs::is_directory(folder))
        fail<InputError>("render: {}: expected a folder of wrinkle maps (as `emoface wrinkles` writes), found none",
                         folder);
    std::vector<std::string> names;
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
        const fs::path path = entry.path();
        if (path.extension() != ".png") continue;
        const std::string name = path.stem().string();
        if (!key_driver(name))
            fail<InputError>("render: {}: expected a key map named neutral, an emotion (joy, ...) or an AU term "
                             "(AU6L, AU17), found '{}'",
                             path.string(), name);
        names.push_back(name);
    }
    // A layout whose map is gone is a key the artist lost, not one to skip:
    // playing without it would silently drop that key's wrinkles.
    for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
        const std::string file = entry.path().filename().string();
        const std::string suffix = ".layout.json";
        if (file.size() <= suffix.size() || file.compare(file.size() - suffix.size(), suffix.size(), suffix) != 0)
            continue;
        const std::string name = file.substr(0, file.size() - suffix.size());
        if (std::find(names.begin(), names.end(), name) == names.end())
            fail<InputError>("render: {}.png: missing wrinkle map (its layout {} is there)",
                             (fs::path(folder) / name).string(), file);
    }
    if (std::find(names.begin(), names.end(), "neutral") == names.end())
        fail<InputError>("render: {}.png: missing wrinkle map", (fs::path(folder) / "neutral").string());
    std::sort(names.begin(), names.end(), [](const std::string& a, const std::string& b) {
        return (a == "neutral") != (b == "neutral") ? a == "neutral" : a < b;
    });
    std::vector<WrinkleKey> keys;
    for (const std::string& name : names) {
        WrinkleKey key;
        key.name = name;
        const std::string stem = (fs::path(folder) / key.name).string();
        if (!fs::exists(stem + ".layout.json"))
            fail<InputError>("render: {}.layout.json: missing layout of {}.png", stem, key.name);
        const ImageRGBA8 image = read_image_rgba8(stem + ".png");
        if (image.width != image.height || image.width < 256 || image.width > 4096)
            fail<InputError>("render: {}.png: expected a square map of 256..4096 pixels, found {}x{}", stem,
                             image.width, image.height);
        if (!keys.empty() && image.width != keys.front().map.width)
            fail<InputError>("render: {}.png: {}x{}, expected the size of {}.png ({}x{})", stem, image.width,
                             image.height, keys.front().name, keys.front().map.width, keys.front().map.height);
        key.map.width = image.width;
        key.map.height = image.height;
        key.map.rgba = image.pixels;
        key.layout = expression::load_layout(stem + ".layout.json");
        for (const expression::FeatureLine& line : lines)
            for (int point : {line.from, line.to})
                if (!key.layout.present[point])
                    fail<InputError>("render: {}.layout.json: lacks feature point {}, which the morph's lines use",
                                     stem, fap::feature_points()[point].id);
        // The neutral key is the whole map (the skin under every frame).
        if (name != "neutral") key.region = painted_region(key.map);
        keys.push_back(std::move(key));
    }
    return keys;
}

}  // namespace emoface::render
