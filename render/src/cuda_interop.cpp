// CUDA-GL interop (thesis 5.4): the wrinkle texture is registered with CUDA
// once; each frame it is mapped, written through a surface object, unmapped.
#include <epoxy/gl.h>  // before cuda_gl_interop.h, which includes GL/gl.h

#include <cuda_gl_interop.h>
#include <cuda_runtime.h>

#include "emoface/render/wrinkle_texture.h"

#include "emoface/common/error.h"

namespace emoface::render {
namespace {

void check_cuda(cudaError_t e, const char* what) {
    if (e != cudaSuccess)
        fail<InternalError>("render: CUDA-GL interop: {}: {} ({})", what, cudaGetErrorName(e),
                            cudaGetErrorString(e));
}

}  // namespace

bool cuda_interop_available() {
    int count = 0;
    if (cudaGetDeviceCount(&count) != cudaSuccess) {
        cudaGetLastError();  // clear the sticky "no device" error
        return false;
    }
    return count > 0;
}

void WrinkleTexture::register_cuda() {
    if (cuda_resource_) return;
    if (!cuda_interop_available())
        fail<EnvironmentError>("render: CUDA-GL interop: no CUDA device");
    cudaGraphicsResource_t resource = nullptr;
    check_cuda(cudaGraphicsGLRegisterImage(&resource, texture_, GL_TEXTURE_2D,
                                           cudaGraphicsRegisterFlagsSurfaceLoadStore),
               "cudaGraphicsGLRegisterImage (is the GL context on the CUDA device?)");
    cuda_resource_ = resource;
}

unsigned long long WrinkleTexture::map_surface(void* stream) { return map_surface(stream, {}); }

unsigned long long WrinkleTexture::map_surface(void* stream, const std::vector<void*>& others) {
    if (surface_) fail("render: WrinkleTexture::map_surface(): already mapped");
    register_cuda();
    auto* resource = static_cast<cudaGraphicsResource_t>(cuda_resource_);
    std::vector<cudaGraphicsResource_t> all{resource};
    for (void* r : others) all.push_back(static_cast<cudaGraphicsResource_t>(r));
    auto s = static_cast<cudaStream_t>(stream);
    check_cuda(cudaGraphicsMapResources(int(all.size()), all.data(), s), "cudaGraphicsMapResources");
    cudaArray_t array = nullptr;
    // The array may differ from one mapping to the next (CUDA's documentation),
    // so the surface object is made per mapping; it costs a few microseconds.
    cudaError_t e = cudaGraphicsSubResourceGetMappedArray(&array, resource, 0, 0);
    cudaSurfaceObject_t surface = 0;
    if (e == cudaSuccess) {
        cudaResourceDesc desc{};
        desc.resType = cudaResourceTypeArray;
        desc.res.array.array = array;
        e = cudaCreateSurfaceObject(&surface, &desc);
    }
    if (e != cudaSuccess) {
        cudaGraphicsUnmapResources(int(all.size()), all.data(), s);
        check_cuda(e, "getting a surface for the mapped texture");
    }
    surface_ = surface;
    return surface_;
}

void WrinkleTexture::unmap(void* stream) { unmap(stream, {}); }

void WrinkleTexture::unmap(void* stream, const std::vector<void*>& others) {
    if (!surface_) return;
    std::vector<cudaGraphicsResource_t> all{static_cast<cudaGraphicsResource_t>(cuda_resource_)};
    for (void* r : others) all.push_back(static_cast<cudaGraphicsResource_t>(r));
    cudaDestroySurfaceObject(static_cast<cudaSurfaceObject_t>(surface_));
    surface_ = 0;
    check_cuda(cudaGraphicsUnmapResources(int(all.size()), all.data(), static_cast<cudaStream_t>(stream)),
               "cudaGraphicsUnmapResources");
}

void WrinkleTexture::unregister_cuda() noexcept {
    if (!cuda_resource_) return;
    try {
        unmap(nullptr);
    } catch (...) {
    }
    cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(cuda_resource_));
    cuda_resource_ = nullptr;
}

}  // namespace emoface::render

// GL vertex buffers written by CUDA kernels (face_geometry.h): registered
// once, write-discard (the kernels rewrite every vertex each frame), mapped
// all in one call per frame.
#include "emoface/render/face_geometry.h"

namespace emoface::render {

GlBufferInterop::GlBufferInterop(const std::vector<unsigned>& gl_buffers) {
    if (!cuda_interop_available()) fail<EnvironmentError>("render: CUDA-GL interop: no CUDA device");
    for (unsigned b : gl_buffers) {
        cudaGraphicsResource_t r = nullptr;
        const cudaError_t e = cudaGraphicsGLRegisterBuffer(&r, b, cudaGraphicsRegisterFlagsWriteDiscard);
        if (e != cudaSuccess) {
            for (void* done : resources_) cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(done));
            check_cuda(e, "cudaGraphicsGLRegisterBuffer (is the GL context on the CUDA device?)");
        }
        resources_.push_back(r);
    }
}

GlBufferInterop::~GlBufferInterop() {
    try {
        unmap(nullptr);
    } catch (...) {
    }
    for (void* r : resources_) cudaGraphicsUnregisterResource(static_cast<cudaGraphicsResource_t>(r));
}

std::vector<float*> GlBufferInterop::map(void* stream) {
    if (mapped_) fail("render: GlBufferInterop::map(): already mapped");
    auto* resources = reinterpret_cast<cudaGraphicsResource_t*>(resources_.data());
    const auto s = static_cast<cudaStream_t>(stream);
    check_cuda(cudaGraphicsMapResources(int(resources_.size()), resources, s), "cudaGraphicsMapResources (buffers)");
    mapped_ = true;
    return pointers();
}

std::vector<float*> GlBufferInterop::pointers() const {
    std::vector<float*> out;
    for (auto* r : resources_) {
        void* p = nullptr;
        std::size_t size = 0;
        check_cuda(cudaGraphicsResourceGetMappedPointer(&p, &size, static_cast<cudaGraphicsResource_t>(r)),
                   "cudaGraphicsResourceGetMappedPointer (are the buffers mapped?)");
        out.push_back(static_cast<float*>(p));
    }
    return out;
}

void GlBufferInterop::unmap(void* stream) {
    if (!mapped_) return;
    mapped_ = false;
    auto* resources = reinterpret_cast<cudaGraphicsResource_t*>(resources_.data());
    check_cuda(cudaGraphicsUnmapResources(int(resources_.size()), resources, static_cast<cudaStream_t>(stream)),
               "cudaGraphicsUnmapResources (buffers)");
}

}  // namespace emoface::render
