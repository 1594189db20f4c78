#pragma once
// Faces in files: Wavefront OBJ meshes with an FDP (feature-point
// definition) JSON beside them, the public Candide-3 model (.wfm), and the
// base colour as PNG. docs/FACE.md documents the FDP JSON format.
//
// Every reader throws emoface::InputError "expression: FILE:LINE: what was
// expected, what was found"; every writer writes to a temporary name in the
// target's folder and renames it, so no partial file is left behind.
#include <string>
#include <string_view>
#include <vector>

#include "emoface/expression/face.h"

namespace emoface::expression {

// --- OBJ + FDP --------------------------------------------------------------

// Writes the mesh as OBJ (v, vt, vn, triangles; one OBJ vertex per mesh
// vertex, so FDP vertex indices stay valid). With `material_file` non-empty
// it adds `mtllib material_file` / `usemtl face`.
void save_obj(const Face& face, const std::string& path, const std::string& material_file = "");

// Writes a material file (newmtl face, map_Kd texture_file).
void save_mtl(const std::string& path, const std::string& texture_file);

// Writes the FDP JSON for `face`: its feature points (vertex index or free
// position), eyeballs, vertex parts, welded seams, pivots, texture box, and
// the names of its mesh and base-colour files (relative to the FDP).
void save_fdp(const Face& face, const std::string& path, const std::string& mesh_file,
              const std::string& base_colour_file = "");

// Loads a user's face: an OBJ mesh (polygons are fanned into triangles; an
// OBJ vertex used with several texture coordinates becomes several welded
// vertices; FDP vertex indices are 0-based indices of the OBJ's `v` lines)
// and its FDP JSON. FAPU are computed from the feature points; pivots and
// texture box are estimated when the FDP omits them.
Face load_obj_with_fdp(const std::string& obj_path, const std::string& fdp_path);
// The same from the two files' text; the names are for messages (and the
// FDP's folder for its base-colour file).
Face parse_obj_with_fdp(std::string_view obj_text, const std::string& obj_path, std::string_view fdp_text,
                        const std::string& fdp_path);

// --- Candide-3 --------------------------------------------------------------

struct Candide3Report {
    int vertices = 0;
    int triangles = 0;
    // Feature points Candide-3 (or this file) has no vertex for, in table
    // order; they stay absent on the face, never invented.
    std::vector<std::string> missing_feature_points;
    // The file's x axis pointed to the face's right (or z away from the
    // viewer) and was flipped to the MPEG-4 frame.
    bool mirrored_x = false;
    bool flipped_z = false;
};

// Reads the Candide-3 wireframe text format: "# VERTEX LIST:" then a count
// and "x y z" lines, "# FACE LIST:" then a count and "a b c" lines (0-based);
// other sections (animation and shape units, parameters) are skipped.
// Feature points come from fap::feature_points()' candide3_vertices (the mean
// of several vertices where the table lists several, as a free position).
Face load_candide3(const std::string& path, Candide3Report* report = nullptr);
Face parse_candide3(std::string_view text, const std::string& source_name, Candide3Report* report = nullptr);

// --- Images -----------------------------------------------------------------

// Writes an RGBA8 image as PNG (uncompressed deflate blocks: larger files,
// no zlib dependency).
void save_png(const Image& image, const std::string& path);

}  // namespace emoface::expression
