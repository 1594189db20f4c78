// The capture writers (capture.h): what the readers read back.
#include <algorithm>
#include <array>
#include <cmath>

#include <fmt/format.h>

#include "emoface/common/error.h"
#include "emoface/expression/capture.h"
#include "emoface/expression/face_state.h"

namespace emoface::expression {
namespace {

constexpr double kFapPerRadian = 1e5;
constexpr std::array<int, 17> kOpenFaceAus{1, 2, 4, 5, 6, 7, 9, 10, 12, 14, 15, 17, 20, 23, 25, 26, 45};
constexpr int kTimecodeRate = 30;  // Live Link Face's timecode frames per second

void check_fps(double fps, const char* writer) {
    if (!(std::isfinite(fps) && fps > 0))
        fail<InputError>("capture: {}(): expected a positive frame rate, got {}", writer, fps);
}

// "HH:MM:SS:FF.fff" of `seconds` at kTimecodeRate.
std::string timecode(double seconds) {
    const long long thousandths = std::llround(seconds * kTimecodeRate * 1000);
    const long long frames = thousandths / 1000, sub = thousandths % 1000;
    const long long whole = frames / kTimecodeRate;
    return fmt::format("{:02}:{:02}:{:02}:{:02}.{:03}", whole / 3600, whole / 60 % 60, whole % 60,
                       frames % kTimecodeRate, sub);
}

// The ARKit fit: min |A w - b|^2 with 0 <= w <= 1 for one frame, A the 52
// shapes' FAP vectors. bounded_least_squares (the AU layer's coordinate
// descent) crawls here: the shapes overlap far more than one region's AUs
// (jaw, lips and the lips' roll and press share FAPs), and it takes
// thousands of sweeps a frame. The Gram matrix is the same for every frame,
// so an active-set method is cheap: solve the free shapes exactly, step back
// to the box where that leaves it, free a shape held at a bound whose
// gradient points inwards, until no shape wants to move (the KKT point of a
// convex problem: the same minimum).
class ShapeFit {
public:
    explicit ShapeFit(const ArkitShapes& shapes) : a_(shapes.faps), n_(shapes.faps.size()), g_(n_ * n_) {
        for (std::size_t i = 0; i < n_; ++i)
            for (std::size_t j = 0; j < n_; ++j) {
                double s = 0;
                for (int f = 2; f < fap::kFapCount; ++f) s += a_[i][std::size_t(f)] * a_[j][std::size_t(f)];
                g_[i * n_ + j] = s;
            }
        for (std::size_t i = 0; i < n_; ++i) ridge_ = std::max(ridge_, 1e-12 * g_[i * n_ + i]);
    }

    // The weights for target FAPs b (FAPs 1 and 2 ignored).
    std::vector<double> fit(const FapValues& b) const {
        std::vector<double> c(n_, 0.0), x(n_, 0.0);
        for (std::size_t i = 0; i < n_; ++i)
            for (int f = 2; f < fap::kFapCount; ++f) c[i] += a_[i][std::size_t(f)] * b[std::size_t(f)];
        double b_norm = 0;
        for (int f = 2; f < fap::kFapCount; ++f) b_norm += b[std::size_t(f)] * b[std::size_t(f)];
        b_norm = std::sqrt(b_norm);
        // Lawson and Hanson's active sets, with two bounds: free the held
        // shape that most wants in; solve the free ones; where that leaves
        // the box, step to its wall and hold the shapes that reached it.
        std::vector<char> free(n_, 0);
        for (int outer = 0; outer < 4 * int(n_); ++outer) {
            std::size_t best = n_;
            double best_pull = 0;
            for (std::size_t i = 0; i < n_; ++i) {
                if (free[i]) continue;
                double grad = -c[i];
                for (std::size_t j = 0; j < n_; ++j) grad += g_[i * n_ + j] * x[j];
                const double pull = x[i] <= 0 ? -grad : grad;  // > 0: it wants into the box
                if (pull > 1e-9 * std::sqrt(g_[i * n_ + i]) * (b_norm + 1) && pull > best_pull) {
                    best_pull = pull;
                    best = i;
                }
            }
            if (best == n_) break;
            free[best] = 1;
            for (int inner = 0; inner < 4 * int(n_); ++inner) {
                const std::vector<double> y = solve_free(free, x, c);
                double step = 1;
                for (std::size_t i = 0; i < n_; ++i) {
                    if (!free[i]) continue;
                    if (y[i] < 0) step = std::min(step, x[i] / (x[i] - y[i]));
                    if (y[i] > 1) step = std::min(step, (1 - x[i]) / (y[i] - x[i]));
                }
                for (std::size_t i = 0; i < n_; ++i)
                    if (free[i]) x[i] = std::clamp(x[i] + step * (y[i] - x[i]), 0.0, 1.0);
                if (step >= 1) break;
                for (std::size_t i = 0; i < n_; ++i)
                    if (free[i] && (y[i] < 0 || y[i] > 1) && (x[i] <= 1e-12 || x[i] >= 1 - 1e-12)) {
                        x[i] = x[i] < 0.5 ? 0.0 : 1.0;
                        free[i] = 0;
                    }
            }
        }
        return x;
    }

private:
    // The free shapes' exact minimum with the others held where they are
    // (Cholesky of the free block; a tiny ridge keeps it positive).
    std::vector<double> solve_free(const std::vector<char>& free, const std::vector<double>& x,
                                   const std::vector<double>& c) const {
        std::vector<std::size_t> idx;
        for (std::size_t i = 0; i < n_; ++i)
            if (free[i]) idx.push_back(i);
        const std::size_t m = idx.size();
        std::vector<double> l(m * m, 0.0), rhs(m);
        for (std::size_t r = 0; r < m; ++r) {
            rhs[r] = c[idx[r]];
            for (std::size_t j = 0; j < n_; ++j)
                if (!free[j]) rhs[r] -= g_[idx[r] * n_ + j] * x[j];
        }
        for (std::size_t r = 0; r < m; ++r)
            for (std::size_t k = 0; k <= r; ++k) {
                double s = g_[idx[r] * n_ + idx[k]] + (r == k ? ridge_ : 0.0);
                for (std::size_t p = 0; p < k; ++p) s -= l[r * m + p] * l[k * m + p];
                l[r * m + k] = r == k ? std::sqrt(std::max(s, ridge_)) : s / l[k * m + k];
            }
        std::vector<double> z(m);
        for (std::size_t r = 0; r < m; ++r) {
            double s = rhs[r];
            for (std::size_t p = 0; p < r; ++p) s -= l[r * m + p] * z[p];
            z[r] = s / l[r * m + r];
        }
        for (std::size_t r = m; r-- > 0;) {
            double s = z[r];
            for (std::size_t p = r + 1; p < m; ++p) s -= l[p * m + r] * z[p];
            z[r] = s / l[r * m + r];
        }
        std::vector<double> y = x;
        for (std::size_t r = 0; r < m; ++r) y[idx[r]] = z[r];
        return y;
    }

    const std::vector<FapValues>& a_;
    std::size_t n_;
    std::vector<double> g_;
    double ridge_ = 0;
};

}  // namespace

std::vector<CaptureFrame> capture_frames(const fap::FapStream& stream, const EmotionProfiles& emotions,
                                         const VisemeProfiles& visemes) {
    const fap::FapStream resolved = fap::resolve_untransmitted(stream);
    std::vector<CaptureFrame> out;
    out.reserve(resolved.frames.size());
    for (const fap::FapFrame& f : resolved.frames) {
        const FaceState s = face_state(f, emotions, &visemes);
        out.push_back({s.faps, s.mask, s.aus});
    }
    return out;
}

std::string format_openface_csv(const std::vector<CaptureFrame>& frames, double fps) {
    check_fps(fps, "format_openface_csv");
    std::string out = "frame, face_id, timestamp, confidence, success, gaze_angle_x, gaze_angle_y, pose_Rx, pose_Ry, "
                      "pose_Rz";
    for (int au : kOpenFaceAus) out += fmt::format(", AU{:02}_r", au);
    out += '\n';
    for (std::size_t k = 0; k < frames.size(); ++k) {
        const CaptureFrame& f = frames[k];
        const auto fap = [&](int n) { return f.mask[std::size_t(n - 1)] ? f.faps[std::size_t(n - 1)] : 0.0; };
        // The reader's conventions, inverted (capture_reader.cpp, read_openface).
        out += fmt::format("{}, 0, {:.6f}, 1, 1, {:.6f}, {:.6f}, {:.6f}, {:.6f}, {:.6f}", k + 1,
                           static_cast<double>(k) / fps, 0.5 * (fap(23) + fap(24)) / kFapPerRadian,
                           0.5 * (fap(25) + fap(26)) / kFapPerRadian, fap(48) / kFapPerRadian,
                           -fap(49) / kFapPerRadian, -fap(50) / kFapPerRadian);
        for (int au : kOpenFaceAus) {
            double v = f.aus.mean(au);
            if (au == 45) v = std::max(v, f.aus.mean(43));
            out += fmt::format(", {:.4f}", 5.0 * std::clamp(v, 0.0, 1.0));
        }
        out += '\n';
    }
    return out;
}

std::string format_arkit_csv(const std::vector<CaptureFrame>& frames, double fps, const ArkitShapes& shapes) {
    check_fps(fps, "format_arkit_csv");
    const std::vector<std::string>& names = arkit_shape_names();
    // Live Link Face's columns after the shapes; those arkit.json maps are
    // written from their FAPs, the others (eye roll) as 0.
    static const std::array<const char*, 9> kAngleColumns{"HeadYaw",     "HeadPitch",    "HeadRoll",
                                                          "LeftEyeYaw",  "LeftEyePitch", "LeftEyeRoll",
                                                          "RightEyeYaw", "RightEyePitch", "RightEyeRoll"};
    std::string out = "Timecode,BlendShapeCount";
    for (const std::string& n : names) out += "," + n;
    for (const char* n : kAngleColumns) out += std::string(",") + n;
    out += '\n';
    const ShapeFit fit(shapes);
    for (std::size_t k = 0; k < frames.size(); ++k) {
        const CaptureFrame& f = frames[k];
        // Every low-level FAP counts, those the frame does not transmit at
        // their neutral 0: a shape may not move what the frame keeps still.
        FapValues target{};
        for (int i = 2; i < fap::kFapCount; ++i) target[std::size_t(i)] = f.mask[std::size_t(i)] ? f.faps[std::size_t(i)] : 0.0;
        const std::vector<double> w = fit.fit(target);
        out += fmt::format("{},{}", timecode(static_cast<double>(k) / fps), names.size() + kAngleColumns.size());
        for (double x : w) out += fmt::format(",{:.6f}", x);
        for (const char* column : kAngleColumns) {
            double v = 0;
            for (const ArkitAngle& a : shapes.angles)
                if (a.column == column && f.mask[std::size_t(a.fap - 1)] && a.per_radian != 0)
                    v = f.faps[std::size_t(a.fap - 1)] / a.per_radian;
            out += fmt::format(",{:.6f}", v);
        }
        out += '\n';
    }
    return out;
}

}  // namespace emoface::expression
