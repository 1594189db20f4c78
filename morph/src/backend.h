#pragma once
// What the Morpher front end hands a backend each frame, and the backend
// interface. The front end validates input and builds the line table; a
// backend only runs it.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "emoface/morph/kernel.h"
#include "emoface/morph/morph.h"

namespace emoface::morph::detail {

// One frame, ready to run: the sources taking part (weight > 0, or all of
// them for positions), their weights and bounds (target pixels where each
// is evaluated), and the line table with one record of
// kernel::record_floats(sources) floats per line. `batch` is the
// compile-time K the kernels run with: min(sources, kernel::kMaxBatch).
struct FramePlan {
    int sources = 0;
    int batch = 1;
    int source_index[kernel::kMaxKeys] = {};
    float weight[kernel::kMaxKeys] = {};
    kernel::Bound bound[kernel::kMaxKeys] = {};
    kernel::Rgba rest{0.0f, 0.0f, 0.0f, 0.0f};  // MorphParams::rest in the format's units
    int lines = 0;
    int record_floats = 0;
    const float* records = nullptr;
    kernel::Law law = kernel::Law::InverseSquare;
    float b = 2.0f;
    bool normal_map = false;
    Accuracy accuracy = Accuracy::Exact;
    int fast_cell = 8;
    float fast_reach = 4.0f;  // cells
    float extent = 1.0f;      // S = max(W, H): iso units to pixels
    float inv_extent = 1.0f;  // 1 / S
};

struct OutputTarget {
    enum class Kind { Host, Device, Surface, Positions };
    Kind kind = Kind::Host;
    void* ptr = nullptr;            // Host/Device: pixels; Positions: host floats
    std::size_t pitch = 0;          // bytes a row (Host, Device)
    unsigned long long surface = 0; // Surface
};

class BackendImpl {
public:
    virtual ~BackendImpl() = default;
    virtual void run(const FramePlan& plan, const OutputTarget& target) = 0;
    virtual void synchronize() {}
    virtual void* stream() const { return nullptr; }
    virtual SetupTimes setup_times() const = 0;
};

// The pixels of a key the backends store: the texels its region touches, or
// the whole map.
struct Crop {
    int x, y, w, h;
};
inline Crop key_crop(const Region& r, int width, int height) {
    auto lo = [](float v, int n) { return std::clamp(static_cast<int>(std::floor(v * n)), 0, n - 1); };
    auto hi = [](float v, int n) { return std::clamp(static_cast<int>(std::ceil(v * n)), 1, n); };
    const int x0 = lo(r.x0, width), y0 = lo(r.y0, height);
    const int x1 = std::max(hi(r.x1, width), x0 + 1), y1 = std::max(hi(r.y1, height), y0 + 1);
    return {x0, y0, x1 - x0, y1 - y0};
}

// keys: validated, all width x height of `format`; each backend stores
// key_crop(key.region) of each.
std::unique_ptr<BackendImpl> make_cpu_backend(int width, int height, PixelFormat format,
                                              const std::vector<KeyMap>& keys);
#if defined(EMOFACE_MORPH_CUDA)
std::unique_ptr<BackendImpl> make_cuda_backend(int width, int height, PixelFormat format,
                                               const std::vector<KeyMap>& keys);
// Found once per process, on first use.
struct CudaStatus {
    bool usable = false;     // a device this build has code for
    bool gpu_found = false;  // the driver answers and counts at least one device
    std::string why;         // when not usable: the CUDA error or what is missing
    std::string description; // "NVIDIA H100 80GB HBM3 (sm_90, 132 SMs)"
};
const CudaStatus& cuda_status();
#endif

}  // namespace emoface::morph::detail
