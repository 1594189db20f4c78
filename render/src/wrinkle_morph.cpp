#include "emoface/render/wrinkle_morph.h"

#include "emoface/common/error.h"

namespace emoface::render {

namespace {
TexelFormat texel_format_of(morph::PixelFormat f) {
    return f == morph::PixelFormat::Rgba8 ? TexelFormat::RGBA8 : TexelFormat::RGBA32F;
}
const char* name(TexelFormat f) { return f == TexelFormat::RGBA8 ? "RGBA8" : "RGBA32F"; }
}  // namespace

WrinkleMorph::WrinkleMorph(morph::Morpher& morpher, WrinkleTexture& texture)
    : morpher_(morpher), texture_(texture), interop_(morpher.backend() == morph::Backend::Cuda) {
    if (morpher.width() != texture.width() || morpher.height() != texture.height())
        fail("render: WrinkleMorph: the morph is {}x{}, the texture {}x{}", morpher.width(),
             morpher.height(), texture.width(), texture.height());
    if (texel_format_of(morpher.format()) != texture.format())
        fail("render: WrinkleMorph: the morph makes {} pixels, the texture holds {}",
             morph::to_string(morpher.format()), name(texture.format()));
    if (interop_)
        texture_.register_cuda();
    else
        host_.resize(std::size_t(morpher.width()) * morpher.height() * morpher.pixel_bytes());
}

void WrinkleMorph::update(const morph::Layout& target, const std::vector<float>& weights,
                          const morph::MorphParams& params) {
    if (interop_) {
        void* stream = morpher_.cuda_stream();
        MappedWrinkleSurface surface(texture_, stream);
        morpher_.morph_to_surface(target, weights, params, surface.surface());
        return;  // unmapping on the morph's stream orders GL after the kernel
    }
    morpher_.morph_to_host(target, weights, params, host_.data());
    texture_.upload(host_.data());
}

}  // namespace emoface::render
