// The default face's baked occlusion (face_occlusion.h) against the plain
// whole-mesh bake (ambient_occlusion.h): the lips' inner faces, closed on
// each other at rest, are baked open enough to show lit when the mouth
// opens; the mouth interior is shaded by its depth behind the lips (front
// teeth light, molars and the cavity's back dim, none black); skin away from
// the mouth keeps the plain bake.
#include <algorithm>
#include <vector>

#include <glm/vec3.hpp>
#include <gtest/gtest.h>

#include "emoface/expression/default_face.h"
#include "emoface/fap/feature_points.h"
#include "emoface/render/ambient_occlusion.h"
#include "emoface/render/face_occlusion.h"

namespace {

namespace ex = emoface::expression;
using emoface::render::bake_face_occlusion;
using emoface::render::bake_vertex_occlusion;

struct Baked {
    ex::Face face;
    ex::TriMesh mesh;
    std::vector<float> plain, mouth_aware;
};

const Baked& baked() {
    static const Baked b = [] {
        Baked r;
        ex::DefaultFaceOptions options;
        options.resolution_scale = 0.5;
        options.texture_size = 64;
        r.face = ex::make_default_face(std::string(EMOFACE_DATA_DIR) + "/face", options);
        r.mesh = r.face.mesh;
        r.mesh.request_vertex_normals();
        r.mesh.request_face_normals();
        r.mesh.update_normals();
        std::vector<glm::vec3> positions, normals;
        for (const auto vh : r.mesh.vertices()) {
            const auto& p = r.mesh.point(vh);
            const auto& n = r.mesh.normal(vh);
            positions.push_back({p[0], p[1], p[2]});
            normals.push_back({n[0], n[1], n[2]});
        }
        std::vector<unsigned> triangles;
        for (const auto fh : r.mesh.faces())
            for (const auto vh : r.mesh.fv_range(fh)) triangles.push_back(unsigned(vh.idx()));
        r.plain = bake_vertex_occlusion(positions, normals, triangles);
        r.mouth_aware = bake_face_occlusion(r.mesh, r.face);
        return r;
    }();
    return b;
}

int vertex_of(const char* id) {
    return baked().face.feature_points[std::size_t(emoface::fap::feature_point_index(id))].vertex;
}

TEST(FaceOcclusion, InnerLipsAreBakedAsIfTheMouthWereOpen) {
    const Baked& b = baked();
    // The inner lip contour: where the lips touch at rest.
    for (const char* id : {"2.2", "2.3", "2.6", "2.7", "2.8", "2.9"}) {
        const int v = vertex_of(id);
        ASSERT_GE(v, 0) << id;
        const float plain = b.plain[std::size_t(v)], aware = b.mouth_aware[std::size_t(v)];
        // Measured: plain 0.07-0.18, aware 0.31-0.80.
        EXPECT_GE(aware, plain + 0.15f) << id;
        EXPECT_GE(aware, 0.3f) << id;
    }
}

TEST(FaceOcclusion, MouthInteriorDimsWithDepthButIsNotBlack) {
    const Baked& b = baked();
    const float incisor = b.mouth_aware[std::size_t(vertex_of("9.10"))];
    float deepest = 1.0f, back_z = 1e9f, back = 0.0f;
    for (std::size_t v = 0; v < b.face.parts.size(); ++v) {
        const auto part = b.face.parts[v];
        if (part != ex::VertexPart::MouthUpper && part != ex::VertexPart::MouthLower && part != ex::VertexPart::Tongue)
            continue;
        deepest = std::min(deepest, b.mouth_aware[v]);
        const float z = b.mesh.point(b.mesh.vertex_handle(int(v)))[2];
        if (z < back_z) {
            back_z = z;
            back = b.mouth_aware[v];
        }
    }
    // The upper incisors' edge, 6 mm behind the lips, stays nearly open;
    // the back of the cavity (behind the tongue) is dim, nothing is black.
    EXPECT_GT(incisor, 0.8f);
    EXPECT_LT(back, 0.5f * incisor);
    EXPECT_GE(deepest, 0.08f);
}

TEST(FaceOcclusion, SkinAwayFromTheMouthKeepsThePlainBake) {
    const Baked& b = baked();
    for (const char* id : {"9.3", "4.1", "4.2", "3.13", "2.1"}) {
        const int v = vertex_of(id);
        ASSERT_GE(v, 0) << id;
        EXPECT_EQ(b.mouth_aware[std::size_t(v)], b.plain[std::size_t(v)]) << id;
    }
}

}  // namespace
