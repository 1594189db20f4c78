#include "gltf_parts.h"

#include <numeric>

namespace emoface::apps::gltf {

namespace {

enum Part { kSkin, kEyes, kTeeth, kMouth, kLashes, kPartCount };

// Roughness: wet surfaces (the cornea's tear film, enamel, mucosa) are glossy,
// skin's stratum corneum scatters more, lashes are dull keratin strands.
const PartMaterial kMaterials[kPartCount] = {
    {"skin", 0.6, "skin: dry stratum corneum, a broad soft highlight", {}},
    {"eyes", 0.05, "eyes: the tear film over the cornea and sclera, a sharp highlight", {}},
    {"teeth", 0.25, "teeth and gums: wet enamel and mucosa", {}},
    {"mouth", 0.35, "mouth interior and tongue: wet mucosa", {}},
    {"lashes", 0.7, "lashes: dull hair", {}},
};

int find(std::vector<int>& up, int v) {
    while (up[v] != v) v = up[v] = up[up[v]];
    return v;
}

}  // namespace

std::vector<PartMaterial> split_into_parts(const expression::Face& face, const expression::RigView& rig) {
    using expression::VertexPart;
    const int nv = face.vertex_count();
    std::vector<std::array<int, 3>> tris;
    for (auto f : face.mesh.faces()) {
        std::array<int, 3> t{};
        int i = 0;
        for (auto v : face.mesh.fv_range(f))
            if (i < 3) t[i++] = v.idx();
        tris.push_back(t);
    }
    auto is_mouth = [&](int v) {
        return face.parts[v] == VertexPart::MouthUpper || face.parts[v] == VertexPart::MouthLower;
    };
    // Connected pieces of the mouth's parts; per part, the largest is the cavity.
    std::vector<int> up(nv);
    std::iota(up.begin(), up.end(), 0);
    for (const auto& t : tris)
        if (is_mouth(t[0]) && face.parts[t[1]] == face.parts[t[0]] && face.parts[t[2]] == face.parts[t[0]])
            for (int k = 1; k < 3; ++k) up[find(up, t[k])] = find(up, t[0]);
    std::vector<int> size(nv, 0);
    for (int v = 0; v < nv; ++v)
        if (is_mouth(v)) ++size[find(up, v)];
    int cavity[2] = {-1, -1};  // upper, lower
    for (int v = 0; v < nv; ++v) {
        if (!is_mouth(v) || find(up, v) != v) continue;
        int& c = cavity[face.parts[v] == VertexPart::MouthUpper ? 0 : 1];
        if (c < 0 || size[v] > size[c]) c = v;
    }

    std::vector<PartMaterial> parts(std::begin(kMaterials), std::end(kMaterials));
    for (const auto& t : tris) {
        Part p = kSkin;
        const bool lash = rig.lash_anchor && (rig.lash_anchor[t[0]] >= 0 || rig.lash_anchor[t[1]] >= 0 ||
                                              rig.lash_anchor[t[2]] >= 0);
        switch (face.parts[t[0]]) {
            case VertexPart::Skin: p = lash ? kLashes : kSkin; break;
            case VertexPart::EyeballLeft:
            case VertexPart::EyeballRight: p = kEyes; break;
            case VertexPart::MouthUpper:
            case VertexPart::MouthLower: {
                const int root = find(up, t[0]);
                p = root == cavity[0] || root == cavity[1] ? kMouth : kTeeth;
                break;
            }
            case VertexPart::Tongue: p = kMouth; break;
        }
        for (int v : t) parts[p].triangles.push_back(static_cast<std::uint32_t>(v));
    }
    std::vector<PartMaterial> out;
    for (auto& p : parts)
        if (!p.triangles.empty()) out.push_back(std::move(p));
    return out;
}

}  // namespace emoface::apps::gltf
