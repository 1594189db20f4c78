// FaceGeometry's CPU bodies (the twin of the CUDA driver) against the path
// they replace: the sequential rig (FaceRig::deform_reference), OpenMesh's
// vertex normals on the full mesh, the projective wrinkle UVs and
// TangentFrames on each part's own mesh, on the default face in frames that
// move every stage of the rig.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "emoface/common/error.h"
#include "emoface/expression/feature_layout.h"
#include "emoface/render/tangents.h"
#include "face_geometry_cases.h"

namespace emoface::render {
namespace {

using namespace testing;

// The old path's part p: points, normals (from the posed full mesh), UVs, tangents.
struct OldPart {
    std::vector<float> shape, frame;
};

std::vector<OldPart> old_path(const expression::FapValues& faps, const std::vector<GeometryPart>& parts) {
    expression::TriMesh full = face().mesh;
    expression::FaceRig::write_to(rig().deform_reference(faps), full);
    std::vector<OldPart> out;
    for (const GeometryPart& gp : parts) {
        expression::TriMesh m;
        m.request_vertex_normals();
        for (int v : gp.full_index) {
            const auto vh = m.add_vertex(full.point(full.vertex_handle(v)));
            m.set_normal(vh, full.normal(full.vertex_handle(v)));
        }
        for (std::size_t t = 0; t < gp.triangles.size(); t += 3)
            m.add_face(m.vertex_handle(gp.triangles[t]), m.vertex_handle(gp.triangles[t + 1]),
                       m.vertex_handle(gp.triangles[t + 2]));
        OldPart o;
        std::vector<glm::vec2> uvs;
        for (std::size_t i = 0; i < gp.full_index.size(); ++i) {
            const auto p = m.point(m.vertex_handle(int(i)));
            const auto n = m.normal(m.vertex_handle(int(i)));
            o.shape.insert(o.shape.end(), {p[0], p[1], p[2], n[0], n[1], n[2]});
            uvs.push_back(expression::project_to_texture(glm::vec3(p[0], p[1], p[2]), face().texture_box));
        }
        if (gp.frames) {
            TangentFrames frames;
            frames.compute(m, uvs);
            for (std::size_t i = 0; i < uvs.size(); ++i) {
                const glm::vec4 t = frames.tangents()[i];
                o.frame.insert(o.frame.end(), {t.x, t.y, t.z, t.w, uvs[i].x, uvs[i].y});
            }
        }
        out.push_back(std::move(o));
    }
    return out;
}

// The largest difference of each of the 6 floats of a vertex record, over
// all vertices; and how many vertices differ by more than `tolerance` in any.
struct Diff {
    float worst[6] = {};
    int over = 0;
};
Diff compare(const std::vector<float>& a, const std::vector<float>& b, float tolerance) {
    Diff d;
    for (std::size_t v = 0; v + 6 <= a.size(); v += 6) {
        bool over = false;
        for (int c = 0; c < 6; ++c) {
            const float e = std::fabs(a[v + std::size_t(c)] - b[v + std::size_t(c)]);
            d.worst[c] = std::max(d.worst[c], e);
            over |= !(e <= tolerance);
        }
        d.over += over;
    }
    return d;
}

TEST(FaceGeometry, CpuBodiesMatchTheRigOpenMeshNormalsAndTangentFrames) {
    const std::vector<GeometryPart> parts = testing::parts();
    ASSERT_GT(parts[0].full_index.size(), 1000u);
    FaceGeometry geometry(rig(), face().mesh, parts, box());
    std::vector<std::vector<float>> shape, frame;
    for (const NamedFaps& f : frames()) {
        geometry.compute(rig().frame(f.faps), shape, frame);
        const std::vector<OldPart> old = old_path(f.faps, parts);
        for (std::size_t p = 0; p < parts.size(); ++p) {
            ASSERT_EQ(shape[p].size(), old[p].shape.size());
            // Positions and normals: the same arithmetic but FMA contraction
            // and the order of a vertex's face normals in the sum.
            const Diff s = compare(shape[p], old[p].shape, 1e-4f);
            EXPECT_EQ(s.over, 0) << f.name << ", part " << p << ": worst position " << s.worst[0] << " "
                                 << s.worst[1] << " " << s.worst[2] << ", normal " << s.worst[3] << " "
                                 << s.worst[4] << " " << s.worst[5];
            ASSERT_EQ(frame[p].size(), old[p].frame.size());
            if (frame[p].empty()) continue;
            // Tangents: a normal a few ulps off moves a tangent as much; a
            // vertex whose corners nearly cancel may turn further, so a
            // handful may differ by more than 1e-3 (its w too).
            const Diff t = compare(frame[p], old[p].frame, 1e-3f);
            EXPECT_LE(t.over, int(frame[p].size() / 6 / 10000) + 2) << f.name << ": tangents";
            EXPECT_LE(std::max(t.worst[4], t.worst[5]), 1e-5f) << f.name << ": UVs";
        }
    }
}

TEST(FaceGeometry, RefusesPartsThatAreNotTheMeshs) {
    std::vector<GeometryPart> parts = testing::parts();
    parts[1].full_index.push_back(int(face().mesh.n_vertices()));
    EXPECT_THROW(FaceGeometry(rig(), face().mesh, parts, box()), Error);
}

}  // namespace
}  // namespace emoface::render
