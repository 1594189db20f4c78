#pragma once
// Still images through OpenImageIO (target emoface::render_io). Every writer
// writes to a temporary file in the destination's folder and renames it into
// place, so a failure never leaves a partial file behind.
#include <string>

#include "emoface/render/image.h"

namespace emoface::render {

// Writes an 8-bit RGBA image; the format follows the extension (.png, .jpg,
// .tif, ...). Throws emoface::Error naming the path on failure.
void write_image(const std::string& path, const ImageRGBA8& image);
// Writes a float RGBA image (.exr: half float, linear; other formats as the
// extension allows).
void write_image(const std::string& path, const ImageRGBA32F& image);

// Throws emoface::InputError "<what>: expected an image name OpenImageIO
// writes ..., found extension '.xyz'" unless an image can be written at
// `path`: the check a command makes before any slow work. Formats without
// alpha (.jpg, .ppm, ...) are written as RGB.
void check_image_output(const std::string& path, const std::string& what);

// Reads any image OpenImageIO knows as RGBA (missing channels: alpha 1, grey
// replicated). Throws emoface::InputError naming the path on failure.
ImageRGBA8 read_image_rgba8(const std::string& path);
ImageRGBA32F read_image_rgba32f(const std::string& path);

}  // namespace emoface::render
