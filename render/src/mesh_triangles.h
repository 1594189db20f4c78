#pragma once
// The mesh's triangles as a flat index list (three vertex indices a face),
// as the geometry passes on the CPU and the GPU read them; faces that are not
// triangles are skipped (a face mesh has none).
#include <vector>

#include "emoface/expression/mesh.h"

namespace emoface::render {

inline std::vector<int> triangle_indices(const expression::TriMesh& mesh) {
    std::vector<int> triangles;
    triangles.reserve(mesh.n_faces() * 3);
    for (const auto fh : mesh.faces()) {
        int idx[3], k = 0;
        for (const auto vh : mesh.fv_range(fh)) {
            if (k < 3) idx[k] = vh.idx();
            ++k;
        }
        if (k == 3) triangles.insert(triangles.end(), idx, idx + 3);
    }
    return triangles;
}

}  // namespace emoface::render
