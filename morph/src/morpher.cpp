// The Morpher front end: input checks (every bad input is an InputError that
// says what was expected and what was found), the choice of backend, and the
// per-frame line table that both backends run.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "backend.h"
#include "emoface/common/error.h"
#include "emoface/morph/morph.h"

namespace emoface::morph {

const char* to_string(Backend backend) {
    switch (backend) {
        case Backend::Auto: return "auto";
        case Backend::Cpu: return "cpu";
        case Backend::Cuda: return "cuda";
    }
    return "?";
}
const char* to_string(Accuracy accuracy) { return accuracy == Accuracy::Exact ? "exact" : "fast"; }
const char* to_string(PixelFormat format) { return format == PixelFormat::Rgba8 ? "rgba8" : "rgbaf32"; }

bool cuda_available() {
#if defined(EMOFACE_MORPH_CUDA)
    return detail::cuda_status().usable;
#else
    return false;
#endif
}

std::string cuda_device_description() {
#if defined(EMOFACE_MORPH_CUDA)
    const detail::CudaStatus& s = detail::cuda_status();
    return s.usable ? s.description : "none (" + s.why + ")";
#else
    return "none (built without the CUDA backend)";
#endif
}

namespace {

using detail::FramePlan;
using detail::OutputTarget;

// A line in iso units (pixels / max(W, H)), in double so the per-frame table
// is built from exact differences and only rounded once.
struct IsoLine {
    double px, py, qx, qy;
};

bool finite(const Line& l) {
    return std::isfinite(l.px) && std::isfinite(l.py) && std::isfinite(l.qx) && std::isfinite(l.qy);
}

// Lines shorter than this (iso units) have no direction to warp along.
constexpr double kMinLength = 1e-6;

IsoLine to_iso(const Line& l, double sx, double sy) {
    return {l.px * sx, l.py * sy, l.qx * sx, l.qy * sy};
}

bool zero_length(const IsoLine& iso) {
    const double dx = iso.qx - iso.px, dy = iso.qy - iso.py;
    return !(dx * dx + dy * dy >= kMinLength * kMinLength);
}

// Key layouts need every line (a zero-length one has no direction to warp
// along); a target line may collapse in some pose (a closed lid, a feature a
// FAP pushes onto another), and then it is skipped for that frame.
enum class ZeroLength { Error, Skip };

void check_layout(const char* fn, const std::string& what, const Layout& layout, double sx, double sy,
                  ZeroLength zero = ZeroLength::Error) {
    for (std::size_t i = 0; i < layout.size(); ++i) {
        const Line& l = layout[i];
        if (!finite(l))
            fail<InputError>("morph: {}(): {} line {} has a non-finite coordinate: P = ({}, {}), Q = ({}, {})",
                             fn, what, i, l.px, l.py, l.qx, l.qy);
        if (zero == ZeroLength::Error && zero_length(to_iso(l, sx, sy)))
            fail<InputError>("morph: {}(): {} line {} has zero length: P = ({}, {}), Q = ({}, {}), "
                             "expected P != Q",
                             fn, what, i, l.px, l.py, l.qx, l.qy);
    }
}

// Backend::Auto without a usable GPU: one plain line a process, on stderr
// (no "morph:" prefix, which reads like the `emoface morph` command). The
// CUDA error behind it is for Backend::Cuda's error and
// cuda_device_description() (`emoface -v` prints it).
void say_the_morph_runs_on_the_cpu() {
    static std::atomic<bool> said{false};
    if (said.exchange(true)) return;
#if defined(EMOFACE_MORPH_CUDA)
    std::fputs(detail::cuda_status().gpu_found
                   ? "the NVIDIA GPU cannot run this build's CUDA code: the morph runs on the CPU\n"
                   : "no NVIDIA GPU found: the morph runs on the CPU\n",
               stderr);
#else
    std::fputs("this build has no CUDA backend: the morph runs on the CPU\n", stderr);
#endif
}

}  // namespace

struct Morpher::Impl {
    int width = 0, height = 0;
    PixelFormat format = PixelFormat::Rgba8;
    int keys = 0, lines = 0;
    double sx = 1.0, sy = 1.0;  // normalised -> iso
    double extent = 1.0;        // S
    std::vector<std::vector<IsoLine>> key_lines;
    std::vector<Region> regions;
    std::vector<bool> whole;  // the key's region is the whole map
    std::vector<float> records;  // capacity for every key: never grows per frame
    FramePlan plan;
    Backend kind = Backend::Cpu;
    std::unique_ptr<detail::BackendImpl> backend;

    void check_params(const char* fn, const MorphParams& params) const {
        if (!(std::isfinite(params.a) && params.a > 0.0f))
            fail<InputError>("morph: {}(): params.a = {}, expected a finite value > 0", fn, params.a);
        if (!(std::isfinite(params.b) && params.b >= 0.0f && params.b <= 16.0f))
            fail<InputError>("morph: {}(): params.b = {}, expected a value in [0, 16]", fn, params.b);
        if (!(std::isfinite(params.p) && params.p >= 0.0f && params.p <= 16.0f))
            fail<InputError>("morph: {}(): params.p = {}, expected a value in [0, 16]", fn, params.p);
        for (int c = 0; c < 4; ++c)
            if (!std::isfinite(params.rest[c]))
                fail<InputError>("morph: {}(): params.rest[{}] = {}, expected a finite value (format units, "
                                 "0..1)",
                                 fn, c, params.rest[c]);
        if (params.accuracy == Accuracy::Fast) {
            const int c = params.fast_cell;
            if (c != 4 && c != 8 && c != 16 && c != 32)
                fail<InputError>("morph: {}(): params.fast_cell = {}, expected 4, 8, 16 or 32", fn, c);
            if (!(std::isfinite(params.fast_reach) && params.fast_reach >= 0.0f && params.fast_reach <= 64.0f))
                fail<InputError>("morph: {}(): params.fast_reach = {}, expected a value in [0, 64] (cells)", fn,
                                 params.fast_reach);
        }
    }

    void check_weights(const char* fn, const std::vector<float>& weights) const {
        if (static_cast<int>(weights.size()) != keys)
            fail<InputError>("morph: {}(): {} weights, expected {} (one per key map)", fn, weights.size(), keys);
        double sum = 0.0;
        for (std::size_t k = 0; k < weights.size(); ++k) {
            const float w = weights[k];
            if (!std::isfinite(w) || w < 0.0f)
                fail<InputError>("morph: {}(): weight {} is {}, expected a finite value >= 0", fn, k, w);
            sum += w;
        }
        // Keys over a rest value add up (MorphParams::rest): up to one full
        // share per key.
        if (sum > kMaxKeys + 1e-4)
            fail<InputError>("morph: {}(): weights sum to {}, expected at most {} (kMaxKeys)", fn, sum, kMaxKeys);
    }

    void check_target(const char* fn, const Layout& target) const {
        if (static_cast<int>(target.size()) != lines)
            fail<InputError>("morph: {}(): target layout has {} lines, expected {} (the key layouts' count)",
                             fn, target.size(), lines);
        check_layout(fn, "target", target, sx, sy, ZeroLength::Skip);
    }

    // Builds the line table for the given sources. Weights of the sources
    // that take part go to plan.weight in the same order.
    void build_plan(const Layout& target, const MorphParams& params, const int* sources, const float* weights,
                    int count, bool use_regions) {
        plan.sources = count;
        plan.batch = std::clamp(count, 1, kernel::kMaxBatch);
        double moved[kMaxKeys] = {};  // largest end point move of each source (iso units)
        for (int i = 0; i < count; ++i) {
            plan.source_index[i] = sources[i];
            plan.weight[i] = weights[i];
        }
        const float unit = format == PixelFormat::Rgba8 ? 255.0f : 1.0f;
        plan.rest = {params.rest[0] * unit, params.rest[1] * unit, params.rest[2] * unit, params.rest[3] * unit};
        plan.record_floats = kernel::record_floats(count);
        plan.law = params.b == 2.0f ? kernel::Law::InverseSquare : kernel::Law::Power;
        plan.b = params.b;
        plan.normal_map = params.normal_map;
        plan.accuracy = params.accuracy;
        plan.fast_cell = params.fast_cell;
        plan.fast_reach = params.fast_reach;
        plan.extent = static_cast<float>(extent);
        plan.inv_extent = static_cast<float>(1.0 / extent);

        // A frame's host work is this loop (N lines): plain sqrt rather than
        // hypot, and pow only for an unusual p, keep it to a few µs.
        records.assign(static_cast<std::size_t>(lines) * plan.record_floats, 0.0f);  // within capacity
        const double a = params.a, p = params.p;
        int kept = 0;
        for (int i = 0; i < lines; ++i) {
            const IsoLine t = to_iso(target[i], sx, sy);
            if (zero_length(t)) continue;  // collapsed in this pose: no direction, no say
            const double dx = t.qx - t.px, dy = t.qy - t.py;
            const double len = std::sqrt(dx * dx + dy * dy);
            const double ex = dx / len, ey = dy / len;
            const double nx = -dy / len, ny = dx / len;  // perp(d) / len
            const double mx = 0.5 * (t.px + t.qx), my = 0.5 * (t.py + t.qy);
            const double wk = p == 0.0 ? 1.0 : p == 0.5 ? 1.0 / std::sqrt(len) : p == 1.0 ? 1.0 / len : std::pow(len, -p);
            float* rec = records.data() + static_cast<std::size_t>(kept++) * plan.record_floats;
            rec[kernel::kEx] = static_cast<float>(ex);
            rec[kernel::kEy] = static_cast<float>(ey);
            rec[kernel::kCs] = static_cast<float>(-(mx * ex + my * ey));
            rec[kernel::kHalfLen] = static_cast<float>(0.5 * len);
            rec[kernel::kNx] = static_cast<float>(nx);
            rec[kernel::kNy] = static_cast<float>(ny);
            rec[kernel::kCv] = static_cast<float>(-(t.px * nx + t.py * ny));
            rec[kernel::kWk] = static_cast<float>(wk);
            rec[kernel::kWa] = static_cast<float>(a * wk);
            for (int j = 0; j < count; ++j) {
                const IsoLine& s = key_lines[sources[j]][i];
                moved[j] = std::max({moved[j], std::sqrt((s.px - t.px) * (s.px - t.px) + (s.py - t.py) * (s.py - t.py)),
                                     std::sqrt((s.qx - t.qx) * (s.qx - t.qx) + (s.qy - t.qy) * (s.qy - t.qy))});
                const double sdx = s.qx - s.px, sdy = s.qy - s.py;
                const double slen = std::sqrt(sdx * sdx + sdy * sdy);
                float* c = rec + kernel::kGeomFloats + kernel::kSourceFloats * j;
                c[0] = static_cast<float>(0.5 * (s.px + s.qx) - mx);  // A = M' - M
                c[1] = static_cast<float>(0.5 * (s.py + s.qy) - my);
                c[2] = static_cast<float>((sdx - dx) / len);  // B = (d' - d) / len
                c[3] = static_cast<float>((sdy - dy) / len);
                c[4] = static_cast<float>(-sdy / slen - nx);  // C = n' - n
                c[5] = static_cast<float>(sdx / slen - ny);
            }
        }
        plan.lines = kept;
        plan.records = records.data();
        for (int j = 0; j < count; ++j)
            plan.bound[j] = use_regions && !whole[sources[j]] ? region_bound(sources[j], moved[j] * extent)
                                                              : kernel::Bound{0, 0, width, height};
    }

    // The target pixels where key k's region can land (morph.h, KeyMap::region):
    // the pixel positions whose bilinear samples touch its stored texels,
    // grown by the largest end point move (pixels), a quarter of it and 2
    // pixels, clipped to the image.
    kernel::Bound region_bound(int k, double moved) const {
        const detail::Crop c = detail::key_crop(regions[k], width, height);
        const double grow = 1.25 * moved + 2.0;
        auto clip = [](double v, int n) { return static_cast<int>(std::clamp(v, 0.0, static_cast<double>(n))); };
        return {clip(std::floor(c.x - 0.5 - grow), width), clip(std::floor(c.y - 0.5 - grow), height),
                clip(std::ceil(c.x + c.w + 0.5 + grow), width), clip(std::ceil(c.y + c.h + 0.5 + grow), height)};
    }

    void frame(const char* fn, const Layout& target, const std::vector<float>& weights, const MorphParams& params,
               const OutputTarget& out) {
        check_params(fn, params);
        check_weights(fn, weights);
        check_target(fn, target);
        int sources[kernel::kMaxKeys];
        float w[kernel::kMaxKeys];
        int count = 0;
        for (int k = 0; k < keys; ++k) {
            if (weights[k] > 0.0f) {
                sources[count] = k;
                w[count] = weights[k];
                ++count;
            }
        }
        build_plan(target, params, sources, w, count, true);  // no sources: rest everywhere
        backend->run(plan, out);
    }
};

Morpher::Morpher(int width, int height, PixelFormat format, std::vector<KeyMap> keys, Backend backend)
    : impl_(std::make_unique<Impl>()) {
    constexpr const char* fn = "Morpher";
    if (width < 1 || height < 1 || width > kMaxSide || height > kMaxSide)
        fail<InputError>("morph: Morpher(): size {} x {}, expected width and height in 1..{}", width, height,
                         kMaxSide);
    if (format != PixelFormat::Rgba8 && format != PixelFormat::RgbaF32)
        fail<InputError>("morph: Morpher(): unknown pixel format {}", static_cast<int>(format));
    if (keys.empty() || keys.size() > static_cast<std::size_t>(kMaxKeys))
        fail<InputError>("morph: Morpher(): K = {} key maps, expected 1 to {} (Morpher::kMaxKeys)", keys.size(),
                         kMaxKeys);

    if (keys[0].layout.size() > static_cast<std::size_t>(kMaxLines))
        fail<InputError>("morph: Morpher(): key 0 layout has {} lines, expected at most {}", keys[0].layout.size(),
                         kMaxLines);
    Impl& m = *impl_;
    m.width = width;
    m.height = height;
    m.format = format;
    m.keys = static_cast<int>(keys.size());
    m.lines = static_cast<int>(keys[0].layout.size());
    m.extent = std::max(width, height);
    m.sx = width / m.extent;
    m.sy = height / m.extent;
    for (std::size_t k = 0; k < keys.size(); ++k) {
        const KeyMap& key = keys[k];
        if (key.pixels == nullptr) fail<InputError>("morph: Morpher(): key {} has no pixels (null pointer)", k);
        if ((key.width != 0 || key.height != 0) && (key.width != width || key.height != height))
            fail<InputError>("morph: Morpher(): key {} is {} x {}, expected {} x {} (all key maps the same size)", k,
                             key.width, key.height, width, height);
        if (static_cast<int>(key.layout.size()) != m.lines)
            fail<InputError>("morph: Morpher(): key {} layout has {} lines, key 0 has {} (every layout needs the "
                             "same line count)",
                             k, key.layout.size(), m.lines);
        check_layout(fn, fmt::format("key {}", k), key.layout, m.sx, m.sy);
        const Region& r = key.region;
        if (!(r.x0 >= 0.0f && r.y0 >= 0.0f && r.x1 <= 1.0f && r.y1 <= 1.0f && r.x0 < r.x1 && r.y0 < r.y1))
            fail<InputError>("morph: Morpher(): key {} region is ({}, {}) - ({}, {}), expected 0 <= x0 < x1 <= 1 and "
                             "0 <= y0 < y1 <= 1 (normalised coordinates of the key's layout)",
                             k, r.x0, r.y0, r.x1, r.y1);
        const detail::Crop crop = detail::key_crop(r, width, height);
        m.regions.push_back(r);
        m.whole.push_back(crop.x == 0 && crop.y == 0 && crop.w == width && crop.h == height);
        std::vector<IsoLine> iso;
        iso.reserve(key.layout.size());
        for (const Line& l : key.layout) iso.push_back(to_iso(l, m.sx, m.sy));
        m.key_lines.push_back(std::move(iso));
    }
    m.records.reserve(static_cast<std::size_t>(m.lines) * kernel::record_floats(m.keys));

    if (backend == Backend::Cuda) {
#if defined(EMOFACE_MORPH_CUDA)
        const detail::CudaStatus& cuda = detail::cuda_status();
        if (!cuda.usable)
            fail<EnvironmentError>("morph: Morpher(): Backend::Cuda asked for, but no CUDA device is usable ({}); "
                                   "run on a machine with an NVIDIA GPU and driver, or ask for Backend::Cpu or "
                                   "Backend::Auto",
                                   cuda.why);
        m.backend = detail::make_cuda_backend(width, height, format, keys);
        m.kind = Backend::Cuda;
#else
        fail<EnvironmentError>("morph: Morpher(): Backend::Cuda asked for, but this build has no CUDA backend "
                               "(configured without nvcc or with -DEMOFACE_CUDA=OFF); rebuild with the CUDA "
                               "toolkit, or ask for Backend::Cpu or Backend::Auto");
#endif
    } else if (backend == Backend::Auto) {
#if defined(EMOFACE_MORPH_CUDA)
        if (detail::cuda_status().usable) {
            m.backend = detail::make_cuda_backend(width, height, format, keys);
            m.kind = Backend::Cuda;
        }
#endif
        if (!m.backend) say_the_morph_runs_on_the_cpu();
    }
    if (!m.backend) {
        m.backend = detail::make_cpu_backend(width, height, format, keys);
        m.kind = Backend::Cpu;
    }
}

Morpher::~Morpher() = default;
Morpher::Morpher(Morpher&&) noexcept = default;
Morpher& Morpher::operator=(Morpher&&) noexcept = default;

Backend Morpher::backend() const { return impl_->kind; }
int Morpher::width() const { return impl_->width; }
int Morpher::height() const { return impl_->height; }
int Morpher::keys() const { return impl_->keys; }
int Morpher::lines() const { return impl_->lines; }
PixelFormat Morpher::format() const { return impl_->format; }
std::size_t Morpher::pixel_bytes() const { return impl_->format == PixelFormat::Rgba8 ? 4 : 16; }
SetupTimes Morpher::setup_times() const { return impl_->backend->setup_times(); }

void Morpher::morph_to_host(const Layout& target, const std::vector<float>& weights, const MorphParams& params,
                            void* out) {
    if (out == nullptr) fail<InputError>("morph: morph_to_host(): out is null, expected a buffer of {} bytes",
                                         static_cast<std::size_t>(width()) * height() * pixel_bytes());
    OutputTarget t;
    t.kind = OutputTarget::Kind::Host;
    t.ptr = out;
    t.pitch = static_cast<std::size_t>(width()) * pixel_bytes();
    impl_->frame("morph_to_host", target, weights, params, t);
}

void Morpher::morph_to_device(const Layout& target, const std::vector<float>& weights, const MorphParams& params,
                              void* device_ptr, std::size_t pitch_bytes) {
    if (impl_->kind != Backend::Cuda)
        fail<InputError>("morph: morph_to_device(): this Morpher runs on the {} backend, expected Backend::Cuda "
                         "(use morph_to_host)",
                         to_string(impl_->kind));
    if (device_ptr == nullptr) fail<InputError>("morph: morph_to_device(): device_ptr is null");
    const std::size_t row = static_cast<std::size_t>(width()) * pixel_bytes();
    if (pitch_bytes < row)
        fail<InputError>("morph: morph_to_device(): pitch_bytes = {}, expected at least {} (width x {} bytes)",
                         pitch_bytes, row, pixel_bytes());
    OutputTarget t;
    t.kind = OutputTarget::Kind::Device;
    t.ptr = device_ptr;
    t.pitch = pitch_bytes;
    impl_->frame("morph_to_device", target, weights, params, t);
}

void Morpher::morph_to_surface(const Layout& target, const std::vector<float>& weights, const MorphParams& params,
                               unsigned long long surface) {
    if (impl_->kind != Backend::Cuda)
        fail<InputError>("morph: morph_to_surface(): this Morpher runs on the {} backend, expected Backend::Cuda",
                         to_string(impl_->kind));
    if (surface == 0) fail<InputError>("morph: morph_to_surface(): surface is 0, expected a cudaSurfaceObject_t");
    OutputTarget t;
    t.kind = OutputTarget::Kind::Surface;
    t.surface = surface;
    impl_->frame("morph_to_surface", target, weights, params, t);
}

void Morpher::positions_to_host(const Layout& target, const MorphParams& params, float* out) {
    constexpr const char* fn = "positions_to_host";
    if (out == nullptr) fail<InputError>("morph: positions_to_host(): out is null");
    Impl& m = *impl_;
    m.check_params(fn, params);
    m.check_target(fn, target);
    int sources[kernel::kMaxKeys];
    float w[kernel::kMaxKeys];
    for (int k = 0; k < m.keys; ++k) {
        sources[k] = k;
        w[k] = 1.0f / m.keys;
    }
    m.build_plan(target, params, sources, w, m.keys, false);
    OutputTarget t;
    t.kind = OutputTarget::Kind::Positions;
    t.ptr = out;
    m.backend->run(m.plan, t);
}

void Morpher::synchronize() { impl_->backend->synchronize(); }
void* Morpher::cuda_stream() const { return impl_->backend->stream(); }

}  // namespace emoface::morph
