#pragma once
// The morph's output into the wrinkle texture, each frame (thesis 5.4):
//   CUDA backend: map the texture (registered once), morph into its surface
//                 on the morph's stream, unmap on that stream: no host copy;
//   CPU backend:  morph into a host buffer kept here, upload it.
#include <cstdint>
#include <vector>

#include "emoface/morph/morph.h"
#include "emoface/render/wrinkle_texture.h"

namespace emoface::render {

class WrinkleMorph {
public:
    // The texture must have the morpher's size and a matching texel format
    // (Rgba8 <-> RGBA8, RgbaF32 <-> RGBA32F); throws emoface::Error otherwise.
    // On the CUDA backend the texture is registered with CUDA here.
    WrinkleMorph(morph::Morpher& morpher, WrinkleTexture& texture);

    // Morphs the keys onto `target` with `weights` into the texture. On the
    // CUDA backend this returns once the work is queued; GL commands issued
    // afterwards see the finished texture.
    void update(const morph::Layout& target, const std::vector<float>& weights,
                const morph::MorphParams& params);

    bool uses_interop() const { return interop_; }

private:
    morph::Morpher& morpher_;
    WrinkleTexture& texture_;
    bool interop_;
    std::vector<std::uint8_t> host_;
};

}  // namespace emoface::render
