#include "emoface/render/wrinkle_keys_io.h"

#include <filesystem>

#include "emoface/common/error.h"
#include "emoface/render/image_io.h"

namespace emoface::render {

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
    std::vector<WrinkleKey> keys;
    for (int k = 0; k < expression::kWrinkleKeyCount; ++k) {
        WrinkleKey key;
        key.name = expression::wrinkle_key_name(static_cast<expression::WrinkleKey>(k));
        const std::string stem = (fs::path(folder) / key.name).string();
        if (!fs::exists(stem + ".png")) fail<InputError>("render: {}.png: missing wrinkle map", stem);
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
        keys.push_back(std::move(key));
    }
    return keys;
}

}  // namespace emoface::render
