#include "geodesic.h"

#include <functional>
#include <limits>

namespace emoface::expression::detail {

GeodesicGraph::GeodesicGraph(const TriMesh& mesh, const std::vector<std::array<int, 2>>& welded) {
    const int n = static_cast<int>(mesh.n_vertices());
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
    dist_.assign(n, std::numeric_limits<double>::infinity());
}

std::vector<std::pair<int, double>> GeodesicGraph::within(const std::vector<int>& sources, double radius) {
    using Item = std::pair<double, int>;
    std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
    std::vector<int> touched;
    for (int s : sources) {
        if (s < 0 || s >= static_cast<int>(dist_.size())) continue;
        if (dist_[s] > 0) {
            if (dist_[s] == std::numeric_limits<double>::infinity()) touched.push_back(s);
            dist_[s] = 0;
            queue.push({0.0, s});
        }
    }
    std::vector<std::pair<int, double>> out;
    while (!queue.empty()) {
        const auto [d, v] = queue.top();
        queue.pop();
        if (d > dist_[v]) continue;
        out.emplace_back(v, d);
        for (int k = start_[v]; k < start_[v + 1]; ++k) {
            const int w = neighbour_[k];
            const double nd = d + length_[k];
            if (nd > radius || nd >= dist_[w]) continue;
            if (dist_[w] == std::numeric_limits<double>::infinity()) touched.push_back(w);
            dist_[w] = nd;
            queue.push({nd, w});
        }
    }
    for (int v : touched) dist_[v] = std::numeric_limits<double>::infinity();
    return out;
}

}  // namespace emoface::expression::detail
