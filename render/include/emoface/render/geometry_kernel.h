#pragma once
// Vertex normals, wrinkle UVs and tangent frames of a deformed mesh: the one
// body that TangentFrames (CPU, all cores) and the CUDA geometry driver
// (gpu_geometry.h) both run. Plain float structs, no glm, so that it
// compiles as CUDA device code; the arithmetic follows what it replaced step
// for step (OpenMesh's normals, tangents.h's MikkTSpace-style frames).
#include <cfloat>
#include <cmath>

#include "emoface/common/hd.h"

// A vertex's gathers loop over its faces; a fan's pole has hundreds (274 on
// the default head). On the GPU such a vertex's gathers are shared by a
// warp (face_geometry.cu); unrolled, a thread has the loads of several
// faces in flight at once.
#if defined(__CUDA_ARCH__)
#define EMOFACE_GATHER_UNROLL _Pragma("unroll 8")
#else
#define EMOFACE_GATHER_UNROLL
#endif

namespace emoface::render::geometry_kernel {

struct V2 {
    float x, y;
};
struct V3 {
    float x, y, z;
};
struct V4 {
    float x, y, z, w;
};

EMOFACE_HD EMOFACE_INLINE V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
EMOFACE_HD EMOFACE_INLINE V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
EMOFACE_HD EMOFACE_INLINE V3 operator*(V3 a, float s) { return {a.x * s, a.y * s, a.z * s}; }
EMOFACE_HD EMOFACE_INLINE V3 operator*(float s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
EMOFACE_HD EMOFACE_INLINE V3 operator/(V3 a, float s) { return {a.x / s, a.y / s, a.z / s}; }
EMOFACE_HD EMOFACE_INLINE V2 operator-(V2 a, V2 b) { return {a.x - b.x, a.y - b.y}; }
EMOFACE_HD EMOFACE_INLINE float dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
EMOFACE_HD EMOFACE_INLINE float dot(V2 a, V2 b) { return a.x * b.x + a.y * b.y; }
EMOFACE_HD EMOFACE_INLINE V3 cross(V3 a, V3 b) {
    return {a.y * b.z - b.y * a.z, a.z * b.x - b.z * a.x, a.x * b.y - b.x * a.y};
}
// v scaled to unit length (as glm::normalize: times the inverse root).
EMOFACE_HD EMOFACE_INLINE V3 normalize(V3 v) { return v * (1.0f / sqrtf(dot(v, v))); }
// The component of v perpendicular to the unit vector n.
EMOFACE_HD EMOFACE_INLINE V3 reject(V3 v, V3 n) { return v - n * dot(n, v); }
// Finite and longer than sqrt(min_length2) (NaN fails both tests).
EMOFACE_HD EMOFACE_INLINE bool usable(V3 v, float min_length2) {
    const float l2 = dot(v, v);
    return l2 > min_length2 && l2 <= FLT_MAX;
}

// A UV triangle whose edges are nearly parallel (sine of their angle below
// this) has no usable tangent direction: MikkTSpace's "degenerate" faces.
constexpr float kMinUvSine = 1e-6f;
constexpr float kMinLength2 = 1e-24f;

// acos to within 7e-5 rad (Abramowitz and Stegun 4.4.45): the angle only
// weights a corner's share, and acos is the loop's largest cost.
EMOFACE_HD EMOFACE_INLINE float fast_acos(float x) {
    x = fminf(fmaxf(x, -1.0f), 1.0f);
    const float a = fabsf(x);
    float r = ((-0.0187293f * a + 0.0742610f) * a - 0.2121144f) * a + 1.5707288f;
    r *= sqrtf(1.0f - a);
    return x < 0 ? 3.14159265358979323846f - r : r;
}

// Any unit vector perpendicular to the unit vector n.
EMOFACE_HD EMOFACE_INLINE V3 any_perpendicular(V3 n) {
    const V3 axis = fabsf(n.x) < 0.9f ? V3{1, 0, 0} : V3{0, 1, 0};
    return normalize(cross(cross(n, axis), n));
}

// The unit normal of triangle (p0, p1, p2), zero when it has no area
// (OpenMesh's calc_face_normal).
EMOFACE_HD EMOFACE_INLINE V3 face_normal(V3 p0, V3 p1, V3 p2) {
    const V3 n = cross(p2 - p1, p0 - p1);
    const float length = sqrtf(dot(n, n));
    return length != 0.0f ? n * (1.0f / length) : V3{0, 0, 0};
}

// A sum of face normals made unit (OpenMesh's calc_vertex_normal).
EMOFACE_HD EMOFACE_INLINE V3 unit_normal(V3 sum) {
    const float length = sqrtf(dot(sum, sum));
    return length != 0.0f ? sum * (1.0f / length) : sum;
}

// The projective layout's wrinkle UV: the point in the face's texture box,
// v down from its top (expression::project_to_texture).
EMOFACE_HD EMOFACE_INLINE V2 project_to_box(V3 p, const float box[4]) {
    return {(p.x - box[0]) / (box[2] - box[0]), (box[3] - p.y) / (box[3] - box[1])};
}

// A triangle's dp/du and dp/dv (up to a positive factor) and its corner
// angles; ok false (t = b = 0) for a face without a usable frame.
struct FaceFrame {
    V3 t, b;
    float angle[3];
    bool ok;
};

EMOFACE_HD EMOFACE_INLINE FaceFrame face_frame(const V3 p[3], const V2 uv[3]) {
    FaceFrame f{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, false};
    const V3 e1 = p[1] - p[0], e2 = p[2] - p[0];
    const V2 d1 = uv[1] - uv[0], d2 = uv[2] - uv[0];
    const float det = d1.x * d2.y - d2.x * d1.y;
    const float uv_scale = sqrtf(dot(d1, d1) * dot(d2, d2));
    if (!(fabsf(det) > kMinUvSine * uv_scale)) return f;  // also rejects NaN UVs
    const float s = det > 0 ? 1.0f : -1.0f;
    const V3 t = (e1 * d2.y - e2 * d1.y) * s;
    const V3 b = (e2 * d1.x - e1 * d2.x) * s;
    if (!usable(t, kMinLength2) || !usable(b, kMinLength2)) return f;
    V3 edge[3] = {p[1] - p[0], p[2] - p[1], p[0] - p[2]};
    for (int c = 0; c < 3; ++c) {
        const float l2 = dot(edge[c], edge[c]);
        if (!(l2 > kMinLength2)) return f;  // a zero-length edge: no corner angles
        edge[c] = edge[c] / sqrtf(l2);
    }
    f.t = t;
    f.b = b;
    f.ok = true;
    // Corner c lies between the edge leaving it and the one arriving.
    for (int c = 0; c < 3; ++c) f.angle[c] = fast_acos(-dot(edge[c], edge[(c + 2) % 3]));
    return f;
}

// A vertex's tangent gather, summed over its corners k = lane, lane +
// lanes, ... below count (lanes > 1: one share of a gather split over
// several threads, the shares added after; lanes = 1: the whole gather).
struct TangentSum {
    V3 t, b;  // handedness-signed tangents and bitangents, angle-weighted
    float w;  // angle-weighted handedness
};

EMOFACE_HD EMOFACE_INLINE TangentSum operator+(TangentSum a, TangentSum b) { return {a.t + b.t, a.b + b.b, a.w + b.w}; }

// The unit normal a frame is built around, from the vertex normal `nv`
// (any length); *has_normal false where it has none.
EMOFACE_HD EMOFACE_INLINE V3 frame_normal(V3 nv, bool* has_normal) {
    *has_normal = usable(nv, kMinLength2);
    return *has_normal ? nv / sqrtf(dot(nv, nv)) : V3{0, 0, 1};
}

// corner(k, t, b, angle) gives the k-th corner's face t and b and the
// corner's angle, for k < count; nn from frame_normal().
template <class Corner>
EMOFACE_HD EMOFACE_INLINE TangentSum tangent_gather(V3 nn, int count, const Corner& corner, int lane, int lanes) {
    TangentSum s{{0, 0, 0}, {0, 0, 0}, 0.0f};
    EMOFACE_GATHER_UNROLL
    for (int k = lane; k < count; k += lanes) {
        V3 ft, fb;
        float angle;
        corner(k, ft, fb, angle);
        V3 t = reject(ft, nn), bt = reject(fb, nn);
        const float lt = dot(t, t), lb = dot(bt, bt);
        if (!(lt > kMinLength2) || !(lb > kMinLength2)) continue;
        t = t / sqrtf(lt);
        bt = bt / sqrtf(lb);
        // Handedness of this corner. Accumulating w*T instead of T keeps
        // the tangents of mirrored halves (u runs the other way) from
        // cancelling where they meet; the vertex then takes the dominant w.
        const float w = dot(cross(nn, t), bt) < 0 ? -1.0f : 1.0f;
        s.t = s.t + (angle * w) * t;
        s.b = s.b + angle * bt;
        s.w += angle * w;
    }
    return s;
}

// The tangent (xyz, handedness w) from a vertex's whole gather; *fallback
// says whether the vertex had no usable direction of its own.
EMOFACE_HD EMOFACE_INLINE V4 tangent_finish(V3 nn, const TangentSum& s, bool* fallback) {
    const float w = s.w < 0 ? -1.0f : 1.0f;
    V3 t = reject(s.t, nn);
    *fallback = false;
    if (usable(t, kMinLength2)) {
        t = w * normalize(t);
    } else {
        *fallback = true;
        const V3 b = reject(s.b, nn);
        // B = w cross(N, T) for an orthonormal frame, hence T = w cross(B, N).
        t = usable(b, kMinLength2) ? w * normalize(cross(b, nn)) : any_perpendicular(nn);
    }
    return {t.x, t.y, t.z, usable(t, kMinLength2) ? w : 1.0f};
}

// The tangent frame of a vertex with normal `nv` (any length) from its
// `count` corners (tangent_gather's corner), in one thread.
template <class Corner>
EMOFACE_HD EMOFACE_INLINE V4 vertex_tangent(V3 nv, int count, const Corner& corner, bool* fallback) {
    bool has_normal = false;
    const V3 nn = frame_normal(nv, &has_normal);
    return tangent_finish(nn, tangent_gather(nn, has_normal ? count : 0, corner, 0, 1), fallback);
}

// Flat arrays of the topology, host or device pointers alike (one layout
// for both bodies' drivers).
struct GeometryView {
    int full_vertices = 0, part_vertices = 0;  // part vertices: all parts one after the other
    const int* triangles = nullptr;            // full mesh, 3 per face
    const int* vertex_face_start = nullptr;    // full_vertices + 1
    const int* vertex_faces = nullptr;
    const int* part_full = nullptr;            // per part vertex: its full vertex
    const int* part_of = nullptr;              // per part vertex: its part
    const int* part_first = nullptr;           // per part: its first part vertex
    const int* part_triangles = nullptr;       // all parts' triangles, in part vertices (global numbering)
    const int* corner_start = nullptr;         // per part vertex + 1: its corners (3 x triangle + corner)
    const int* corners = nullptr;
    const unsigned char* part_frames = nullptr;  // per part: 1 = UVs and tangents per frame
    const float* fixed_uvs = nullptr;          // 2 per part vertex (anchored layout), or null: projected
    float box[4] = {0, 0, 1, 1};               // texture box min.x, min.y, max.x, max.y
};

// Three passes, each a body per item, so that no item's work grows with its
// valence beyond a gather (a fan's pole has hundreds of faces):
//   rig:        each full vertex's position (expression/rig_kernel.h);
//   faces:      each full-mesh face's unit normal (face_pass), and each part
//               triangle's frame (part_triangle_pass);
//   vertices:   each part vertex's normal (its full-mesh faces' normals
//               summed, OpenMesh's), wrinkle UV and tangent frame
//               (part_vertex_pass).
EMOFACE_HD EMOFACE_INLINE V3 at(const float* pos, int v) { return {pos[3 * v], pos[3 * v + 1], pos[3 * v + 2]}; }

EMOFACE_HD EMOFACE_INLINE V2 wrinkle_uv(const GeometryView& g, const float* pos, int pv) {
    if (g.fixed_uvs) return {g.fixed_uvs[2 * pv], g.fixed_uvs[2 * pv + 1]};
    return project_to_box(at(pos, g.part_full[pv]), g.box);
}

// Full-mesh face f's unit normal.
EMOFACE_HD EMOFACE_INLINE V3 face_pass(const GeometryView& g, const float* pos, int f) {
    const int* t = g.triangles + 3 * f;
    return face_normal(at(pos, t[0]), at(pos, t[1]), at(pos, t[2]));
}

// Part triangle t's frame (all parts' triangles numbered together).
EMOFACE_HD EMOFACE_INLINE FaceFrame part_triangle_pass(const GeometryView& g, const float* pos, int t) {
    const int* tri = g.part_triangles + 3 * t;
    const V3 p[3] = {at(pos, g.part_full[tri[0]]), at(pos, g.part_full[tri[1]]), at(pos, g.part_full[tri[2]])};
    const V2 uv[3] = {wrinkle_uv(g, pos, tri[0]), wrinkle_uv(g, pos, tri[1]), wrinkle_uv(g, pos, tri[2])};
    return face_frame(p, uv);
}

// Part vertex pv's two gathers, each summed over its share k = lane, lane +
// lanes, ... (on the GPU a vertex of hundreds of faces, a fan's pole, is
// split over a warp; every other vertex, and the CPU, take lanes = 1).
// First its full-mesh faces' normals,
EMOFACE_HD EMOFACE_INLINE V3 part_normal_gather(const GeometryView& g, const V3* face_normals, int pv, int lane,
                                                int lanes) {
    const int v = g.part_full[pv];
    V3 sum{0, 0, 0};
    EMOFACE_GATHER_UNROLL
    for (int k = g.vertex_face_start[v] + lane; k < g.vertex_face_start[v + 1]; k += lanes)
        sum = sum + face_normals[g.vertex_faces[k]];
    return sum;
}

// then, around n (unit_normal of the whole first gather), its part
// triangles' frames.
EMOFACE_HD EMOFACE_INLINE TangentSum part_tangent_gather(const GeometryView& g, const FaceFrame* triangle_frames,
                                                         int pv, V3 n, int lane, int lanes) {
    bool has_normal = false;
    const V3 nn = frame_normal(n, &has_normal);
    const int first = g.corner_start[pv];
    auto corner = [&](int k, V3& t, V3& b, float& angle) {
        const int c = g.corners[first + k];
        const FaceFrame& f = triangle_frames[c / 3];
        t = f.t;
        b = f.b;
        angle = f.angle[c % 3];
    };
    return tangent_gather(nn, has_normal ? g.corner_start[pv + 1] - first : 0, corner, lane, lanes);
}

// The longer of part vertex pv's two gathers (what a thread's time grows with).
EMOFACE_HD EMOFACE_INLINE int part_gather_size(const GeometryView& g, int pv) {
    const int v = g.part_full[pv];
    const int faces = g.vertex_face_start[v + 1] - g.vertex_face_start[v];
    const int corners = g.corner_start[pv + 1] - g.corner_start[pv];
    return faces > corners ? faces : corners;
}

// Part vertex pv from its whole gathers (n: the unit normal; tangent_sum:
// the tangent gather around it): position and normal into shape[0..5];
// when `frame` is set (a part with frames), tangent xyzw and wrinkle UV
// into frame[0..5].
EMOFACE_HD EMOFACE_INLINE void part_vertex_write(const GeometryView& g, const float* pos, int pv, V3 n,
                                                 const TangentSum& tangent_sum, float* shape, float* frame) {
    const V3 p = at(pos, g.part_full[pv]);
    shape[0] = p.x, shape[1] = p.y, shape[2] = p.z;
    shape[3] = n.x, shape[4] = n.y, shape[5] = n.z;
    if (!frame) return;
    bool has_normal = false, fallback = false;
    const V4 tangent = tangent_finish(frame_normal(n, &has_normal), tangent_sum, &fallback);
    const V2 uv = wrinkle_uv(g, pos, pv);
    frame[0] = tangent.x, frame[1] = tangent.y, frame[2] = tangent.z, frame[3] = tangent.w;
    frame[4] = uv.x, frame[5] = uv.y;
}

// Part vertex pv in one thread.
EMOFACE_HD EMOFACE_INLINE void part_vertex_pass(const GeometryView& g, const float* pos, const V3* face_normals,
                                                const FaceFrame* triangle_frames, int pv, float* shape, float* frame) {
    const V3 n = unit_normal(part_normal_gather(g, face_normals, pv, 0, 1));
    const TangentSum t = frame ? part_tangent_gather(g, triangle_frames, pv, n, 0, 1) : TangentSum{};
    part_vertex_write(g, pos, pv, n, t, shape, frame);
}

}  // namespace emoface::render::geometry_kernel
