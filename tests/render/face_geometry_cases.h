#pragma once
// The default face (half resolution, as the expression tests use), split into
// a skin part with wrinkle frames and the rest without, and a few frames that
// move every stage of the rig: for the geometry bodies' CPU and CUDA tests.
#include <string>
#include <vector>

#include "emoface/expression/default_face.h"
#include "emoface/expression/rig.h"
#include "emoface/render/face_geometry.h"

namespace emoface::render::testing {

inline const expression::Face& face() {
    static const expression::Face f = [] {
        expression::DefaultFaceOptions options;
        options.resolution_scale = 0.5;
        options.texture_size = 64;
        return expression::make_default_face(std::string(EMOFACE_DATA_DIR) + "/face", options);
    }();
    return f;
}

inline const expression::FaceRig& rig() {
    static const expression::FaceRig r(face());
    return r;
}

// Skin triangles (all three vertices skin) with frames; the others without.
inline std::vector<GeometryPart> parts() {
    const expression::Face& f = face();
    std::vector<GeometryPart> out(2);
    out[0].frames = true;
    std::vector<std::vector<int>> local(2, std::vector<int>(f.mesh.n_vertices(), -1));
    for (const auto fh : f.mesh.faces()) {
        int v[3], k = 0;
        for (const auto vh : f.mesh.fv_range(fh))
            if (k < 3) v[k++] = vh.idx();
        bool skin = true;
        for (int i = 0; i < 3; ++i) skin &= f.parts[std::size_t(v[i])] == expression::VertexPart::Skin;
        const int p = skin ? 0 : 1;
        for (int i = 0; i < 3; ++i) {
            int& l = local[std::size_t(p)][std::size_t(v[i])];
            if (l < 0) {
                l = int(out[std::size_t(p)].full_index.size());
                out[std::size_t(p)].full_index.push_back(v[i]);
            }
            out[std::size_t(p)].triangles.push_back(l);
        }
    }
    return out;
}

inline std::array<float, 4> box() {
    const auto& b = face().texture_box;
    return {b.min.x, b.min.y, b.max.x, b.max.y};
}

struct NamedFaps {
    std::string name;
    expression::FapValues faps{};
};

inline std::vector<NamedFaps> frames() {
    std::vector<NamedFaps> out;
    out.push_back({"neutral", {}});
    NamedFaps smile{"smile, brows up"};
    for (int f : {6, 7, 53, 54}) smile.faps[f - 1] = 200;
    for (int f : {31, 32, 33, 34, 35, 36}) smile.faps[f - 1] = 150;
    out.push_back(smile);
    NamedFaps open{"jaw open, lids closed, eyes turned and dilated, head turned"};
    open.faps[3 - 1] = 512;
    open.faps[19 - 1] = open.faps[20 - 1] = 1024;
    open.faps[23 - 1] = open.faps[24 - 1] = 20000;
    open.faps[29 - 1] = open.faps[30 - 1] = 400;
    open.faps[48 - 1] = 15000;
    open.faps[49 - 1] = -20000;
    open.faps[50 - 1] = 8000;
    out.push_back(open);
    NamedFaps all{"every low-level FAP at 100"};
    for (int f = 3; f <= fap::kFapCount; ++f) all.faps[f - 1] = (f % 2 ? 100 : -100);
    out.push_back(all);
    return out;
}

}  // namespace emoface::render::testing
