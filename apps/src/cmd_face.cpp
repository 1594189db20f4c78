// emoface face --out face.obj: writes the default face (or a converted
// Candide-3 model) as OBJ + material + base-colour PNG + FDP JSON.
#include <cstdio>
#include <memory>
#include <string>

#include <fmt/format.h>

#include "cli_checks.h"
#include "command.h"
#include "emoface/common/output_batch.h"
#include "emoface/common/error.h"
#include "emoface/expression/default_face.h"
#include "emoface/expression/face_io.h"

namespace {

using namespace emoface::expression;

struct FaceOptions {
    std::string out;
    std::string data = EMOFACE_DATA_DIR;
    std::string candide3;
    double resolution = 1.0;
    int texture_size = 0;
};

void add_face_command(CLI::App& root) {
    auto o = std::make_shared<FaceOptions>();
    auto* sub = root.add_subcommand(
        "face",
        "Write the default face (generated from data/face/face.json) as OBJ with its feature points: "
        "OUT.obj, OUT.mtl, OUT.png (base colour) and OUT.fdp.json (docs/FACE.md)");
    sub->add_option("-o,--out", o->out, "Output .obj path; the other files go beside it")->required();
    sub->add_option("--data", o->data, "Folder holding face/face.json (default: the project's data/)");
    sub->add_option("--resolution", o->resolution, "Mesh resolution scale (1 = face.json's; 0.5 = about a quarter of "
                                                   "the vertices)");
    sub->add_option("--texture-size", o->texture_size, "Base-colour image size in pixels (default: face.json's)");
    sub->add_option("--candide3", o->candide3,
                    "Convert this Candide-3 .wfm instead of the default face; lists the feature points it lacks");
    sub->callback([o] {
        const std::string suffix = ".obj";
        if (o->out.size() <= suffix.size() || o->out.compare(o->out.size() - suffix.size(), suffix.size(), suffix) != 0)
            emoface::fail<emoface::InputError>("face: --out must name an .obj file, found \"{}\"", o->out);
        emoface::apps::check_in_range("face", "--resolution", o->resolution, 0.1, 2.0);
        if (o->texture_size != 0)
            emoface::apps::check_in_range("face", "--texture-size", o->texture_size, 64, 8192,
                                          " (0: face.json's)");
        const std::string stem = o->out.substr(0, o->out.size() - suffix.size());
        // The OBJ, its material, texture and feature points appear together
        // or not at all; the folder is checked before the face is built.
        const auto [folder, obj_name] = emoface::apps::split_output_path(o->out, "face", "--out");
        emoface::OutputBatch batch(folder, "face: --out " + o->out);
        const std::string name_stem = obj_name.substr(0, obj_name.size() - suffix.size());
        Face face;
        if (!o->candide3.empty()) {
            Candide3Report report;
            face = load_candide3(o->candide3, &report);
            fmt::print("{}: {} vertices, {} triangles{}{}\n", o->candide3, report.vertices, report.triangles,
                       report.mirrored_x ? "; x mirrored to the face's left" : "",
                       report.flipped_z ? "; z flipped towards the viewer" : "");
            std::string missing;
            for (const auto& id : report.missing_feature_points) missing += (missing.empty() ? "" : " ") + id;
            fmt::print("feature points Candide-3 lacks ({}): {}\n", report.missing_feature_points.size(), missing);
        } else {
            DefaultFaceOptions options;
            options.resolution_scale = o->resolution;
            options.texture_size = o->texture_size;
            face = make_default_face(o->data + "/face", options);
        }
        const std::string png = face.base_colour.empty() ? std::string() : name_stem + ".png";
        if (!png.empty()) {
            save_png(face.base_colour, batch.stage(png));
            save_mtl(batch.stage(name_stem + ".mtl"), png);
        }
        save_obj(face, batch.stage(obj_name), png.empty() ? std::string() : name_stem + ".mtl");
        save_fdp(face, batch.stage(name_stem + ".fdp.json"), obj_name, png);
        batch.commit();
        fmt::print("{}: {} vertices, {} triangles; feature points in {}{}\n", o->out, face.vertex_count(),
                   face.mesh.n_faces(), stem + ".fdp.json",
                   png.empty() ? std::string()
                               : fmt::format("; base colour {} ({}x{})", stem + ".png", face.base_colour.width,
                                             face.base_colour.height));
        fmt::print("FAPU (x1024): IRISD0 {:.2f}  ES0 {:.2f}  ENS0 {:.2f}  MNS0 {:.2f}  MW0 {:.2f}\n",
                   face.fapu.irisd * 1024, face.fapu.es * 1024, face.fapu.ens * 1024, face.fapu.mns * 1024,
                   face.fapu.mw * 1024);
    });
}

}  // namespace

EMOFACE_COMMAND(add_face_command)
