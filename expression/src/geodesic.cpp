#include "geodesic.h"

#include <cmath>
#include <functional>
#include <limits>

namespace emoface::expression::detail {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// The distance at c of a planar front that is at distance ta at a and tb at
// b (a triangle's corners), or infinity when the front's ray to c does not
// cross the edge ab (then the edges carry the distance).
double front_through(const std::array<float, 3>& c, const std::array<float, 3>& a, const std::array<float, 3>& b,
                     double ta, double tb) {
    double ea[3], eb[3];
    for (int k = 0; k < 3; ++k) ea[k] = double(a[k]) - c[k], eb[k] = double(b[k]) - c[k];
    const double g00 = ea[0] * ea[0] + ea[1] * ea[1] + ea[2] * ea[2];
    const double g01 = ea[0] * eb[0] + ea[1] * eb[1] + ea[2] * eb[2];
    const double g11 = eb[0] * eb[0] + eb[1] * eb[1] + eb[2] * eb[2];
    const double det = g00 * g11 - g01 * g01;
    if (!(det > 1e-12 * g00 * g11)) return kInfinity;
    // The front's gradient g in the triangle's plane has g.ea = ta - t and
    // g.eb = tb - t; |g| = 1 is a quadratic in t (the inverse Gram matrix
    // Q turns the two projections into g's length).
    const double q00 = g11 / det, q01 = -g01 / det, q11 = g00 / det;
    const double alpha = q00 + 2 * q01 + q11;
    const double beta = (q00 + q01) * ta + (q01 + q11) * tb;
    const double gamma = q00 * ta * ta + 2 * q01 * ta * tb + q11 * tb * tb - 1.0;
    const double disc = beta * beta - alpha * gamma;
    if (!(alpha > 0) || disc < 0) return kInfinity;
    const double t = (beta + std::sqrt(disc)) / alpha;
    // Upwind: the front reaches c from inside the triangle, i.e. -g is a
    // non-negative mix of the edges to a and b.
    const double la = q00 * (ta - t) + q01 * (tb - t), lb = q01 * (ta - t) + q11 * (tb - t);
    if (la > 0 || lb > 0 || t < std::max(ta, tb)) return kInfinity;
    return t;
}

}  // namespace

GeodesicGraph::GeodesicGraph(const TriMesh& mesh, const std::vector<std::array<int, 2>>& welded) {
    const int n = static_cast<int>(mesh.n_vertices());
    point_.resize(n);
    for (int v = 0; v < n; ++v) {
        const auto p = mesh.point(TriMesh::VertexHandle(v));
        point_[v] = {p[0], p[1], p[2]};
    }
    start_.assign(n + 1, 0);
    for (auto eh : mesh.edges()) {
        const auto h = mesh.halfedge_handle(eh, 0);
        ++start_[mesh.from_vertex_handle(h).idx() + 1];
        ++start_[mesh.to_vertex_handle(h).idx() + 1];
    }
    for (const auto& w : welded) {
        ++start_[w[0] + 1];
        ++start_[w[1] + 1];
    }
    for (int v = 0; v < n; ++v) start_[v + 1] += start_[v];
    neighbour_.resize(start_[n]);
    length_.resize(start_[n]);
    std::vector<int> fill(start_.begin(), start_.end() - 1);
    for (auto eh : mesh.edges()) {
        const auto h = mesh.halfedge_handle(eh, 0);
        const int a = mesh.from_vertex_handle(h).idx(), b = mesh.to_vertex_handle(h).idx();
        const double l = (mesh.point(TriMesh::VertexHandle(a)) - mesh.point(TriMesh::VertexHandle(b))).norm();
        neighbour_[fill[a]] = b;
        length_[fill[a]++] = l;
        neighbour_[fill[b]] = a;
        length_[fill[b]++] = l;
    }
    for (const auto& w : welded) {
        neighbour_[fill[w[0]]] = w[1];
        length_[fill[w[0]]++] = 0.0;
        neighbour_[fill[w[1]]] = w[0];
        length_[fill[w[1]]++] = 0.0;
    }
    corner_start_.assign(n + 1, 0);
    for (auto f : mesh.faces())
        for (auto v : mesh.fv_range(f)) ++corner_start_[v.idx() + 1];
    for (int v = 0; v < n; ++v) corner_start_[v + 1] += corner_start_[v];
    opposite_.resize(corner_start_[n]);
    std::vector<int> at(corner_start_.begin(), corner_start_.end() - 1);
    for (auto f : mesh.faces()) {
        std::array<int, 3> t{};
        int i = 0;
        for (auto v : mesh.fv_range(f)) t[i++] = v.idx();
        for (int k = 0; k < 3; ++k) opposite_[at[t[k]]++] = {t[(k + 1) % 3], t[(k + 2) % 3]};
    }
    dist_.assign(n, kInfinity);
    done_.assign(n, 0);
}

std::vector<std::pair<int, double>> GeodesicGraph::within(const std::vector<int>& sources, double radius) {
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    std::vector<int> touched;
    auto reach = [&](int w, double d) {
        if (d > radius || d >= dist_[w]) return;
        if (dist_[w] == kInfinity) touched.push_back(w);
        dist_[w] = d;
        queue.push({d, w});
    };
    for (int s : sources)
        if (s >= 0 && s < static_cast<int>(dist_.size())) reach(s, 0.0);
    std::vector<std::pair<int, double>> out;
    while (!queue.empty()) {
        const auto [d, v] = queue.top();
        queue.pop();
        if (done_[v] || d > dist_[v]) continue;
        done_[v] = 1;
        out.emplace_back(v, d);
        for (int k = start_[v]; k < start_[v + 1]; ++k)
            if (!done_[neighbour_[k]]) reach(neighbour_[k], d + length_[k]);
        // Triangles with v and one more vertex done carry the front on to
        // their third.
        for (int k = corner_start_[v]; k < corner_start_[v + 1]; ++k) {
            const auto [a, b] = opposite_[k];
            if (done_[a] == done_[b]) continue;
            const int known = done_[a] ? a : b, next = done_[a] ? b : a;
            reach(next, front_through(point_[next], point_[v], point_[known], d, dist_[known]));
        }
    }
    for (int v : touched) dist_[v] = kInfinity, done_[v] = 0;
    return out;
}

}  // namespace emoface::expression::detail
