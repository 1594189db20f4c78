#pragma once
// The FAP rig's per-vertex body (rig.h says what the rig does), written once
// for the CPU (FaceRig::deform runs it on all cores) and the GPU (the render
// module's CUDA geometry driver runs it into the GL vertex buffers).
//
// Everything that depends on the face only lives in flat arrays (RigArrays,
// built once by FaceRig, viewed through RigView); everything that depends on
// the frame's FAPs is a few hundred doubles (RigFrame, made on the host per
// frame by FaceRig::frame()). A vertex's position is then a function of its
// index alone: the point-FAP sheet as a gather over its precomputed weights,
// the lid FAPs' weights, the lids sliding over the eyeballs, a lash riding on
// its margin vertex (which it recomputes), the jaw, the eyeball and the head,
// in that order. Doubles where the rig always used doubles, so the CPU result
// is the sequential rig's to the last float bit but for FMA contraction.
#include <cmath>
#include <cstdint>

#include "emoface/common/hd.h"

namespace emoface::expression {

namespace rig_kernel {
// Sizes of the per-frame tables (checked when the rig is built).
constexpr int kMaxSystem = 84;  // point-field entries: at most one per feature point
constexpr int kMaxLidFps = 12;  // 3.1-3.4 and the inner brows (lids, bulges), 5.3-5.4 (cheek masses, the lower lids' push)
constexpr int kMaxEyes = 4;
}  // namespace rig_kernel

// One influence of the point field: vertex += weight x displacement[system].
struct RigInfluence {
    std::uint16_t system;
    float weight;
};
// One lid FAP's pull on a vertex.
struct RigLidWeight {
    int lid;  // index into RigFrame::lid_d
    float weight;
};
// A skin vertex in front of an eyeball: it keeps min_radius from the
// eyeball's centre, and what a lid FAP carries keeps its neutral shell.
struct RigSlide {
    int eye;
    float min_radius, shell_radius, follow;
};

// Pointers into the face's flat arrays (host or device memory alike).
struct RigView {
    int vertex_count = 0;
    const float* neutral = nullptr;          // 3 per vertex
    const int* influence_start = nullptr;    // vertex_count + 1
    const RigInfluence* influences = nullptr;
    const int* lid_start = nullptr;          // vertex_count + 1
    const RigLidWeight* lid_weights = nullptr;
    const int* slide_start = nullptr;        // vertex_count + 1
    const RigSlide* slides = nullptr;
    const int* lash_anchor = nullptr;        // per vertex: the margin vertex it rides on, or -1
    const int* lash_eye = nullptr;
    const float* jaw_weight = nullptr;       // per vertex, 0 off the jaw
    const int* eye_of = nullptr;             // per vertex: its eyeball, or -1
    const float* eye_polar = nullptr;        // per eyeball vertex (else 0)
    const float* eye_azimuth = nullptr;
    const float* head_weight = nullptr;      // per vertex
    double eye_centre[rig_kernel::kMaxEyes][3] = {};
};

// Matrices are column-major (glm's layout): m[3 * column + row].
struct RigEyeFrame {
    bool on = false;      // this eye rotates, thrusts or dilates
    bool dilate = false;
    double r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double t[3] = {0, 0, 0};
    double iris_angle = 0, pupil_angle = 0, new_pupil = 0;
};

// One frame's parameters: all the host sends per frame.
struct RigFrame {
    bool points = false;     // some point FAP moves
    bool lids = false;       // some lid FAP moves
    bool jaw = false;
    bool head = false;
    double system_d[rig_kernel::kMaxSystem][3] = {};
    double lid_d[rig_kernel::kMaxLidFps][3] = {};
    double jaw_r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double jaw_pivot[3] = {0, 0, 0}, jaw_t[3] = {0, 0, 0};
    RigEyeFrame eyes[rig_kernel::kMaxEyes];
    double head_r[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
    double head_pivot[3] = {0, 0, 0};
};

namespace rig_kernel {

struct P3 {
    float x, y, z;
};

EMOFACE_HD EMOFACE_INLINE P3 neutral(const RigView& r, int v) {
    return {r.neutral[3 * v], r.neutral[3 * v + 1], r.neutral[3 * v + 2]};
}

// m (column-major) x (x, y, z), summed in glm's order.
EMOFACE_HD EMOFACE_INLINE void mul(const double* m, double x, double y, double z, double out[3]) {
    out[0] = m[0] * x + m[3] * y + m[6] * z;
    out[1] = m[1] * x + m[4] * y + m[7] * z;
    out[2] = m[2] * x + m[5] * y + m[8] * z;
}

// p moved by w of the rigid motion r about `pivot` followed by t.
EMOFACE_HD EMOFACE_INLINE P3 blend_rigid(P3 p, double w, const double* r, const double* pivot, const double* t) {
    const double x = p.x, y = p.y, z = p.z;
    double m[3];
    mul(r, x - pivot[0], y - pivot[1], z - pivot[2], m);
    const double mx = m[0] + pivot[0] + t[0], my = m[1] + pivot[1] + t[1], mz = m[2] + pivot[2] + t[2];
    return {static_cast<float>(x + w * (mx - x)), static_cast<float>(y + w * (my - y)),
            static_cast<float>(z + w * (mz - z))};
}

// The skin's stages: neutral, the point field, the lid FAPs, the slide over
// the eyeballs.
EMOFACE_HD EMOFACE_INLINE P3 skin_position(const RigView& r, const RigFrame& f, int v) {
    P3 p = neutral(r, v);
    if (f.points) {
        double dx = 0, dy = 0, dz = 0;
        for (int k = r.influence_start[v]; k < r.influence_start[v + 1]; ++k) {
            const double* dj = f.system_d[r.influences[k].system];
            const double w = r.influences[k].weight;
            dx += w * dj[0];
            dy += w * dj[1];
            dz += w * dj[2];
        }
        p.x += static_cast<float>(dx);
        p.y += static_cast<float>(dy);
        p.z += static_cast<float>(dz);
    }
    if (f.lids)
        for (int k = r.lid_start[v]; k < r.lid_start[v + 1]; ++k) {
            const double* dk = f.lid_d[r.lid_weights[k].lid];
            const float w = r.lid_weights[k].weight;
            p.x += static_cast<float>(w * dk[0]);
            p.y += static_cast<float>(w * dk[1]);
            p.z += static_cast<float>(w * dk[2]);
        }
    if (f.points || f.lids)
        for (int k = r.slide_start[v]; k < r.slide_start[v + 1]; ++k) {
            const RigSlide& s = r.slides[k];
            const double* c = r.eye_centre[s.eye];
            const double dx = p.x - c[0], dy = p.y - c[1], dz = p.z - c[2];
            const double r2 = dx * dx + dy * dy + dz * dz, m2 = double(s.min_radius) * s.min_radius;
            const double s2 = double(s.shell_radius) * s.shell_radius;
            if (r2 < m2 && dx * dx + dy * dy < m2) {
                p.z = static_cast<float>(c[2] + sqrt(m2 - dx * dx - dy * dy));
            } else if (s.follow > 0 && r2 > s2 && dx * dx + dy * dy < s2) {
                const double shell_z = c[2] + sqrt(s2 - dx * dx - dy * dy);
                p.z = static_cast<float>(p.z + s.follow * (shell_z - p.z));
            }
        }
    return p;
}

// Vertex v after the whole rig.
EMOFACE_HD EMOFACE_INLINE P3 position(const RigView& r, const RigFrame& f, int v) {
    P3 p = skin_position(r, f, v);
    const int anchor = r.lash_anchor[v];
    if (anchor >= 0 && (f.points || f.lids)) {
        // A lash turns with its margin vertex about the eyeball's horizontal axis.
        const double* c = r.eye_centre[r.lash_eye[v]];
        const P3 a0 = neutral(r, anchor), a = skin_position(r, f, anchor), n = neutral(r, v);
        const double turn = atan2(a.y - c[1], a.z - c[2]) - atan2(a0.y - c[1], a0.z - c[2]);
        const float ox = n.x - a0.x, oy = n.y - a0.y, oz = n.z - a0.z;
        const double cs = cos(turn), sn = sin(turn);
        p = {a.x + ox, a.y + static_cast<float>(oy * cs + oz * sn), a.z + static_cast<float>(oz * cs - oy * sn)};
    }
    if (f.jaw && r.jaw_weight[v] > 0) p = blend_rigid(p, r.jaw_weight[v], f.jaw_r, f.jaw_pivot, f.jaw_t);
    const int e = r.eye_of[v];
    if (e >= 0 && f.eyes[e].on) {
        const RigEyeFrame& ef = f.eyes[e];
        const double* c = r.eye_centre[e];
        const P3 n = neutral(r, v);
        double dx = double(n.x) - c[0], dy = double(n.y) - c[1], dz = double(n.z) - c[2];
        const double a = r.eye_polar[v];
        if (ef.dilate && a < ef.iris_angle) {
            // The iris's rings slide over the eyeball as the pupil grows.
            const double len = sqrt(dx * dx + dy * dy + dz * dz);
            const double na = a < ef.pupil_angle
                                  ? a * ef.new_pupil / ef.pupil_angle
                                  : ef.new_pupil + (a - ef.pupil_angle) * (ef.iris_angle - ef.new_pupil) /
                                                       (ef.iris_angle - ef.pupil_angle);
            const double az = r.eye_azimuth[v];
            dx = len * sin(na) * cos(az);
            dy = len * sin(na) * sin(az);
            dz = len * cos(na);
        }
        double m[3];
        mul(ef.r, dx, dy, dz, m);
        p = {static_cast<float>(m[0] + c[0] + ef.t[0]), static_cast<float>(m[1] + c[1] + ef.t[1]),
             static_cast<float>(m[2] + c[2] + ef.t[2])};
    }
    if (f.head && r.head_weight[v] > 0) {
        const double zero[3] = {0, 0, 0};
        p = blend_rigid(p, r.head_weight[v], f.head_r, f.head_pivot, zero);
    }
    return p;
}

}  // namespace rig_kernel
}  // namespace emoface::expression
