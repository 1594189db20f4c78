// The CPU backend: the key maps copied once (each cropped to its region),
// the shared kernel body run over rows on the process's thread pool
// (emoface/common/parallel.h).
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "backend.h"
#include "cpu_kernels.h"
#include "emoface/common/parallel.h"
#include "emoface/common/timing.h"

namespace emoface::morph::detail {
namespace {

// The AVX2 + FMA row loops where the build has them and the processor runs
// them, unless EMOFACE_MORPH_BASELINE=1 asks for the baseline ones (so they
// are tested on machines that have AVX2, outside the sanitizer build too).
const CpuKernels& pick_kernels() {
    const char* baseline = std::getenv("EMOFACE_MORPH_BASELINE");
    if (baseline != nullptr && std::strcmp(baseline, "1") == 0) return cpu_base::kernels();
#if defined(EMOFACE_MORPH_HAVE_AVX2) && (defined(__x86_64__) || defined(__i386__))
    if (__builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma")) return cpu_avx2::kernels();
#endif
    return cpu_base::kernels();
}

class CpuBackend final : public BackendImpl {
public:
    CpuBackend(int width, int height, PixelFormat format, const std::vector<KeyMap>& keys)
        : width_(width), height_(height), is_float_(format == PixelFormat::RgbaF32),
          kernels_(pick_kernels()) {
        const std::size_t pixel = is_float_ ? 16 : 4;
        auto t0 = Clock::now();
        keys_.resize(keys.size());
        for (std::size_t k = 0; k < keys.size(); ++k) {
            crops_.push_back(key_crop(keys[k].region, width, height));
            keys_[k].resize(static_cast<std::size_t>(crops_[k].w) * crops_[k].h * pixel);
        }
        times_.allocate_ms = ms_since(t0);
        t0 = Clock::now();
        for (std::size_t k = 0; k < keys.size(); ++k) {
            const Crop& c = crops_[k];
            const auto* src = static_cast<const unsigned char*>(keys[k].pixels);
            for (int y = 0; y < c.h; ++y)
                std::memcpy(keys_[k].data() + static_cast<std::size_t>(y) * c.w * pixel,
                            src + (static_cast<std::size_t>(c.y + y) * width + c.x) * pixel, c.w * pixel);
        }
        times_.upload_ms = ms_since(t0);
    }

    SetupTimes setup_times() const override { return times_; }

    void run(const FramePlan& plan, const OutputTarget& target) override {
        CpuJob job;
        job.plan = &plan;
        job.width = width_;
        job.height = height_;
        job.is_float = is_float_;
        for (int i = 0; i < plan.sources; ++i) {
            const int k = plan.source_index[i];
            const Crop& c = crops_[k];
            job.keys[i] = {keys_[k].data(), static_cast<std::size_t>(c.w) * (is_float_ ? 16 : 4), width_, height_,
                           is_float_, c.x, c.y, c.w, c.h, plan.rest};
        }
        if (target.kind == OutputTarget::Kind::Positions) {
            job.positions = static_cast<float*>(target.ptr);
        } else {
            job.out = static_cast<unsigned char*>(target.ptr);
            job.out_pitch = target.pitch;
        }

        if (plan.accuracy == Accuracy::Exact) {
            parallel_for(height_, 1, [&](int y0, int y1) { kernels_.exact_rows(job, y0, y1); });
            return;
        }
        // Grid points i·cell cover pixel centres up to the last one, plus one
        // more so every pixel lies inside a cell.
        job.grid_w = (width_ - 1) / plan.fast_cell + 2;
        job.grid_h = (height_ - 1) / plan.fast_cell + 2;
        const std::size_t grid_floats =
            static_cast<std::size_t>(job.grid_w) * job.grid_h * kernel::sum_floats(plan.sources);  // by slot
        if (grid_.size() < grid_floats) grid_.resize(grid_floats);  // first use / finer cell only
        job.grid = grid_.data();
        parallel_for(job.grid_h, 1, [&](int g0, int g1) { kernels_.grid_rows(job, g0, g1); });
        const int cell_rows = (height_ + plan.fast_cell - 1) / plan.fast_cell;
        parallel_for(cell_rows, 1, [&](int t0, int t1) { kernels_.apply_rows(job, t0, t1); });
    }

private:
    int width_, height_;
    bool is_float_;
    const CpuKernels& kernels_;
    std::vector<std::vector<unsigned char>> keys_;  // crops_[k] of key k
    std::vector<Crop> crops_;
    std::vector<float> grid_;
    SetupTimes times_;
};

}  // namespace

std::unique_ptr<BackendImpl> make_cpu_backend(int width, int height, PixelFormat format,
                                              const std::vector<KeyMap>& keys) {
    return std::make_unique<CpuBackend>(width, height, format, keys);
}

}  // namespace emoface::morph::detail

namespace emoface::morph {

const char* cpu_kernels_name() {
    return &detail::pick_kernels() == &detail::cpu_base::kernels() ? "baseline" : "avx2";
}

}  // namespace emoface::morph
