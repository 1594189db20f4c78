#pragma once
// Distances along a mesh's edges (Dijkstra), bounded by a radius. The rig
// measures influence with them so that kernels stop at slits (the closed
// mouth, the eye openings) that Euclidean distance would jump.
#include <array>
#include <queue>
#include <utility>
#include <vector>

#include "emoface/expression/mesh.h"

namespace emoface::expression::detail {

class GeodesicGraph {
public:
    // `welded` pairs are joined by zero-length edges (UV seams).
    explicit GeodesicGraph(const TriMesh& mesh, const std::vector<std::array<int, 2>>& welded = {});

    // (vertex, distance) for every vertex within `radius` of the nearest source.
    std::vector<std::pair<int, double>> within(const std::vector<int>& sources, double radius);

private:
    std::vector<int> start_;
    std::vector<int> neighbour_;
    std::vector<double> length_;
    std::vector<double> dist_;  // scratch, infinity between calls
};

}  // namespace emoface::expression::detail
