#include "golden.h"

#include <cstdlib>
#include <filesystem>

#include <fmt/format.h>

#include "emoface/common/error.h"
#include "emoface/render/image_diff.h"
#include "emoface/render/image_io.h"

namespace emoface::render::testing {

ImageRGBA8 downsample2x(const ImageRGBA8& image) {
    ImageRGBA8 out(image.width / 2, image.height / 2);
    for (int y = 0; y < out.height; ++y)
        for (int x = 0; x < out.width; ++x)
            for (int c = 0; c < 4; ++c) {
                const int sum = image.at(2 * x, 2 * y)[c] + image.at(2 * x + 1, 2 * y)[c] +
                                image.at(2 * x, 2 * y + 1)[c] + image.at(2 * x + 1, 2 * y + 1)[c];
                out.at(x, y)[c] = std::uint8_t((sum + 2) / 4);
            }
    return out;
}

GoldenResult compare_with_golden(const ImageRGBA8& actual, const std::string& golden_path,
                                 const Tolerance& tolerance, const std::string& failure_dir) {
    GoldenResult r;
    const char* update = std::getenv("EMOFACE_UPDATE_GOLDENS");
    if (update && std::string(update) == "1") {
        write_image(golden_path, actual);
        r.ok = r.updated = true;
        r.message = "updated " + golden_path;
        return r;
    }
    const std::string name = std::filesystem::path(golden_path).stem().string();
    std::filesystem::create_directories(failure_dir);
    const std::string actual_path = failure_dir + "/" + name + ".actual.png";
    const std::string diff_path = failure_dir + "/" + name + ".diff.png";

    ImageRGBA8 golden;
    try {
        golden = read_image_rgba8(golden_path);
    } catch (const Error& e) {
        write_image(actual_path, actual);
        r.message = fmt::format("no golden {} ({}); the render is in {} (run scripts/update-goldens)",
                                golden_path, e.what(), actual_path);
        return r;
    }
    if (golden.width != actual.width || golden.height != actual.height) {
        write_image(actual_path, actual);
        r.message = fmt::format("golden {} is {}x{}, the render {}x{} (in {})", golden_path,
                                golden.width, golden.height, actual.width, actual.height,
                                actual_path);
        return r;
    }
    const ImageDiff diff = diff_images(actual, golden);
    r.max_channel_diff = diff.max_channel_diff;
    r.mean_diff = diff.mean_diff;
    r.ok = r.max_channel_diff <= tolerance.max_channel_diff && r.mean_diff <= tolerance.mean_diff;
    if (!r.ok) {
        write_image(actual_path, actual);
        write_image(diff_path, diff.visual);
        r.message = fmt::format(
            "{}: max channel difference {} (allowed {}), mean {:.3f} (allowed {}); tolerance: "
            "{}; actual image {}, difference {}",
            golden_path, r.max_channel_diff, tolerance.max_channel_diff, r.mean_diff,
            tolerance.mean_diff, tolerance.reason, actual_path, diff_path);
    }
    return r;
}

}  // namespace emoface::render::testing
