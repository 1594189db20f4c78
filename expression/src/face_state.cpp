#include "emoface/expression/face_state.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace emoface::expression {
namespace {

constexpr int kN = kEmotionCount;

// Solves the normal equations of the columns in `passive` (Gaussian
// elimination with partial pivoting; at most 6 unknowns).
std::array<double, kN> least_squares(const std::vector<std::array<double, kN>>& a, const std::vector<double>& b,
                                     const std::array<bool, kN>& passive) {
    std::vector<int> cols;
    for (int j = 0; j < kN; ++j)
        if (passive[j]) cols.push_back(j);
    const int m = static_cast<int>(cols.size());
    std::vector<double> ata(m * m, 0.0), atb(m, 0.0);
    for (std::size_t r = 0; r < a.size(); ++r)
        for (int i = 0; i < m; ++i) {
            atb[i] += a[r][cols[i]] * b[r];
            for (int k = 0; k < m; ++k) ata[i * m + k] += a[r][cols[i]] * a[r][cols[k]];
        }
    for (int c = 0; c < m; ++c) {
        int piv = c;
        for (int r = c + 1; r < m; ++r)
            if (std::abs(ata[r * m + c]) > std::abs(ata[piv * m + c])) piv = r;
        if (std::abs(ata[piv * m + c]) < 1e-12) continue;  // dependent column: leave its value 0
        if (piv != c) {
            for (int k = 0; k < m; ++k) std::swap(ata[c * m + k], ata[piv * m + k]);
            std::swap(atb[c], atb[piv]);
        }
        for (int r = 0; r < m; ++r) {
            if (r == c) continue;
            const double f = ata[r * m + c] / ata[c * m + c];
            if (f == 0.0) continue;
            for (int k = 0; k < m; ++k) ata[r * m + k] -= f * ata[c * m + k];
            atb[r] -= f * atb[c];
        }
    }
    std::array<double, kN> x{};
    for (int i = 0; i < m; ++i) x[cols[i]] = std::abs(ata[i * m + i]) < 1e-12 ? 0.0 : atb[i] / ata[i * m + i];
    return x;
}

}  // namespace

const char* mix_source_name(MixSource s) {
    switch (s) {
        case MixSource::None: return "none";
        case MixSource::Expression: return "expression (FAP 2)";
        case MixSource::Fitted: return "fitted to the FAPs";
        case MixSource::Given: return "given";
    }
    return "?";
}

EmotionMix fit_emotion_mix(const FapValues& faps, const std::bitset<fap::kFapCount>& mask,
                           const EmotionProfiles& emotions) {
    std::vector<std::array<double, kN>> a;
    std::vector<double> b;
    for (int f = 3; f <= fap::kFapCount; ++f) {
        if (!mask[f - 1]) continue;
        std::array<double, kN> row{};
        bool used = false;
        for (int e = 0; e < kN; ++e) {
            row[e] = emotions.profiles[e][f - 1];
            used |= row[e] != 0.0;
        }
        if (!used) continue;
        a.push_back(row);
        b.push_back(faps[f - 1]);
    }
    EmotionMix mix;
    if (a.empty()) return mix;

    // Lawson-Hanson active set.
    std::array<double, kN> w{};
    std::array<bool, kN> passive{};
    auto gradient = [&]() {
        std::array<double, kN> g{};
        for (std::size_t r = 0; r < a.size(); ++r) {
            double res = b[r];
            for (int e = 0; e < kN; ++e) res -= a[r][e] * w[e];
            for (int e = 0; e < kN; ++e) g[e] += a[r][e] * res;
        }
        return g;
    };
    double scale = 0.0;
    for (const auto& row : a)
        for (double v : row) scale = std::max(scale, std::abs(v));
    const double tol = 1e-10 * std::max(scale * scale, 1.0) * static_cast<double>(a.size());
    for (int outer = 0; outer < 3 * kN; ++outer) {
        const auto g = gradient();
        int best = -1;
        for (int e = 0; e < kN; ++e)
            if (!passive[e] && g[e] > tol && (best < 0 || g[e] > g[best])) best = e;
        if (best < 0) break;
        passive[best] = true;
        for (int inner = 0; inner < 3 * kN; ++inner) {
            const auto s = least_squares(a, b, passive);
            bool feasible = true;
            for (int e = 0; e < kN; ++e)
                if (passive[e] && s[e] <= 0) feasible = false;
            if (feasible) {
                w = s;
                break;
            }
            double alpha = 1.0;
            for (int e = 0; e < kN; ++e)
                if (passive[e] && s[e] <= 0) alpha = std::min(alpha, w[e] / (w[e] - s[e]));
            for (int e = 0; e < kN; ++e) {
                w[e] += alpha * (s[e] - w[e]);
                if (passive[e] && w[e] <= 1e-12) {
                    passive[e] = false;
                    w[e] = 0.0;
                }
            }
        }
    }
    for (int e = 0; e < kN; ++e) mix.weights[e] = std::clamp(w[e], 0.0, 1.0);
    const double sum = mix.sum();
    if (sum > 1.0)
        for (double& x : mix.weights) x /= sum;
    return mix;
}

FaceState face_state(const EmotionMix& mix, const EmotionProfiles& emotions) {
    FaceState s;
    s.mix = mix;
    s.mix_source = MixSource::Given;
    s.faps = emotions.faps(mix);
    for (int f = 3; f <= fap::kFapCount; ++f)
        for (const FapValues& p : emotions.profiles)
            if (p[f - 1] != 0.0) s.mask[f - 1] = true;
    return s;
}

FaceState face_state(const fap::FapFrame& frame, const EmotionProfiles& emotions, const VisemeProfiles* visemes) {
    FaceState s;
    bool any_low = false, any_mouth = false;
    for (int f = 3; f <= fap::kFapCount; ++f) {
        if (!frame.has(f)) continue;
        s.faps[f - 1] = frame.get(f);
        s.mask[f - 1] = true;
        any_low = true;
        any_mouth |= is_mouth_fap(f);
    }
    if (frame.has(2)) {
        const fap::Expression& x = frame.expression;
        auto add = [&](int code, int intensity) {
            if (code < 1 || code > kN) return;  // 0 neutral; unknown codes ignored
            s.mix.weights[code - 1] += std::clamp(intensity, 0, fap::kMaxIntensity) / double(fap::kMaxIntensity);
        };
        add(x.select1, x.intensity1);
        add(x.select2, x.intensity2);
        const double sum = s.mix.sum();
        if (sum > 1.0)
            for (double& w : s.mix.weights) w /= sum;
        s.mix_source = s.mix.sum() > 0 ? MixSource::Expression : MixSource::None;
        if (!any_low) {
            const FaceState synth = face_state(s.mix, emotions);
            s.faps = synth.faps;
            s.mask = synth.mask;
        }
    } else if (any_low) {
        s.mix = fit_emotion_mix(s.faps, s.mask, emotions);
        s.mix_source = s.mix.sum() > 0 ? MixSource::Fitted : MixSource::None;
    }
    if (frame.has(1)) {
        s.has_viseme = true;
        s.viseme = frame.viseme;
        if (visemes && !any_mouth) {
            const FapValues v = visemes->faps(frame.viseme);
            for (int f = 3; f <= fap::kFapCount; ++f)
                if (v[f - 1] != 0.0) {
                    s.faps[f - 1] += v[f - 1];
                    s.mask[f - 1] = true;
                }
        }
    }
    return s;
}

}  // namespace emoface::expression
