#pragma once
// One frame of the pipeline (DESIGN.md, "One frame") on a face:
//   FAPs -> rig (mesh + feature points) -> target layout L* -> morph of the
//   key wrinkle maps onto L* into the wrinkle texture (interop on the GPU) ->
//   wrinkle UVs -> tangent frames -> draw.
// The wrinkle layout (WrinkleLayout) says which texture space the maps live
// in: projective (L* and the wrinkle UVs are the current feature points and
// vertices projected into the face's texture box, every frame) or anchored
// (the mesh's own UVs: L* and the wrinkle UVs are fixed, the morph blends).
// The face's mesh is drawn as three meshes with their own materials: skin
// (bump-mapped with the wrinkle map), eyeballs (glossy, no wrinkles) and the
// mouth interior (teeth, tongue, cavity; no wrinkles).
#include <array>
#include <bitset>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "emoface/expression/face.h"
#include "emoface/expression/feature_layout.h"
#include "emoface/expression/rig.h"
#include "emoface/expression/wrinkle_map.h"
#include "emoface/morph/morph.h"
#include "emoface/render/platform.h"
#include "emoface/render/renderer.h"
#include "emoface/render/wrinkle_texture.h"

namespace emoface::render {

// A key of the wrinkle morph: a normal map (RGBA8, rows top first, the
// convention of expression/wrinkle_map.h), the layout it was made at and the
// region its wrinkles cover (normalised, in that layout; outside it the map
// is flat skin, so the morph costs only the region). Its name says what
// drives its weight (face_assets.h, key_weights): "neutral", an emotion
// ("joy") or an AU term ("AU6L", "AU17").
struct WrinkleKey {
    std::string name;
    expression::NormalMap map;
    expression::FeatureLayout layout;
    expression::WrinkleRegion region;  // the whole map unless known smaller
};

// Which texture space the wrinkle maps live in (DESIGN.md "Texture layouts").
enum class WrinkleLayout {
    // A frontal projection of the face into its texture box, made again each
    // frame: the keys are made at their own expression's layout and warped
    // onto the current one; the wrinkle UVs are the vertices projected the
    // same way. For faces without UVs of their own (the default face's UVs
    // are this projection at rest).
    Projective,
    // The mesh's own UVs (an artist's, v up as OBJ stores them, used as
    // (u, 1 - v) so that v runs down the image like every map here): the
    // feature points and the wrinkle UVs stay put in that space, so every
    // key's layout is L* and the morph reduces to a weighted blend. Key maps
    // are painted (or generated) in the mesh's UV space.
    Anchored,
};
const char* wrinkle_layout_name(WrinkleLayout layout);  // "projective", "anchored"
// "projective" | "anchored"; nullopt for anything else.
std::optional<WrinkleLayout> parse_wrinkle_layout(std::string_view text);

// The face-space box of `face` as the layout functions take it.
expression::TextureBox layout_box(const expression::Face& face);

// The layout of the face posed by `faps`: projective, its feature points
// projected into the face's texture box; anchored, their UVs
// (expression::anchored_layout(face), the same in every pose).
expression::FeatureLayout posed_layout(const expression::Face& face,
                                       const expression::FaceRig& rig,
                                       const expression::FapValues& faps,
                                       WrinkleLayout layout = WrinkleLayout::Projective);

// The one key generator: the library's wrinkles of `sources` (none: the
// neutral skin) generated at posed_layout(face, rig, pose, layout) (pose:
// what makes those wrinkles, at the intensities of `sources`), size x size
// pixels, rendered only inside their region.
WrinkleKey make_wrinkle_key(const expression::Face& face, const expression::FaceRig& rig,
                            const expression::WrinkleLibrarySpec& spec, std::string name,
                            const expression::WrinkleSources& sources, const expression::FapValues& pose,
                            int size, WrinkleLayout layout = WrinkleLayout::Projective);

// Where the skin's wrinkle UVs and tangent frames come from each frame.
enum class WrinkleFrames {
    // Projected (or the mesh's UVs) and computed on the CPU (TangentFrames on
    // the deformed mesh) and uploaded: works for any UV set and either layout.
    Mesh,
    // Derived in the vertex shader from the position and normal: the
    // projective layout's UVs and their tangent frames have a closed form.
    // Projective layout only.
    Shader,
};

enum class GeometryDevice { Auto, Cpu, Gpu };

struct FaceSceneOptions {
    morph::Backend backend = morph::Backend::Auto;
    WrinkleFrames frames = WrinkleFrames::Mesh;
    // The keys must have been made in this layout's texture space.
    WrinkleLayout layout = WrinkleLayout::Projective;
    // Beier-Neely parameters; normal_map is always set (the keys are normal maps).
    morph::MorphParams morph{};
    Material skin{};  // base_texture: the face's base colour unless set
    Material eyes{};
    Material mouth{};
    // Where the rig, vertex normals, wrinkle UVs and tangent frames run.
    // Gpu: face_geometry.h's CudaGeometry (the CPU path's kernel bodies),
    // written straight into the vertex buffers through CUDA-GL interop; per
    // frame only the rig's parameters leave the host; mesh() then stays at
    // the neutral pose (surface_point() gives the posed surface). Needs a
    // CUDA device sharing the GL context. Auto: the GPU exactly when the
    // morph runs on CUDA through interop (so the GL context is on a CUDA
    // device), else the CPU.
    GeometryDevice geometry = GeometryDevice::Auto;
    // 2: the pipelined GPU frame. update() leaves its frame in flight (the
    // morph and the geometry queued on CUDA into a second wrinkle texture and
    // second vertex buffers) and draw() draws the frame before it, so the
    // GPU computes frame n+1 while it draws frame n, ordered on the GPU only.
    // Needs the CUDA morph through interop and the GPU geometry; otherwise
    // the scene runs as with 1 (frames_in_flight() says which). With 2,
    // update() alone makes frames (update_geometry()/update_wrinkles() refuse).
    int frames_in_flight = 1;
    FaceSceneOptions();
};

// Wall-clock milliseconds of the stages of the last update() (host side; the
// GPU morph is only queued, its time shows in the draw or a later sync).
struct FrameStageTimes {
    double rig_ms = 0, layout_ms = 0, morph_ms = 0, uv_ms = 0, tangents_ms = 0, upload_ms = 0;
};

class WrinkleMorph;
class FaceGeometry;
class CudaGeometry;
class GlBufferInterop;

class FaceScene {
public:
    // `face` and `rig` must outlive the scene. Keys: at most
    // morph::Morpher::kMaxKeys, all of one size. `lines`: the feature lines of
    // the morph (lines_for_face() of the face's present points).
    FaceScene(Platform& platform, const expression::Face& face, const expression::FaceRig& rig,
              std::vector<WrinkleKey> keys, std::vector<expression::FeatureLine> lines,
              const FaceSceneOptions& options = {});
    ~FaceScene();
    FaceScene(const FaceScene&) = delete;
    FaceScene& operator=(const FaceScene&) = delete;

    // One frame: the face deformed by `faps`, the keys blended by
    // `key_weights` (one per key, each >= 0; face_assets.h key_weights) onto
    // the frame's layout, flat skin where their weights sum under 1.
    // The layout first, then the morph is queued (on the GPU it overlaps
    // the CPU work that follows), then update_geometry(faps).
    void update(const expression::FapValues& faps, const std::vector<float>& key_weights);
    // The geometry half: rig, layout L*, wrinkle UVs, tangents, vertex upload.
    void update_geometry(const expression::FapValues& faps);
    // The wrinkle half: the morph onto the current L* into the texture.
    void update_wrinkles(const std::vector<float>& key_weights);
    // The ambient occlusion and the key's cast shadows, baked again on the
    // shape `faps` pose (about a second on the default face). The scene
    // bakes them on the rest shape, and the skin carries them along: right
    // for the small motions of speech, but in a held expression a shadow
    // rides on skin that moved out of it (the nose's shadow onto joy's
    // raised cheek, a dark gash beside the nose). For still pictures.
    void bake_light_on_pose(const expression::FapValues& faps);

    // Draws the three meshes (options.wrinkles false: without the wrinkle map).
    // With frames_in_flight() 2: the frame of the update() before the last
    // one (the last one's is in flight), which it then hands to the next draw.
    void draw(const DrawOptions& options);
    // 1, or 2 when the frame is pipelined (FaceSceneOptions::frames_in_flight).
    int frames_in_flight() const { return back_texture_ ? 2 : 1; }
    // Pipelined: the frame in flight becomes the one draw() draws (as after
    // a draw()); the next draw() then draws the last update(). Else nothing.
    void flush_pipeline();
    // Waits until the GL has done all it was given (glFinish): the draw's
    // rasterisation (on llvmpipe, the CPU's threads) and, through interop,
    // the CUDA morph the draw waits for. A clock read after it bills the
    // draw what it cost, not only its submission.
    void finish();

    // A frontal camera framing the face (neutral pose) for this aspect ratio.
    Camera frontal_camera(float aspect, float fovy_degrees = 20.0f) const;
    // A key light above-left of the camera, as a portrait is lit.
    Light portrait_light() const;

    const FrameStageTimes& last_times() const { return times_; }
    bool uses_interop() const;
    bool uses_gpu_geometry() const { return cuda_geometry_ != nullptr; }
    // The CUDA stream the GPU geometry runs on (null without it).
    void* geometry_stream() const;
    // The geometry the GPU runs (null without it).
    const FaceGeometry* geometry() const { return geometry_.get(); }
    int key_count() const;
    // The full mesh: posed with the CPU geometry, neutral with the GPU's.
    const expression::TriMesh& mesh() const { return mesh_; }
    // A vertex of the full mesh as the last frame posed it (its position and
    // unit vertex normal), on either geometry device: with the GPU's it is
    // computed on the host from the vertex's one-ring (the rig's kernel body
    // over a few vertices), for the few vertices a caller asks for.
    struct SurfacePoint {
        glm::vec3 position, normal;
    };
    SurfacePoint surface_point(int vertex) const;
    const expression::FeatureLayout& layout() const { return layout_; }
    WrinkleLayout layout_kind() const { return layout_kind_; }
    // L* as the morph takes it (one line per feature line), and its parameters.
    const morph::Layout& target_layout() const { return target_; }
    const morph::MorphParams& morph_params() const { return params_; }
    WrinkleTexture& wrinkle_texture() { return *texture_; }
    morph::Morpher& morpher() { return *morpher_; }
    Renderer& renderer() { return *renderer_; }

private:
    struct Part;
    // Rig, wrinkle UVs, tangents, upload; and L* from the deformed feature
    // points when asked (projective layout; the anchored L* never moves).
    void deform(const expression::FapValues& faps, bool layout_from_mesh);
    void deform_on_gpu(const expression::FapValues& faps, bool layout_from_mesh);
    // Bakes the occlusion and the key's shadows on `shape` (the full mesh,
    // with normals) into the skin's and the mouth's meshes; `on_pose`: the
    // shape is the pose drawn, not the rest shape.
    void bake_light(const expression::TriMesh& shape, bool on_pose);
    // update() with the morph and the geometry both on CUDA: one mapping for both.
    void update_on_gpu(const expression::FapValues& faps, const std::vector<float>& key_weights);
    // CudaGeometry::run into the mapped vertex buffers (GlBufferInterop's order).
    void run_gpu_geometry(const std::vector<float*>& buffers);
    // Pipelined: the GPU geometry's buffers (staging_, as the renderer's
    // buffers_ in order) copied into the renderer's, in the GL's order.
    void copy_staging_to_renderer();

    Platform& platform_;
    const expression::Face& face_;
    const expression::FaceRig& rig_;
    expression::TextureBox box_;
    WrinkleLayout layout_kind_;
    std::vector<expression::FeatureLine> lines_;
    expression::TriMesh mesh_;  // the posed full mesh
    expression::DeformedFace deformed_;
    expression::FeatureLayout layout_;
    morph::Layout target_;
    std::vector<Part> parts_;
    std::unique_ptr<Renderer> renderer_;
    std::unique_ptr<WrinkleTexture> texture_;
    std::unique_ptr<morph::Morpher> morpher_;
    std::unique_ptr<WrinkleMorph> wrinkle_morph_;
    morph::MorphParams params_;
    WrinkleFrames frames_;
    FrameStageTimes times_;
    expression::RigFrame frame_;  // the last frame's rig parameters (GPU geometry)
    std::unique_ptr<FaceGeometry> geometry_;
    std::unique_ptr<CudaGeometry> cuda_geometry_;
    std::unique_ptr<GlBufferInterop> geometry_buffers_;
    // Pipelined (frames_in_flight 2): texture_ and geometry_buffers_ (over
    // staging_) hold the frame draw() draws, the back_ ones the frame in
    // flight (mapped for CUDA while pending_); a frame handed over swaps them.
    // The GPU geometry writes GL buffers of its own (staging_) that draw()
    // copies into the renderer's (renderer_buffers_), as the renderer's
    // meshes have one set of vertex buffers.
    std::unique_ptr<WrinkleTexture> back_texture_;
    std::unique_ptr<GlBufferInterop> back_buffers_;
    std::vector<unsigned> staging_, back_staging_, renderer_buffers_;
    std::vector<long long> buffer_bytes_;
    bool pending_ = false, staging_copied_ = false;
};

}  // namespace emoface::render
