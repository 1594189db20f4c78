#include "emoface/render/image_io.h"

#include <OpenImageIO/imageio.h>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <filesystem>
#include <optional>
#include <vector>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/common/input_file.h"
#include "emoface/common/output_batch.h"

namespace emoface::render {
namespace {

template <typename Image>
void check_image(const std::string& path, const Image& image) {
    if (image.width <= 0 || image.height <= 0 ||
        image.pixels.size() != std::size_t(image.width) * image.height * 4)
        fail("render: {}: cannot write a {}x{} image holding {} values (expected width*height*4)",
             OutputBatch::shown_path(path), image.width, image.height, image.pixels.size());
}

std::string extension_of(const std::string& path) {
    const std::string ext = std::filesystem::path(path).extension().string();
    return ext.empty() ? "none" : "'" + ext + "'";
}

void write_pixels(const std::string& path, int width, int height, OIIO::TypeDesc in_type,
                  OIIO::TypeDesc file_type, const void* pixels) {
    const std::string shown = OutputBatch::shown_path(path);
    const std::string temp = temporary_path_for(path);
    auto out = OIIO::ImageOutput::create(path);  // format from the real name
    OIIO::geterror();  // OpenImageIO keeps its messages per thread: ours are one line
    if (!out)
        fail<InputError>("render: {}: expected an image name OpenImageIO writes (.png, .jpg, .tif, .exr, ...), "
                         "found extension {}",
                         shown, extension_of(path));
    // Formats without alpha (JPEG, PNM, ...) get the colour channels: the
    // pixels are RGBA, every fourth value skipped.
    const int channels = out->supports("alpha") ? 4 : 3;
    OIIO::ImageSpec spec(width, height, channels, file_type);
    // Our pixels are straight (unassociated) alpha, written as they are.
    spec.attribute("oiio:UnassociatedAlpha", 1);
    if (!out->open(temp, spec)) {
        const std::string why = out->geterror();
        discard_temporary(temp);
        fail<InputError>("render: {}: cannot write it: {}", shown, why);
    }
    const OIIO::stride_t pixel_bytes = OIIO::stride_t(4 * in_type.size());
    const bool wrote = out->write_image(in_type, pixels, pixel_bytes);
    const bool closed = out->close();
    if (!wrote || !closed) {
        const std::string why = out->geterror();
        out.reset();
        discard_temporary(temp);
        fail<InputError>("render: {}: writing failed: {}", shown, why);
    }
    out.reset();
    commit_temporary(temp, path, "render");
}

// OpenImageIO's messages may span lines (libpng's, then its own): the first
// one, cut, is the reason.
std::string first_line(const std::string& text) { return echo_input(text.substr(0, text.find('\n')), 120); }

// A PNG whose chunks run past the end of the file (a truncated download, a
// copy cut short). Checked before libpng sees it: libpng prints its own
// "libpng error: ..." lines to stderr for it, beside our one line.
std::string png_truncation(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    char signature[8];
    if (!in.read(signature, 8) || std::memcmp(signature, "\x89PNG\r\n\x1a\n", 8) != 0) return "";
    in.seekg(0, std::ios::end);
    const std::uint64_t size = static_cast<std::uint64_t>(in.tellg());
    std::uint64_t at = 8;
    while (at + 8 <= size) {
        unsigned char head[8];
        in.seekg(static_cast<std::streamoff>(at));
        if (!in.read(reinterpret_cast<char*>(head), 8)) break;
        const std::uint64_t length = (std::uint64_t(head[0]) << 24) | (head[1] << 16) | (head[2] << 8) | head[3];
        at += 12 + length;  // length, type, data, CRC
        if (std::memcmp(head + 4, "IEND", 4) == 0) return at <= size ? "" : "a PNG cut short in its IEND chunk";
    }
    return fmt::format("a PNG cut short after {} bytes (no IEND chunk)", size);
}

// libpng reports a corrupt file by printing "libpng error: ..." to stderr
// itself, then OpenImageIO hands the same reason to geterror(): stderr is
// pointed at /dev/null while an image is decoded, so only our line remains.
class QuietStderr {
public:
    QuietStderr() {
        std::fflush(stderr);
        saved_ = ::dup(2);
        const int null = ::open("/dev/null", O_WRONLY | O_CLOEXEC);
        if (saved_ >= 0 && null >= 0) ::dup2(null, 2);
        if (null >= 0) ::close(null);
    }
    ~QuietStderr() {
        std::fflush(stderr);
        if (saved_ >= 0) {
            ::dup2(saved_, 2);
            ::close(saved_);
        }
    }
    QuietStderr(const QuietStderr&) = delete;
    QuietStderr& operator=(const QuietStderr&) = delete;

private:
    int saved_ = -1;
};

template <typename T>
std::vector<T> read_rgba(const std::string& path, OIIO::TypeDesc type, int& width, int& height) {
    check_input_file(path, kMaxImageFileBytes, "render");
    if (const std::string cut = png_truncation(path); !cut.empty())
        fail_data("render", FileLoc{path, 0, ""}, "a whole image file", cut);
    // Keep straight alpha as stored (OpenImageIO would premultiply it).
    OIIO::ImageSpec config;
    config.attribute("oiio:UnassociatedAlpha", 1);
    std::optional<QuietStderr> quiet(std::in_place);
    auto in = OIIO::ImageInput::open(path, &config);
    if (!in) fail<InputError>("render: {}: cannot read the image: {}", path, first_line(OIIO::geterror()));
    const OIIO::ImageSpec& spec = in->spec();
    width = spec.width;
    height = spec.height;
    const int channels = spec.nchannels;
    if (width <= 0 || height <= 0 || channels <= 0 || std::int64_t(width) * height > (1 << 28))
        fail<InputError>("render: {}: unsupported image size {}x{} with {} channels", path,
                         width, height, channels);
    std::vector<T> raw(std::size_t(width) * height * channels);
    const bool read = in->read_image(0, 0, 0, channels, type, raw.data());
    quiet.reset();
    if (!read)
        fail<InputError>("render: {}: cannot read the pixels: {}", path, first_line(in->geterror()));
    in->close();
    const T one = type == OIIO::TypeDesc::UINT8 ? T(255) : T(1);
    std::vector<T> rgba(std::size_t(width) * height * 4);
    for (std::size_t i = 0, n = std::size_t(width) * height; i < n; ++i) {
        const T* s = raw.data() + i * channels;
        T* d = rgba.data() + i * 4;
        if (channels >= 3) {
            d[0] = s[0]; d[1] = s[1]; d[2] = s[2];
            d[3] = channels >= 4 ? s[3] : one;
        } else {  // grey, grey + alpha
            d[0] = d[1] = d[2] = s[0];
            d[3] = channels == 2 ? s[1] : one;
        }
    }
    return rgba;
}

}  // namespace

void write_image(const std::string& path, const ImageRGBA8& image) {
    check_image(path, image);
    write_pixels(path, image.width, image.height, OIIO::TypeDesc::UINT8, OIIO::TypeDesc::UINT8,
                 image.pixels.data());
}

void write_image(const std::string& path, const ImageRGBA32F& image) {
    check_image(path, image);
    write_pixels(path, image.width, image.height, OIIO::TypeDesc::FLOAT, OIIO::TypeDesc::HALF,
                 image.pixels.data());
}

void check_image_output(const std::string& path, const std::string& what) {
    auto out = OIIO::ImageOutput::create(path);
    OIIO::geterror();
    if (!out)
        fail<InputError>("{}: expected an image name OpenImageIO writes (.png, .jpg, .tif, .exr, ...), found "
                         "extension {}",
                         what, extension_of(path));
}

ImageRGBA8 read_image_rgba8(const std::string& path) {
    ImageRGBA8 image;
    image.pixels = read_rgba<std::uint8_t>(path, OIIO::TypeDesc::UINT8, image.width, image.height);
    return image;
}

ImageRGBA32F read_image_rgba32f(const std::string& path) {
    ImageRGBA32F image;
    image.pixels = read_rgba<float>(path, OIIO::TypeDesc::FLOAT, image.width, image.height);
    return image;
}

}  // namespace emoface::render
