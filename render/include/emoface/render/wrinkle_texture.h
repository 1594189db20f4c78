#pragma once
// The GL texture the shader samples as the wrinkle (normal) map, and the two
// ways the morph result gets into it (thesis 5.4):
//   CPU: upload() copies host pixels with glTexSubImage2D;
//   GPU: the texture is registered with CUDA once (cudaGraphicsGLRegisterImage,
//        surface load/store); each frame map_surface() gives a surface object
//        the morph kernel writes into, unmap() hands it back to GL. The image
//        never passes through host memory.
//
// Conventions shared with morph/ and expression/: texel (x, y) of the image,
// row 0 first, is the texture's row y, so UV (u, v) = ((x + 0.5) / W,
// (y + 0.5) / H): v runs down the image. The tangent-space normal's x goes
// along +u (image right) and y along +v (image down), z out of the skin.
#include <cstddef>
#include <vector>

#include "emoface/render/renderer.h"

namespace emoface::render {

enum class TexelFormat {
    RGBA8,    // 4 x uint8, the normal encoded as 0.5 + 0.5 n
    RGBA32F,  // 4 x float
};
std::size_t texel_bytes(TexelFormat format);

// True when this build has CUDA-GL interop and a CUDA device is present.
bool cuda_interop_available();

class WrinkleTexture {
public:
    // Creates the texture in the current GL context (a Platform's): linear
    // filtering, clamped to the edge, initialised to the flat normal (0, 0, 1).
    WrinkleTexture(int width, int height, TexelFormat format, NormalEncoding encoding);
    ~WrinkleTexture();
    WrinkleTexture(const WrinkleTexture&) = delete;
    WrinkleTexture& operator=(const WrinkleTexture&) = delete;

    int width() const { return width_; }
    int height() const { return height_; }
    TexelFormat format() const { return format_; }
    NormalEncoding encoding() const { return encoding_; }
    unsigned gl_texture() const { return texture_; }

    // CPU path: replaces the whole texture with `pixels` (in this texture's
    // format, rows top first, `row_bytes` apart; 0 = tightly packed).
    void upload(const void* pixels, std::size_t row_bytes = 0);

    // Reads the whole texture back (for tests): width * height texels of
    // this texture's format, rows top first. Waits for the GPU.
    void download(void* pixels) const;

    // GPU path. register_cuda() is called once (map_surface() calls it when
    // needed); throws emoface::EnvironmentError without CUDA or a device.
    void register_cuda();
    bool cuda_registered() const { return cuda_resource_ != nullptr; }
    // Maps the texture for CUDA on `stream` (a cudaStream_t, null = default)
    // and returns a cudaSurfaceObject_t over it. GL must not use the texture
    // until unmap().
    unsigned long long map_surface(void* stream = nullptr);
    void unmap(void* stream = nullptr);
    // The same with `others` (other registered cudaGraphicsResource_t: a
    // GlBufferInterop's) mapped and unmapped in the same calls: each mapping
    // is a handoff between GL and CUDA that costs more GPU time than a
    // small kernel, so a frame makes one for all its resources.
    unsigned long long map_surface(void* stream, const std::vector<void*>& others);
    void unmap(void* stream, const std::vector<void*>& others);
    bool mapped() const { return surface_ != 0; }

private:
    void unregister_cuda() noexcept;

    int width_, height_;
    TexelFormat format_;
    NormalEncoding encoding_;
    unsigned texture_ = 0;
    void* cuda_resource_ = nullptr;   // cudaGraphicsResource_t
    unsigned long long surface_ = 0;  // cudaSurfaceObject_t while mapped
};

// Maps on construction, unmaps on destruction.
class MappedWrinkleSurface {
public:
    explicit MappedWrinkleSurface(WrinkleTexture& texture, void* stream = nullptr)
        : texture_(texture), stream_(stream), surface_(texture.map_surface(stream)) {}
    ~MappedWrinkleSurface() {
        try {
            texture_.unmap(stream_);
        } catch (...) {  // a destructor must not throw; the next map reports it
        }
    }
    MappedWrinkleSurface(const MappedWrinkleSurface&) = delete;
    MappedWrinkleSurface& operator=(const MappedWrinkleSurface&) = delete;
    unsigned long long surface() const { return surface_; }

private:
    WrinkleTexture& texture_;
    void* stream_;
    unsigned long long surface_;
};

}  // namespace emoface::render
