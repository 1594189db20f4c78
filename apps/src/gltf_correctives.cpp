#include "gltf_correctives.h"

#include <algorithm>
#include <cmath>

#include "emoface/common/parallel.h"

namespace emoface::apps::gltf {

namespace {

// The farthest any vertex of `r` (3 per vertex) is from 0.
double farthest(const std::vector<double>& r) {
    double worst = 0;
    for (std::size_t i = 0; i + 2 < r.size(); i += 3) worst = std::max(worst, r[i] * r[i] + r[i + 1] * r[i + 1] + r[i + 2] * r[i + 2]);
    return std::sqrt(worst);
}

}  // namespace

Correctives fit_correctives(const std::vector<int>& vertices, std::vector<std::vector<float>> remainders,
                            int vertex_count, double tolerance, int max_targets) {
    Correctives out;
    const std::size_t poses = remainders.size(), rows = 3 * vertices.size();
    out.weights.assign(poses, {});
    // Doubles for the projections: each target is subtracted from every pose.
    std::vector<std::vector<double>> r(poses);
    for (std::size_t k = 0; k < poses; ++k) {
        r[k].assign(remainders[k].begin(), remainders[k].end());
        std::vector<float>().swap(remainders[k]);
    }
    std::vector<double> off(poses);
    for (;;) {
        parallel_for(int(poses), 16, [&](int b, int e) {
            for (int k = b; k < e; ++k) off[std::size_t(k)] = farthest(r[std::size_t(k)]);
        });
        const auto worst = std::max_element(off.begin(), off.end());
        out.worst_left = worst == off.end() ? 0.0 : *worst;
        if (out.targets.empty()) out.worst_before = out.worst_left;
        if (out.worst_left <= tolerance || static_cast<int>(out.targets.size()) >= max_targets) break;
        // The worst pose's remainder, as a unit direction.
        std::vector<double> q = r[std::size_t(worst - off.begin())];
        double norm = 0;
        for (double x : q) norm += x * x;
        norm = std::sqrt(norm);
        for (double& x : q) x /= norm;
        // Each pose's part along it becomes that pose's weight; the target is
        // the direction at the worst pose's size, so weights stay near 0..1.
        std::vector<float> target(3 * std::size_t(vertex_count), 0.0f);
        for (std::size_t i = 0; i < rows; ++i) target[3 * std::size_t(vertices[i / 3]) + i % 3] = float(q[i] * norm);
        // The weights multiply the float target: project on what is stored.
        std::vector<double> stored(rows);
        double stored2 = 0;
        for (std::size_t i = 0; i < rows; ++i) {
            stored[i] = target[3 * std::size_t(vertices[i / 3]) + i % 3];
            stored2 += stored[i] * stored[i];
        }
        parallel_for(int(poses), 16, [&](int b, int e) {
            for (int k = b; k < e; ++k) {
                std::vector<double>& rk = r[std::size_t(k)];
                double dot = 0;
                for (std::size_t i = 0; i < rows; ++i) dot += stored[i] * rk[i];
                const float w = float(dot / stored2);
                for (std::size_t i = 0; i < rows; ++i) rk[i] -= double(w) * stored[i];
                out.weights[std::size_t(k)].push_back(w);
            }
        });
        out.targets.push_back(std::move(target));
    }
    return out;
}

}  // namespace emoface::apps::gltf
