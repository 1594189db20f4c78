#include "emoface/render/wrinkle_texture.h"

#include "emoface/common/error.h"

#include <cstdint>
#include <vector>

#include "gl_util.h"

namespace emoface::render {

std::size_t texel_bytes(TexelFormat format) {
    return format == TexelFormat::RGBA8 ? 4 : 16;
}

namespace {

struct GlFormat {
    GLenum internal, type;
};
GlFormat gl_format(TexelFormat f) {
    return f == TexelFormat::RGBA8 ? GlFormat{GL_RGBA8, GL_UNSIGNED_BYTE}
                                   : GlFormat{GL_RGBA32F, GL_FLOAT};
}

}  // namespace

WrinkleTexture::WrinkleTexture(int width, int height, TexelFormat format,
                               NormalEncoding encoding)
    : width_(width), height_(height), format_(format), encoding_(encoding) {
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (width <= 0 || height <= 0 || width > max_size || height > max_size)
        fail("render: WrinkleTexture: size must be in 1..{} (GL_MAX_TEXTURE_SIZE), got {}x{}",
             max_size, width, height);
    if (format == TexelFormat::RGBA8 && encoding == NormalEncoding::Signed)
        fail("render: WrinkleTexture: an RGBA8 map cannot hold signed normals");

    // The flat normal (0, 0, 1), so an unwritten map leaves the surface smooth.
    const std::size_t n = std::size_t(width) * height;
    std::vector<std::uint8_t> init(n * texel_bytes(format));
    if (format == TexelFormat::RGBA8) {
        for (std::size_t i = 0; i < n; ++i) {
            init[4 * i + 0] = 128; init[4 * i + 1] = 128;
            init[4 * i + 2] = 255; init[4 * i + 3] = 255;
        }
    } else {
        auto* f = reinterpret_cast<float*>(init.data());
        const bool u = encoding == NormalEncoding::Unsigned;
        for (std::size_t i = 0; i < n; ++i) {
            f[4 * i + 0] = u ? 0.5f : 0.0f; f[4 * i + 1] = u ? 0.5f : 0.0f;
            f[4 * i + 2] = 1.0f; f[4 * i + 3] = 1.0f;
        }
    }
    const GlFormat gf = gl_format(format);
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTexImage2D(GL_TEXTURE_2D, 0, GLint(gf.internal), width, height, 0, GL_RGBA, gf.type,
                 init.data());
    // No mipmaps: the map changes every frame and a face seldom shrinks
    // below the map's resolution by more than 2x.
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAX_LEVEL, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    detail::check_gl("WrinkleTexture: creating the texture");
}

WrinkleTexture::~WrinkleTexture() {
    unregister_cuda();
    if (texture_) glDeleteTextures(1, &texture_);
}

void WrinkleTexture::upload(const void* pixels, std::size_t row_bytes) {
    if (!pixels) fail("render: WrinkleTexture::upload(): no pixels");
    if (mapped()) fail("render: WrinkleTexture::upload(): the texture is mapped for CUDA");
    const std::size_t texel = texel_bytes(format_);
    const std::size_t tight = texel * std::size_t(width_);
    if (row_bytes == 0) row_bytes = tight;
    if (row_bytes < tight || row_bytes % texel != 0)
        fail("render: WrinkleTexture::upload(): row pitch {} bytes, expected a multiple of {} "
             "that is at least {}",
             row_bytes, texel, tight);
    const GlFormat gf = gl_format(format_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, GLint(row_bytes / texel));
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGBA, gf.type, pixels);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glBindTexture(GL_TEXTURE_2D, 0);
    detail::check_gl("WrinkleTexture::upload()");
}

void WrinkleTexture::download(void* pixels) const {
    if (mapped()) fail("render: WrinkleTexture::download(): the texture is mapped for CUDA");
    glBindTexture(GL_TEXTURE_2D, texture_);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glGetTexImage(GL_TEXTURE_2D, 0, GL_RGBA, gl_format(format_).type, pixels);
    glBindTexture(GL_TEXTURE_2D, 0);
    detail::check_gl("WrinkleTexture::download()");
}

}  // namespace emoface::render
