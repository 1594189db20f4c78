// CUDA-GL interop in a build without CUDA: every GPU entry point says so.
#include "emoface/render/wrinkle_texture.h"

#include "emoface/common/error.h"

namespace emoface::render {

bool cuda_interop_available() { return false; }

void WrinkleTexture::register_cuda() {
    fail<EnvironmentError>("render: CUDA-GL interop: this build has no CUDA (nvcc was not found)");
}

unsigned long long WrinkleTexture::map_surface(void*) {
    register_cuda();
    return 0;
}

void WrinkleTexture::unmap(void*) {}

unsigned long long WrinkleTexture::map_surface(void*, const std::vector<void*>&) {
    register_cuda();
    return 0;
}

void WrinkleTexture::unmap(void*, const std::vector<void*>&) {}

void WrinkleTexture::unregister_cuda() noexcept {}

}  // namespace emoface::render

#include "emoface/render/face_geometry.h"

namespace emoface::render {

GlBufferInterop::GlBufferInterop(const std::vector<unsigned>&) {
    fail<EnvironmentError>("render: CUDA-GL interop: this build has no CUDA (nvcc was not found)");
}
GlBufferInterop::~GlBufferInterop() = default;
std::vector<float*> GlBufferInterop::map(void*) { return {}; }
void GlBufferInterop::unmap(void*) {}
std::vector<float*> GlBufferInterop::pointers() const { return {}; }

}  // namespace emoface::render
