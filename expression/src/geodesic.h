#pragma once
// Distances along a mesh's surface, bounded by a radius. The rig measures
// influence with them so that kernels stop at slits (the closed mouth, the
// eye openings) that Euclidean distance would jump.
//
// Fast marching over the triangles (Kimmel and Sethian 1998): a vertex's
// distance comes from a planar front crossing a triangle whose other two
// vertices are done, or along an edge where no triangle gives a front.
// Shortest paths along edges alone (Dijkstra) measure a grid mesh in its
// edge directions: their distance bends along every line of edges through
// the source, and a bell over it creased the skin there (joy's cheek: a
// ridge down the vertical edge line through the cheek point).
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
    std::vector<std::array<float, 3>> point_;
    std::vector<int> start_;
    std::vector<int> neighbour_;
    std::vector<double> length_;
    // Per vertex, the triangles round it as the pairs of their other two
    // vertices (CSR by vertex).
    std::vector<int> corner_start_;
    std::vector<std::array<int, 2>> opposite_;
    std::vector<double> dist_;  // scratch, infinity between calls
    std::vector<char> done_;    // scratch, 0 between calls
};

}  // namespace emoface::expression::detail
