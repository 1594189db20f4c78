#include "emoface/expression/face_io.h"

#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>

#include <OpenMesh/Core/System/omstream.hh>
#include <nlohmann/json.hpp>

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/common/input_file.h"
#include "emoface/expression/rig.h"
#include "emoface/fap/feature_points.h"
#include "json_reader.h"

namespace emoface::expression {
namespace {

using nlohmann::json;

constexpr long long kMaxElements = 10'000'000;  // vertices or faces in one file

std::string folder_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    return slash == std::string::npos ? std::string() : path.substr(0, slash + 1);
}

std::string stem_of(const std::string& path) {
    const auto slash = path.find_last_of('/');
    std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
    const auto dot = name.find_last_of('.');
    return dot == std::string::npos ? name : name.substr(0, dot);
}

std::string read_text(const std::string& path) { return read_input_file(path, kMaxMeshFileBytes, "expression"); }

// 1234567 -> "1,234,567" (counts in messages).
std::string with_commas(long long n) {
    std::string digits = std::to_string(n < 0 ? -n : n), out;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
        out += digits[i];
    }
    return n < 0 ? "-" + out : out;
}

// Adds triangles to a mesh with OpenMesh's own per-triangle complaints
// ("PolyMeshT::add_face: complex edge", one line each; 98,120 for one bad
// file) switched off, counted by kind for one message instead. (Switched off
// rather than redirected: OpenMesh's stream leaks what connect() allocates.)
class TriangleAdder {
public:
    explicit TriangleAdder(TriMesh& mesh) : mesh_(mesh), was_enabled_(::omerr().is_enabled()) { ::omerr().disable(); }
    ~TriangleAdder() {
        if (was_enabled_) ::omerr().enable();
    }
    TriangleAdder(const TriangleAdder&) = delete;
    TriangleAdder& operator=(const TriangleAdder&) = delete;

    // Whether the triangle was added; a rejected one is counted and, the
    // first time, `line` (the file's line it came from) kept.
    bool add(int a, int b, int c, std::size_t line) {
        const TriMesh::VertexHandle v[3] = {TriMesh::VertexHandle(a), TriMesh::VertexHandle(b), TriMesh::VertexHandle(c)};
        if (mesh_.add_face(v[0], v[1], v[2]).is_valid()) return true;
        if (rejected_++ == 0) first_line_ = line;
        // OpenMesh's two reasons: an edge that already has a triangle on
        // this side, or a vertex whose fan is already closed.
        bool edge = false;
        for (int k = 0; k < 3; ++k) {
            const auto h = mesh_.find_halfedge(v[k], v[(k + 1) % 3]);
            edge = edge || (h.is_valid() && !mesh_.is_boundary(h));
        }
        (edge ? complex_edges_ : complex_vertices_)++;
        return false;
    }
    long long rejected() const { return rejected_; }
    std::size_t first_line() const { return first_line_; }
    // "complex edges" / "complex vertices" / both.
    std::string kinds() const {
        if (complex_edges_ > 0 && complex_vertices_ > 0) return "complex edges and complex vertices";
        return complex_edges_ > 0 ? "complex edges" : "complex vertices";
    }

private:
    TriMesh& mesh_;
    bool was_enabled_;
    long long rejected_ = 0, complex_edges_ = 0, complex_vertices_ = 0;
    std::size_t first_line_ = 0;
};

// A mesh the rig can drive is one surface: a triangle OpenMesh rejects
// (an edge in three triangles, two triangles wound against each other, a
// vertex joining two fans) would be a hole the rig's geodesic distances and
// the wrinkle maps do not know about, so the file is refused, not patched.
void check_all_added(TriangleAdder& adder, long long triangles, const std::string& file) {
    if (adder.rejected() == 0) return;
    fail_data("expression", FileLoc{file, static_cast<int>(adder.first_line()), ""},
              "a manifold mesh (each edge in at most two triangles, wound alike)",
              fmt::format("{} of {} triangles rejected: {}{}", with_commas(adder.rejected()), with_commas(triangles),
                          adder.kinds(), adder.first_line() > 0 ? " (the first one here)" : ""));
}

std::vector<std::string_view> split_lines(std::string_view text) {
    std::vector<std::string_view> lines;
    std::size_t start = 0;
    for (std::size_t i = 0; i <= text.size(); ++i) {
        if (i == text.size() || text[i] == '\n' || text[i] == '\r') {
            lines.push_back(text.substr(start, i - start));
            if (i + 1 < text.size() && text[i] == '\r' && text[i + 1] == '\n') ++i;
            start = i + 1;
        }
    }
    return lines;
}

std::vector<std::string_view> tokens(std::string_view line) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t s = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > s) out.push_back(line.substr(s, i - s));
    }
    return out;
}

// A coordinate: finite and within float's range, as the mesh stores floats.
bool parse_double(std::string_view t, double* out) {
    // std::from_chars for double is in libstdc++ 11+.
    const char* end = t.data() + t.size();
    auto [p, ec] = std::from_chars(t.data(), end, *out);
    return ec == std::errc() && p == end && std::isfinite(*out) && std::abs(*out) <= FLT_MAX;
}

bool parse_int(std::string_view t, long long* out) {
    const char* end = t.data() + t.size();
    auto [p, ec] = std::from_chars(t.data(), end, *out);
    return ec == std::errc() && p == end;
}

std::string quoted(std::string_view t) { return "\"" + echo_input(t, 40) + "\""; }

constexpr const char* kNumber = "a number (within a float's range, 3.4e38)";

void finish_mesh(Face& face) {
    face.mesh.request_face_normals();
    face.mesh.request_vertex_normals();
    face.mesh.update_normals();
}

// The face's size and place in float arithmetic's comfortable range: the
// rig, the layouts and the GL pipeline work in float, where a face 1e30 wide
// gives lines of zero length and one 1e-30 wide underflows.
constexpr double kMaxCoordinate = 1e7, kMinExtent = 1e-4;

// A face the rig and the morph can drive, or an InputError naming `mesh_file`
// (its size) or `source` (where its feature points come from):
// coordinates in range, a face of some size not far from its origin, and
// the rig built on it without complaint (feature points that coincide or
// stand where no skin is give a singular or empty influence field).
void check_face_geometry(const Face& face, const std::string& mesh_file, const std::string& source) {
    double max_abs = 0.0;
    glm::dvec3 lo(1e300), hi(-1e300);
    for (auto vh : face.mesh.vertices()) {
        const auto p = face.mesh.point(vh);
        for (int c = 0; c < 3; ++c) {
            max_abs = std::max(max_abs, std::abs(double(p[c])));
            lo[c] = std::min(lo[c], double(p[c]));
            hi[c] = std::max(hi[c], double(p[c]));
        }
    }
    const double extent = std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z});
    if (max_abs > kMaxCoordinate || extent < kMinExtent || extent < max_abs * 1e-3)
        fail_data("expression", FileLoc{mesh_file, 0, ""},
                  fmt::format("a face between {:g} and {:g} units across (any unit), near its origin", kMinExtent,
                              kMaxCoordinate),
                  fmt::format("one {:.3g} across, {:.3g} from its origin", extent, max_abs));
    try {
        const FaceRig rig(face);
    } catch (const InputError& e) {
        std::string why = e.what();
        for (const char* prefix : {"expression: rig: ", "expression: "})
            if (why.rfind(prefix, 0) == 0) {
                why = why.substr(std::string(prefix).size());
                break;
            }
        fail<InputError>("expression: {}: the rig cannot drive this face: {}", source, why);
    }
}

json vec_json(const Vec3d& v) { return json::array({v[0], v[1], v[2]}); }

Vec3d vec_from(const detail::JsonReader& value) {
    const auto xyz = value.as_numbers<3>();
    return {xyz[0], xyz[1], xyz[2]};
}

// Makes x point to the face's left and z to the viewer, judging by pairs of
// left/right feature points and by the nose tip standing in front of the eyes.
void orient(Face& face, bool* mirrored_x, bool* flipped_z) {
    auto has = [&](const char* id) { return face.has(fap::feature_point_index(id)); };
    auto at = [&](const char* id) { return face.position(fap::feature_point_index(id)); };
    double left_minus_right = 0.0;
    for (auto [l, r] : {std::pair{"3.5", "3.6"}, {"3.7", "3.12"}, {"2.4", "2.5"}, {"8.3", "8.4"}, {"4.5", "4.6"}})
        if (has(l) && has(r)) {
            left_minus_right = at(l)[0] - at(r)[0];
            break;
        }
    double front = 0.0;
    if (has("9.3") && has("3.7") && has("3.12")) front = at("9.3")[2] - 0.5 * (at("3.7")[2] + at("3.12")[2]);
    const bool mx = left_minus_right < 0, fz = front < 0;
    *mirrored_x = mx;
    *flipped_z = fz;
    if (!mx && !fz) return;
    for (auto vh : face.mesh.vertices()) {
        auto p = face.mesh.point(vh);
        if (mx) p[0] = -p[0];
        if (fz) p[2] = -p[2];
        face.mesh.set_point(vh, p);
    }
    for (auto& fp : face.feature_points) {
        if (mx) fp.position[0] = -fp.position[0];
        if (fz) fp.position[2] = -fp.position[2];
    }
    if (mx != fz) {
        // One reflection turns the triangles inside out: rebuild them reversed.
        std::vector<std::array<int, 3>> tris;
        for (auto fh : face.mesh.faces()) {
            std::array<int, 3> t{};
            int k = 0;
            for (auto vh : face.mesh.fv_range(fh)) t[k++] = vh.idx();
            tris.push_back({t[0], t[2], t[1]});
        }
        TriMesh mesh;
        mesh.request_vertex_texcoords2D();
        for (auto vh : face.mesh.vertices()) {
            auto nv = mesh.add_vertex(face.mesh.point(vh));
            if (face.mesh.has_vertex_texcoords2D()) mesh.set_texcoord2D(nv, face.mesh.texcoord2D(vh));
        }
        for (const auto& t : tris)
            mesh.add_face(TriMesh::VertexHandle(t[0]), TriMesh::VertexHandle(t[1]), TriMesh::VertexHandle(t[2]));
        face.mesh = std::move(mesh);
    }
}

}  // namespace

// --- OBJ + FDP --------------------------------------------------------------

void save_obj(const Face& face, const std::string& path, const std::string& material_file) {
    const TriMesh& m = face.mesh;
    std::string out;
    out.reserve(m.n_vertices() * 90 + m.n_faces() * 40);
    fmt::format_to(std::back_inserter(out), "# emoface face \"{}\": {} vertices, {} triangles\n", face.name,
                   m.n_vertices(), m.n_faces());
    out += "# x = the face's left, y = up, z = towards the viewer; feature points in the .fdp.json beside it\n";
    if (!material_file.empty()) fmt::format_to(std::back_inserter(out), "mtllib {}\n", material_file);
    out += "o face\n";
    for (auto vh : m.vertices()) {
        const auto p = m.point(vh);
        fmt::format_to(std::back_inserter(out), "v {:.6g} {:.6g} {:.6g}\n", p[0], p[1], p[2]);
    }
    const bool uv = m.has_vertex_texcoords2D(), nrm = m.has_vertex_normals();
    if (uv)
        for (auto vh : m.vertices()) {
            const auto t = m.texcoord2D(vh);
            fmt::format_to(std::back_inserter(out), "vt {:.6g} {:.6g}\n", t[0], t[1]);
        }
    if (nrm)
        for (auto vh : m.vertices()) {
            const auto n = m.normal(vh);
            fmt::format_to(std::back_inserter(out), "vn {:.5g} {:.5g} {:.5g}\n", n[0], n[1], n[2]);
        }
    if (!material_file.empty()) out += "usemtl face\n";
    for (auto fh : m.faces()) {
        out += 'f';
        for (auto vh : m.fv_range(fh)) {
            const int i = vh.idx() + 1;
            if (uv && nrm) fmt::format_to(std::back_inserter(out), " {}/{}/{}", i, i, i);
            else if (uv) fmt::format_to(std::back_inserter(out), " {}/{}", i, i);
            else if (nrm) fmt::format_to(std::back_inserter(out), " {}//{}", i, i);
            else fmt::format_to(std::back_inserter(out), " {}", i);
        }
        out += '\n';
    }
    write_file_atomically(path, out, "expression");
}

void save_mtl(const std::string& path, const std::string& texture_file) {
    write_file_atomically(
        path, fmt::format("newmtl face\nKa 0 0 0\nKd 1 1 1\nKs 0.05 0.05 0.05\nNs 20\nmap_Kd {}\n", texture_file),
        "expression");
}

void save_fdp(const Face& face, const std::string& path, const std::string& mesh_file,
              const std::string& base_colour_file) {
    json j;
    j["format"] = "emoface-fdp";
    j["version"] = 1;
    j["name"] = face.name;
    j["mesh"] = mesh_file;
    if (!base_colour_file.empty()) j["base_colour"] = base_colour_file;
    j["frame"] = "x = the face's left, y = up, z = towards the viewer";
    json fps = json::object();
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const FeaturePointLocation& fp = face.feature_points[k];
        if (!fp.present) continue;
        const std::string id(fap::feature_points()[k].id);
        if (fp.vertex >= 0) fps[id] = {{"vertex", fp.vertex}};
        else fps[id] = {{"position", vec_json(fp.position)}};
    }
    j["feature_points"] = fps;
    json eyes = json::array();
    for (const Eyeball& e : face.eyeballs) {
        eyes.push_back({{"side", e.centre[0] > 0 ? "left" : "right"},
                        {"vertices", {e.vertices.first, e.vertices.count}},
                        {"centre", vec_json(e.centre)},
                        {"radius", e.radius},
                        {"iris_angle", e.iris_angle},
                        {"pupil_angle", e.pupil_angle},
                        {"upper_margin", e.upper_margin},
                        {"lower_margin", e.lower_margin}});
    }
    j["eyeballs"] = eyes;
    json parts = json::array();
    for (int v = 0; v < face.vertex_count();) {
        int end = v;
        while (end < face.vertex_count() && face.parts[end] == face.parts[v]) ++end;
        if (face.parts[v] != VertexPart::Skin) parts.push_back({{"part", part_name(face.parts[v])}, {"first", v}, {"count", end - v}});
        v = end;
    }
    j["parts"] = parts;
    json welded = json::array();
    for (const auto& w : face.welded) welded.push_back({w[0], w[1]});
    j["welded"] = welded;
    j["jaw_pivot"] = vec_json(face.jaw_pivot);
    j["head_pivot"] = vec_json(face.head_pivot);
    j["texture_box"] = {{"min", {face.texture_box.min.x, face.texture_box.min.y}},
                        {"max", {face.texture_box.max.x, face.texture_box.max.y}}};
    write_file_atomically(path, j.dump(1) + "\n", "expression");
}

Face load_obj_with_fdp(const std::string& obj_path, const std::string& fdp_path) {
    const std::string obj_text = read_text(obj_path);
    return parse_obj_with_fdp(obj_text, obj_path, detail::read_text_file(fdp_path), fdp_path);
}

Face parse_obj_with_fdp(std::string_view text, const std::string& obj_path, std::string_view fdp_text,
                        const std::string& fdp_path) {
    std::vector<Vec3d> positions;
    std::vector<std::array<double, 2>> uvs;
    struct Corner {
        int v, vt;
    };
    std::vector<std::vector<Corner>> polygons;
    std::vector<std::size_t> polygon_lines;  // 1-based, for messages
    const auto lines = split_lines(text);
    for (std::size_t li = 0; li < lines.size(); ++li) {
        const auto t = tokens(lines[li]);
        if (t.empty() || t[0][0] == '#') continue;
        auto bad = [&](const std::string& what) {
            fail<InputError>("expression: {}:{}: {}", obj_path, li + 1, what);
        };
        if (t[0] == "v") {
            if (t.size() < 4) bad(fmt::format("expected \"v x y z\", found {} numbers", t.size() - 1));
            Vec3d p;
            for (int c = 0; c < 3; ++c)
                if (!parse_double(t[1 + c], &p[c])) bad(fmt::format("expected {}, found {}", kNumber, quoted(t[1 + c])));
            positions.push_back(p);
            if (static_cast<long long>(positions.size()) > kMaxElements) bad("more vertices than the 10 million allowed");
        } else if (t[0] == "vt") {
            if (t.size() < 3) bad("expected \"vt u v\"");
            std::array<double, 2> uv{};
            for (int c = 0; c < 2; ++c)
                if (!parse_double(t[1 + c], &uv[c])) bad(fmt::format("expected {}, found {}", kNumber, quoted(t[1 + c])));
            uvs.push_back(uv);
        } else if (t[0] == "f") {
            if (t.size() < 4) bad(fmt::format("a face needs at least 3 corners, found {}", t.size() - 1));
            std::vector<Corner> poly;
            for (std::size_t k = 1; k < t.size(); ++k) {
                const auto s1 = t[k].find('/');
                long long vi = 0, ti = 0;
                if (!parse_int(t[k].substr(0, s1), &vi)) bad("expected a vertex index, found " + quoted(t[k]));
                if (s1 != std::string_view::npos) {
                    const auto rest = t[k].substr(s1 + 1);
                    const auto s2 = rest.find('/');
                    const auto ts = rest.substr(0, s2);
                    if (!ts.empty() && !parse_int(ts, &ti)) bad("expected a texture index, found " + quoted(t[k]));
                }
                // Negative indices count back from the latest element.
                if (vi < 0) vi += static_cast<long long>(positions.size()) + 1;
                if (ti < 0) ti += static_cast<long long>(uvs.size()) + 1;
                if (vi < 1 || vi > static_cast<long long>(positions.size()))
                    bad(fmt::format("vertex index {} outside the {} vertices read so far", vi, positions.size()));
                if (ti > static_cast<long long>(uvs.size()))
                    bad(fmt::format("texture index {} outside the {} read so far", ti, uvs.size()));
                poly.push_back({static_cast<int>(vi - 1), static_cast<int>(ti - 1)});
            }
            polygons.push_back(std::move(poly));
            polygon_lines.push_back(li + 1);
            if (static_cast<long long>(polygons.size()) > kMaxElements) bad("more faces than the 10 million allowed");
        }
        // o, g, s, usemtl, mtllib, vn, l, ...: not needed.
    }
    if (positions.empty() || polygons.empty())
        fail<InputError>("expression: {}: expected vertices and faces, found {} and {}", obj_path, positions.size(),
                         polygons.size());

    Face face;
    face.name = stem_of(obj_path);
    face.mesh.request_vertex_texcoords2D();
    // Vertex i is OBJ vertex i with the first texture coordinate it is used
    // with; other coordinates of the same OBJ vertex get welded copies.
    std::vector<int> first_uv(positions.size(), -2);
    for (const auto& poly : polygons)
        for (const Corner& c : poly)
            if (first_uv[c.v] == -2) first_uv[c.v] = c.vt;
    for (std::size_t i = 0; i < positions.size(); ++i) {
        auto vh = face.mesh.add_vertex(TriMesh::Point(static_cast<float>(positions[i][0]),
                                                      static_cast<float>(positions[i][1]),
                                                      static_cast<float>(positions[i][2])));
        const int t = first_uv[i];
        face.mesh.set_texcoord2D(vh, t >= 0 ? TriMesh::TexCoord2D(static_cast<float>(uvs[t][0]), static_cast<float>(uvs[t][1]))
                                            : TriMesh::TexCoord2D(0.f, 0.f));
    }
    std::map<std::pair<int, int>, int> copies;
    auto vertex_for = [&](const Corner& c) {
        if (c.vt == first_uv[c.v] || c.vt < 0) return c.v;
        auto [it, inserted] = copies.emplace(std::pair{c.v, c.vt}, 0);
        if (inserted) {
            // A copy: add_vertex may grow the storage the reference would point into.
            const TriMesh::Point p = face.mesh.point(TriMesh::VertexHandle(c.v));
            auto vh = face.mesh.add_vertex(p);
            face.mesh.set_texcoord2D(vh, TriMesh::TexCoord2D(static_cast<float>(uvs[c.vt][0]), static_cast<float>(uvs[c.vt][1])));
            it->second = vh.idx();
            face.welded.push_back({c.v, vh.idx()});
        }
        return it->second;
    };
    {
        TriangleAdder adder(face.mesh);
        long long triangles = 0;
        for (std::size_t p = 0; p < polygons.size(); ++p) {
            const auto& poly = polygons[p];
            for (std::size_t k = 1; k + 1 < poly.size(); ++k) {
                const int a = vertex_for(poly[0]), b = vertex_for(poly[k]), c = vertex_for(poly[k + 1]);
                if (a == b || b == c || a == c) continue;
                ++triangles;
                adder.add(a, b, c, polygon_lines[p]);
            }
        }
        check_all_added(adder, triangles, obj_path);
    }
    face.parts.assign(face.mesh.n_vertices(), VertexPart::Skin);
    const int obj_vertices = static_cast<int>(positions.size());

    // Pivots and texture box given in the file replace the estimated ones.
    std::optional<Vec3d> jaw_pivot, head_pivot;
    std::optional<TextureBox> texture_box;
    detail::read_json_text(fdp_text, fdp_path, [&](detail::JsonReader& root) {
        // Written by save_fdp; free text for people.
        root.comment("frame");
        if (root.has("format") && root.string("format") != "emoface-fdp")
            root.at("format").fail("\"emoface-fdp\"");
        if (root.has("version")) root.integer_in("version", 1, 1);
        if (root.has("mesh")) (void)root.string("mesh");
        if (root.has("name")) face.name = root.string("name");
        for (auto& [id, entry] : root.object("feature_points").entries()) {
            const auto k = fap::find_feature_point(id);
            if (!k) entry.fail("an MPEG-4 feature point id as the key", "\"" + id + "\"");
            const char* expected = "{\"vertex\": i} or {\"position\": [x, y, z]}";
            if (!entry.is_object()) entry.fail(expected);
            detail::JsonReader e = entry.as_object();
            FeaturePointLocation& fp = face.feature_points[*k];
            fp.present = true;
            const bool by_vertex = e.has("vertex"), by_position = e.has("position");
            if (by_vertex == by_position) e.fail(expected);
            if (by_vertex) {
                fp.vertex = e.integer_in("vertex", 0, obj_vertices - 1);
                const auto q = face.mesh.point(TriMesh::VertexHandle(fp.vertex));
                fp.position = {q[0], q[1], q[2]};
            } else {
                fp.position = vec_from(e.at("position"));
            }
            e.finish();
        }
        const int n = face.vertex_count();
        if (root.has("parts")) {
            for (detail::JsonReader p : root.objects("parts")) {
                const detail::JsonReader name = p.at("part");
                int part = -1;
                for (int q = 0; q <= static_cast<int>(VertexPart::Tongue); ++q)
                    if (name.as_string() == part_name(static_cast<VertexPart>(q))) part = q;
                if (part < 0) name.fail("skin, eyeball_left, eyeball_right, mouth_upper, mouth_lower or tongue");
                const int first = p.integer_in("first", 0, n - 1);
                const int count = p.integer_in("count", 0, n - first);
                p.finish();
                for (int v = first; v < first + count; ++v) face.parts[v] = static_cast<VertexPart>(part);
            }
        }
        if (root.has("eyeballs")) {
            for (detail::JsonReader e : root.objects("eyeballs")) {
                Eyeball eb;
                if (e.has("side")) (void)e.string("side");  // informative; the centre decides
                const detail::JsonReader range = e.at("vertices");
                const std::vector<detail::JsonReader> ends = range.elements();
                if (ends.size() != 2) range.fail("[first, count]");
                eb.vertices.first = ends[0].as_integer_in(0, n - 1);
                eb.vertices.count = ends[1].as_integer_in(0, n - eb.vertices.first);
                eb.centre = vec_from(e.at("centre"));
                eb.radius = e.number("radius");
                eb.iris_angle = e.number("iris_angle", 0.5);
                eb.pupil_angle = e.number("pupil_angle", 0.18);
                for (const char* key : {"upper_margin", "lower_margin"}) {
                    if (!e.has(key)) continue;
                    auto& margin = std::string(key) == "upper_margin" ? eb.upper_margin : eb.lower_margin;
                    for (const detail::JsonReader& v : e.at(key).elements()) margin.push_back(v.as_integer_in(0, n - 1));
                }
                e.finish();
                face.eyeballs.push_back(std::move(eb));
            }
        }
        if (root.has("welded")) {
            for (const detail::JsonReader& w : root.at("welded").elements()) {
                const std::vector<detail::JsonReader> pair = w.elements();
                if (pair.size() != 2) w.fail("a pair [a, b] of vertex indices");
                face.welded.push_back({pair[0].as_integer_in(0, n - 1), pair[1].as_integer_in(0, n - 1)});
            }
        }
        if (root.has("jaw_pivot")) jaw_pivot = vec_from(root.at("jaw_pivot"));
        if (root.has("head_pivot")) head_pivot = vec_from(root.at("head_pivot"));
        if (root.has("texture_box")) {
            detail::JsonReader b = root.object("texture_box");
            const auto min = b.numbers<2>("min");
            const auto max = b.numbers<2>("max");
            b.finish();
            texture_box = TextureBox{{static_cast<float>(min[0]), static_cast<float>(min[1])},
                                     {static_cast<float>(max[0]), static_cast<float>(max[1])}};
            if (!(texture_box->max.x > texture_box->min.x && texture_box->max.y > texture_box->min.y))
                b.at("max").fail(fmt::format("a corner above and right of min [{}, {}]", min[0], min[1]));
        }
        if (root.has("base_colour")) face.base_colour_file = folder_of(fdp_path) + root.string("base_colour");
    });
    finish_mesh(face);
    update_fapu(face, fdp_path);
    estimate_pivots(face);
    if (jaw_pivot) face.jaw_pivot = *jaw_pivot;
    if (head_pivot) face.head_pivot = *head_pivot;
    face.texture_box = texture_box ? *texture_box : frontal_box(face);
    face.source = fdp_path;
    validate_face(face, fdp_path);
    check_face_geometry(face, obj_path, fdp_path);
    return face;
}

// --- Candide-3 --------------------------------------------------------------

Face load_candide3(const std::string& path, Candide3Report* report) {
    return parse_candide3(read_text(path), path, report);
}

Face parse_candide3(std::string_view text, const std::string& source, Candide3Report* report) {
    const auto lines = split_lines(text);
    std::size_t li = 0;
    auto bad = [&](std::size_t line, const std::string& what) {
        fail<InputError>("expression: {}:{}: {}", source, line + 1, what);
    };
    // Next line that is neither blank nor a comment.
    auto next_data = [&](const char* expected) {
        while (li < lines.size()) {
            const auto t = tokens(lines[li]);
            if (!t.empty() && t[0][0] != '#') return t;
            ++li;
        }
        fail<InputError>("expression: {}: ended before {}", source, expected);
    };
    auto find_section = [&](const char* title) {
        for (; li < lines.size(); ++li) {
            const auto& l = lines[li];
            if (!l.empty() && l.find('#') != std::string_view::npos && l.find(title) != std::string_view::npos) {
                ++li;
                return;
            }
        }
        fail<InputError>("expression: {}: no \"# {}:\" section", source, title);
    };
    auto read_count = [&](const char* what) {
        const auto t = next_data(what);
        long long count = 0;
        if (t.size() != 1 || !parse_int(t[0], &count) || count < 0 || count > kMaxElements)
            bad(li, fmt::format("expected the number of {} (0 to 10 million), found {}", what, quoted(lines[li])));
        ++li;
        return static_cast<int>(count);
    };

    find_section("VERTEX LIST");
    const int nv = read_count("vertices");
    std::vector<Vec3d> vertices(nv);
    for (int i = 0; i < nv; ++i) {
        const auto t = next_data("all vertices were read");
        if (t.size() != 3) bad(li, fmt::format("vertex {}: expected 3 coordinates, found {}", i, t.size()));
        for (int c = 0; c < 3; ++c)
            if (!parse_double(t[c], &vertices[i][c])) bad(li, fmt::format("vertex {}: expected {}, found {}", i, kNumber, quoted(t[c])));
        ++li;
    }
    find_section("FACE LIST");
    const int nf = read_count("faces");
    std::vector<std::array<int, 3>> faces(nf);
    std::vector<std::size_t> face_lines(nf);  // 1-based, for messages
    for (int i = 0; i < nf; ++i) {
        const auto t = next_data("all faces were read");
        face_lines[i] = li + 1;
        if (t.size() != 3) bad(li, fmt::format("face {}: expected 3 vertex indices, found {}", i, t.size()));
        for (int c = 0; c < 3; ++c) {
            long long v = 0;
            if (!parse_int(t[c], &v) || v < 0 || v >= nv)
                bad(li, fmt::format("face {}: expected a vertex index in [0, {}), found {}", i, nv, quoted(t[c])));
            faces[i][c] = static_cast<int>(v);
        }
        ++li;
    }

    Face face;
    face.name = "candide3";
    face.mesh.request_vertex_texcoords2D();
    for (const Vec3d& p : vertices)
        face.mesh.add_vertex(TriMesh::Point(static_cast<float>(p[0]), static_cast<float>(p[1]), static_cast<float>(p[2])));
    {
        TriangleAdder adder(face.mesh);
        long long triangles = 0;
        for (std::size_t i = 0; i < faces.size(); ++i) {
            const auto& f = faces[i];
            if (f[0] == f[1] || f[1] == f[2] || f[0] == f[2]) continue;
            ++triangles;
            adder.add(f[0], f[1], f[2], face_lines[i]);
        }
        check_all_added(adder, triangles, source);
    }
    face.parts.assign(nv, VertexPart::Skin);

    // Feature points from the table; never invented where Candide-3 (or this
    // file) has no vertex.
    for (int k = 0; k < fap::kFeaturePointCount; ++k) {
        const auto& info = fap::feature_points()[k];
        Vec3d sum{0, 0, 0};
        int count = 0, single = -1;
        bool all_there = info.candide3_vertices[0] >= 0;
        for (int v : info.candide3_vertices) {
            if (v < 0) continue;
            if (v >= nv) {
                all_there = false;
                break;
            }
            for (int c = 0; c < 3; ++c) sum[c] += vertices[v][c];
            ++count;
            single = v;
        }
        if (!all_there || count == 0) continue;
        FeaturePointLocation& fp = face.feature_points[k];
        fp.present = true;
        fp.vertex = count == 1 ? single : -1;
        fp.position = {sum[0] / count, sum[1] / count, sum[2] / count};
    }
    Candide3Report r;
    orient(face, &r.mirrored_x, &r.flipped_z);
    // UVs: frontal projection of the (oriented) model, for a texture painted
    // on a photograph of the face.
    face.texture_box = frontal_box(face);
    for (auto vh : face.mesh.vertices()) {
        const auto p = face.mesh.point(vh);
        // project_to_texture() measures v down the image; OBJ texcoords measure it up.
        const glm::vec2 uv = project_to_texture({p[0], p[1], p[2]}, face.texture_box);
        face.mesh.set_texcoord2D(vh, TriMesh::TexCoord2D(uv.x, 1.0f - uv.y));
    }
    finish_mesh(face);
    r.vertices = nv;
    r.triangles = static_cast<int>(face.mesh.n_faces());
    r.missing_feature_points = missing_feature_points(face);
    if (report) *report = r;
    face.source = source;
    update_fapu(face, source);
    estimate_pivots(face);
    validate_face(face, source);
    check_face_geometry(face, source, source);
    return face;
}

// --- PNG --------------------------------------------------------------------

void save_png(const Image& image, const std::string& path) {
    if (image.empty() || image.rgba.size() != static_cast<std::size_t>(image.width) * image.height * 4)
        fail<InputError>("expression: cannot write {}: the image is empty or its size does not match", path);
    static std::array<std::uint32_t, 256> crc_table = [] {
        std::array<std::uint32_t, 256> t{};
        for (std::uint32_t n = 0; n < 256; ++n) {
            std::uint32_t c = n;
            for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
            t[n] = c;
        }
        return t;
    }();
    auto be32 = [](std::string& s, std::uint32_t v) {
        for (int k = 3; k >= 0; --k) s += static_cast<char>((v >> (8 * k)) & 0xff);
    };
    std::string out("\x89PNG\r\n\x1a\n", 8);
    auto chunk = [&](const char* type, const std::string& data) {
        be32(out, static_cast<std::uint32_t>(data.size()));
        std::string body = std::string(type, 4) + data;
        std::uint32_t c = 0xffffffffu;
        for (unsigned char b : body) c = crc_table[(c ^ b) & 0xff] ^ (c >> 8);
        out += body;
        be32(out, c ^ 0xffffffffu);
    };
    std::string ihdr;
    be32(ihdr, static_cast<std::uint32_t>(image.width));
    be32(ihdr, static_cast<std::uint32_t>(image.height));
    ihdr += std::string("\x08\x06\x00\x00\x00", 5);  // 8-bit RGBA, no interlace
    chunk("IHDR", ihdr);
    // Raw scanlines (filter byte 0), wrapped in stored deflate blocks.
    std::string raw;
    const std::size_t row = static_cast<std::size_t>(image.width) * 4;
    raw.reserve((row + 1) * image.height);
    for (int y = 0; y < image.height; ++y) {
        raw += '\0';
        raw.append(reinterpret_cast<const char*>(image.rgba.data() + y * row), row);
    }
    std::string z("\x78\x01", 2);
    for (std::size_t pos = 0; pos < raw.size() || pos == 0;) {
        const std::size_t len = std::min<std::size_t>(65535, raw.size() - pos);
        const bool last = pos + len >= raw.size();
        z += static_cast<char>(last ? 1 : 0);
        z += static_cast<char>(len & 0xff);
        z += static_cast<char>(len >> 8);
        z += static_cast<char>(~len & 0xff);
        z += static_cast<char>((~len >> 8) & 0xff);
        z.append(raw, pos, len);
        pos += len;
        if (last) break;
    }
    std::uint32_t a = 1, b = 0;
    for (unsigned char ch : raw) {
        a = (a + ch) % 65521;
        b = (b + a) % 65521;
    }
    be32(z, (b << 16) | a);
    chunk("IDAT", z);
    chunk("IEND", "");
    write_file_atomically(path, out, "expression");
}

}  // namespace emoface::expression
