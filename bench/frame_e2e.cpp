// bench/frame_e2e: the whole frame on the GPU machine (issues 6, 13). Per
// frame: sample the FAP stream, layout, morph of the key maps into the
// interop texture, the geometry (rig, normals, wrinkle UVs, tangent frames:
// on the GPU into the vertex buffers with --geometry gpu, else on the CPU and
// uploaded), bump-mapped draw, fence. Prints the thesis's
// stage table (allocate, upload, per-frame morph, bump-mapped draw, whole
// frame) as medians, and compares one frame with a reference render (the same
// frame drawn on the CPU backend and llvmpipe, saved with --save), printing
// the PSNR. Also the frame period in steady state with frames in flight
// (throughput; --frames-in-flight 2: the pipelined GPU frame) beside the
// single frame's latency (sample .. fence, nothing else in flight). Links neither OpenImageIO nor OpenCV, so it can be carried to the
// GPU machine with its few libraries (frames are written as binary PPM).
#include <epoxy/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#if EMOFACE_BENCH_CUDA
#include <cuda_runtime.h>
#endif

#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/expression/default_face.h"
#include "emoface/fap/fap_io.h"
#include "emoface/render/face_assets.h"
#include "emoface/render/face_geometry.h"
#include "emoface/render/face_scene.h"
#include "emoface/render/image_diff.h"
#include "emoface/render/platform.h"

namespace {

using namespace emoface;
using Clock = std::chrono::steady_clock;

double ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

struct Series {
    std::vector<double> v;
    void add(double x) { v.push_back(x); }
    double pct(double p) const {
        if (v.empty()) return NAN;
        std::vector<double> s = v;
        const auto k = std::size_t(std::lround(p * double(s.size() - 1)));
        std::nth_element(s.begin(), s.begin() + std::ptrdiff_t(k), s.end());
        return s[k];
    }
    double median() const { return pct(0.5); }
};

void write_ppm(const std::string& path, const render::ImageRGBA8& img) {
    std::string bytes = fmt::format("P6\n{} {}\n255\n", img.width, img.height);
    for (std::size_t i = 0; i < img.pixels.size(); i += 4)
        bytes.append(reinterpret_cast<const char*>(&img.pixels[i]), 3);
    write_file_atomically(path, bytes, "frame_e2e");
}

render::ImageRGBA8 read_ppm(const std::string& path) {
    std::ifstream f(path, std::ios::binary);
    std::string magic;
    int w = 0, h = 0, maxv = 0;
    f >> magic >> w >> h >> maxv;
    f.get();
    if (!f || magic != "P6" || maxv != 255 || w <= 0 || h <= 0 || w > 16384 || h > 16384)
        fail<InputError>("frame_e2e: {}: not a binary 8-bit PPM", path);
    render::ImageRGBA8 img(w, h);
    std::vector<char> rgb(std::size_t(w) * h * 3);
    f.read(rgb.data(), std::streamsize(rgb.size()));
    if (!f) fail<InputError>("frame_e2e: {}: truncated", path);
    for (std::size_t i = 0, n = std::size_t(w) * h; i < n; ++i) {
        for (int c = 0; c < 3; ++c) img.pixels[4 * i + c] = std::uint8_t(rgb[3 * i + c]);
        img.pixels[4 * i + 3] = 255;
    }
    return img;
}

void fence() {
    GLsync sync = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glClientWaitSync(sync, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(10) * 1000000000ull);
    glDeleteSync(sync);
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"emoface end-to-end frame benchmark (FAP sample to fenced draw)"};
    std::string data_dir = EMOFACE_DATA_DIR, fap_path, save, compare, backend_name = "auto";
    std::string frames_name = "mesh", accuracy = "exact", geometry = "auto";
    int frames = 500, warmup = 30, map_size = 2048, width = 1920, height = 1080, samples = 4;
    int check_frame = 25, frames_in_flight = 1, ahead = 0;
    double face_scale = 1.0, min_psnr = 30.0;
    app.add_option("--data", data_dir, "the project's data folder");
    app.add_option("--fap", fap_path, "FAP file to play (default: data/fap/demo_tour.fap)");
    app.add_option("--frames", frames, "timed frames (median over them)")->check(CLI::Range(1, 100000));
    app.add_option("--warmup", warmup, "untimed frames first")->check(CLI::Range(0, 10000));
    app.add_option("--map-size", map_size, "wrinkle map side")->check(CLI::Range(64, 8192));
    app.add_option("--width", width)->check(CLI::Range(16, 8192));
    app.add_option("--height", height)->check(CLI::Range(16, 8192));
    app.add_option("--samples", samples, "MSAA samples")->check(CLI::Range(1, 16));
    std::string shading = "skin";
    app.add_option("--shading", shading, "skin (data/render/skin.json) or thesis (Blinn-Phong)")
        ->check(CLI::IsMember({"skin", "thesis"}));
    app.add_option("--face-scale", face_scale, "default face mesh resolution scale")->check(CLI::Range(0.1, 2.0));
    app.add_option("--backend", backend_name, "morph backend: auto, cpu, cuda");
    app.add_option("--tangents", frames_name,
                   "wrinkle UVs and tangent frames: mesh (CPU, uploaded) or shader (closed form)")
        ->check(CLI::IsMember({"mesh", "shader"}));
    app.add_option("--geometry", geometry,
                   "rig, normals and tangent frames: gpu (CUDA, into the vertex buffers), cpu, or auto "
                   "(gpu with a CUDA device and morph backend)")
        ->check(CLI::IsMember({"auto", "gpu", "cpu"}));
    app.add_option("--accuracy", accuracy, "morph accuracy: exact or fast")
        ->check(CLI::IsMember({"exact", "fast"}));
    app.add_option("--frames-in-flight", frames_in_flight,
                   "2: the pipelined GPU frame (frame n+1's morph and geometry beside frame n's draw; "
                   "FaceSceneOptions::frames_in_flight)")
        ->check(CLI::Range(1, 2));
    app.add_option("--ahead", ahead,
                   "throughput pass: frames the host may have submitted and not finished when it starts "
                   "the next (0: it waits for each frame's fence first; on the H100 with interop, 1 or 2 cost "
                   "~1.4 ms a frame more: docs/PERFORMANCE.md, fourth round)")
        ->check(CLI::Range(0, 8));
    app.add_option("--check-frame", check_frame, "stream frame saved or compared");
    app.add_option("--save", save, "write the check frame as PPM (the reference, on the CPU)");
    app.add_option("--compare", compare, "PPM reference to compare the check frame with");
    app.add_option("--min-psnr", min_psnr, "fail below this PSNR (dB)");
    CLI11_PARSE(app, argc, argv);

    try {
        const morph::Backend backend = backend_name == "cpu"    ? morph::Backend::Cpu
                                       : backend_name == "cuda" ? morph::Backend::Cuda
                                                                : morph::Backend::Auto;
        if (fap_path.empty()) fap_path = data_dir + "/fap/demo_tour.fap";
        const fap::FapStream stream = fap::resolve_untransmitted(fap::read_fap_file(fap_path));

        // Setup (not per frame): face, rig, profiles, lines, keys.
        auto t = Clock::now();
        render::FaceAssetsOptions ao;
        ao.face.resolution_scale = face_scale;
        ao.wrinkle_map_size = map_size;
        const auto assets = render::load_default_face_assets(data_dir, ao);
        const double assets_ms = ms(Clock::now() - t);
        const expression::Face& face = assets->face;

        render::PlatformOptions po;
        po.width = width;
        po.height = height;
        po.samples = samples;
        po.cuda_device = 0;
        render::HeadlessPlatform platform(po);
        render::FaceSceneOptions so;
        so.backend = backend;
        so.frames = frames_name == "shader" ? render::WrinkleFrames::Shader : render::WrinkleFrames::Mesh;
        so.morph.accuracy = accuracy == "fast" ? morph::Accuracy::Fast : morph::Accuracy::Exact;
        so.geometry = geometry == "gpu"   ? render::GeometryDevice::Gpu
                      : geometry == "cpu" ? render::GeometryDevice::Cpu
                                          : render::GeometryDevice::Auto;
        so.frames_in_flight = frames_in_flight;
        t = Clock::now();
        render::FaceScene scene(platform, face, *assets->rig, assets->keys, assets->lines, so);
        const double scene_ms = ms(Clock::now() - t);
        const morph::SetupTimes setup = scene.morpher().setup_times();

        std::printf("frame_e2e: %s\n", platform.description().c_str());
        std::printf("  morph: %s backend (%s), %s; %d keys %dx%d, %zu lines; interop %s\n",
                    morph::to_string(scene.morpher().backend()), accuracy.c_str(),
                    morph::cuda_device_description().c_str(), scene.key_count(), map_size,
                    map_size, assets->lines.size(), scene.uses_interop() ? "yes" : "no");
        std::printf("  rig, normals: %s; wrinkle UVs and tangent frames: %s\n",
                    scene.uses_gpu_geometry() ? "GPU (CUDA into the vertex buffers)" : "CPU (all cores), uploaded",
                    frames_name == "shader"       ? "vertex shader (closed form)"
                    : scene.uses_gpu_geometry() ? "GPU (CUDA into the vertex buffers)"
                                                : "CPU (TangentFrames), uploaded");
        if (scene.uses_gpu_geometry()) {
            const render::CudaGeometry probe(*scene.geometry());
            std::printf("  GPU geometry: %d part vertices, %d of them (fans' poles) with a warp each\n",
                        scene.geometry()->view().part_vertices, probe.split_vertices());
        }
        std::printf("  face: %zu vertices, %zu triangles; frame %dx%d, %d samples; FAP %s, %zu frames at %g fps\n",
                    face.mesh.n_vertices(), face.mesh.n_faces(), width, height, platform.samples(),
                    fap_path.c_str(), stream.frames.size(), stream.fps);
        std::printf("  setup: face, rig, profiles and keys %.0f ms, scene %.0f ms\n", assets_ms, scene_ms);
        const bool pipelined = scene.frames_in_flight() == 2;
        std::printf("  frames in flight: %d%s\n", scene.frames_in_flight(),
                    pipelined ? " (pipelined: draw() draws the frame before the last update())"
                    : frames_in_flight == 2 ? " (2 asked: needs the CUDA morph through interop and the GPU geometry)"
                                            : "");

        render::DrawOptions draw;
        draw.camera = scene.frontal_camera(float(width) / float(height));
        draw.light = scene.portrait_light();
        draw.shading = shading == "thesis" ? render::Shading::Thesis : render::Shading::Skin;
        draw.skin = render::load_skin_shading(data_dir + "/render/skin.json");

        auto frame_at = [&](long i) {
            return stream.sample(double(i % std::max<long>(1, long(stream.frames.size()))) / stream.fps);
        };
        // A frame's state: its FAPs (mix profiles synthesised when it has
        // only FAP 2, viseme mouths added) and its emotion mix.
        auto state_of = [&](const fap::FapFrame& f) {
            return expression::face_state(f, assets->emotions, &assets->visemes);
        };

        // The check frame: saved (reference) or compared.
        if (!save.empty() || !compare.empty()) {
            const expression::FaceState st = state_of(frame_at(check_frame));
            scene.update(st.faps, render::key_weights(assets->keys, st));
            scene.flush_pipeline();  // pipelined: the next draw() draws this frame
            platform.begin_frame();
            scene.draw(draw);
            platform.end_frame();
            const render::ImageRGBA8 img = platform.read_rgba();
            if (!save.empty()) {
                write_ppm(save, img);
                std::printf("  saved frame %d to %s\n", check_frame, save.c_str());
            }
            if (!compare.empty()) {
                const render::ImageRGBA8 ref = read_ppm(compare);
                if (ref.width != img.width || ref.height != img.height)
                    fail("frame_e2e: reference {} is {}x{}, the frame {}x{}", compare, ref.width,
                         ref.height, img.width, img.height);
                const double p = render::diff_images(img, ref).psnr();
                std::printf("  check frame %d vs %s: PSNR %.1f dB (minimum %.1f)\n", check_frame,
                            compare.c_str(), p, min_psnr);
                write_ppm("frame_e2e_check.ppm", img);
                if (!(p >= min_psnr)) {
                    std::fprintf(stderr, "frame_e2e: FAILED: the frame differs from the reference (PSNR %.1f dB < %.1f); it is in frame_e2e_check.ppm\n", p, min_psnr);
                    return 1;
                }
            }
        }

        // Pass 0: throughput, frames in flight. The frame period in steady
        // state: nothing waits for a frame but a limiter (before a frame the
        // host waits until at most --ahead frames are unfinished); with 2
        // frames in flight, frame n+1's morph and geometry are queued beside
        // frame n's draw. Wall time over the timed frames / frames.
        Series period_host;
        double period_ms = 0;
        {
            std::deque<GLsync> queued;
            auto start = Clock::now();
            for (long i = 0; i < warmup + frames; ++i) {
                while (queued.size() > std::size_t(ahead)) {
                    glClientWaitSync(queued.front(), GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(10) * 1000000000ull);
                    glDeleteSync(queued.front());
                    queued.pop_front();
                }
                if (i == warmup) start = Clock::now();
                const auto t0 = Clock::now();
                const expression::FaceState st = state_of(frame_at(i));
                scene.update(st.faps, render::key_weights(assets->keys, st));
                platform.begin_frame();
                scene.draw(draw);
                platform.end_frame();
                queued.push_back(glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0));
                if (i >= warmup) period_host.add(ms(Clock::now() - t0));
            }
            for (GLsync f : queued) {
                glClientWaitSync(f, GL_SYNC_FLUSH_COMMANDS_BIT, GLuint64(10) * 1000000000ull);
                glDeleteSync(f);
            }
            period_ms = ms(Clock::now() - start) / double(frames);
            scene.flush_pipeline();
        }

        // Pass 1: whole frames, nothing but the final fence synchronises.
        // Pipelined: the frame flushed before its draw, so this is one
        // frame's latency with nothing else in flight.
        // The host's share: the frame's parameters (update) and everything
        // up to the draw's submission; the fence's wait is the GPU's.
        // With the GPU geometry, update()'s host stages too (FrameStageTimes).
        Series whole, host_update, host_submit, update_layout_s, update_geometry_s, update_morph_s;
        for (long i = 0; i < warmup + frames; ++i) {
            const auto t0 = Clock::now();
            const expression::FaceState st = state_of(frame_at(i));
            const std::vector<float> w = render::key_weights(assets->keys, st);
            const auto t1 = Clock::now();
            scene.update(st.faps, w);
            scene.flush_pipeline();
            const auto t2 = Clock::now();
            platform.begin_frame();
            scene.draw(draw);
            platform.end_frame();
            const auto t3 = Clock::now();
            fence();
            if (i >= warmup) {
                whole.add(ms(Clock::now() - t0));
                host_update.add(ms(t2 - t1));
                host_submit.add(ms(t3 - t0));
                const render::FrameStageTimes times = scene.last_times();
                update_layout_s.add(times.layout_ms);
                update_geometry_s.add(times.rig_ms);
                update_morph_s.add(times.morph_ms);
            }
        }

        // Pass 2: the same frames with each stage timed on its own (host
        // clocks, CUDA events around map + morph + unmap, a GL timer query
        // around the draw), so the stages' sum exceeds pass 1's frame a little.
        Series sample_s, rig_s, layout_s, uv_s, tangents_s, upload_s, map_s, unmap_s, morph_s, draw_s, geometry_gpu_s;
        GLuint query = 0;
        glGenQueries(1, &query);
#if EMOFACE_BENCH_CUDA
        cudaEvent_t ev0 = nullptr, ev1 = nullptr, ev2 = nullptr, ev3 = nullptr;
        const bool cuda = scene.uses_interop();
        if (cuda) {
            cudaEventCreate(&ev0);
            cudaEventCreate(&ev1);
        }
        const auto geometry_stream = static_cast<cudaStream_t>(scene.geometry_stream());
        if (geometry_stream) {
            cudaEventCreate(&ev2);
            cudaEventCreate(&ev3);
        }
#endif
        // (update_geometry()/update_wrinkles(): not on a pipelined scene.)
        for (long i = 0; i < (pipelined ? 0 : warmup + frames); ++i) {
            auto t0 = Clock::now();
            const expression::FaceState state = state_of(frame_at(i));
            const expression::FapValues& faps = state.faps;
            const std::vector<float> w = render::key_weights(assets->keys, state);
            const double sample_ms = ms(Clock::now() - t0);
#if EMOFACE_BENCH_CUDA
            if (geometry_stream) cudaEventRecord(ev2, geometry_stream);
#endif
            scene.update_geometry(faps);
            const render::FrameStageTimes st = scene.last_times();
            double geometry_gpu_ms = 0;
#if EMOFACE_BENCH_CUDA
            if (geometry_stream) {
                cudaEventRecord(ev3, geometry_stream);
                cudaEventSynchronize(ev3);
                float e = 0;
                cudaEventElapsedTime(&e, ev2, ev3);
                geometry_gpu_ms = e;
            }
#endif
            double map_ms = 0, unmap_ms = 0, morph_ms = 0;
#if EMOFACE_BENCH_CUDA
            if (cuda) {
                void* stream_ptr = scene.morpher().cuda_stream();
                auto s = static_cast<cudaStream_t>(stream_ptr);
                cudaEventRecord(ev0, s);
                t0 = Clock::now();
                const unsigned long long surface = scene.wrinkle_texture().map_surface(stream_ptr);
                map_ms = ms(Clock::now() - t0);
                scene.morpher().morph_to_surface(scene.target_layout(), w, scene.morph_params(), surface);
                t0 = Clock::now();
                scene.wrinkle_texture().unmap(stream_ptr);
                unmap_ms = ms(Clock::now() - t0);
                cudaEventRecord(ev1, s);
                cudaEventSynchronize(ev1);
                float e = 0;
                cudaEventElapsedTime(&e, ev0, ev1);
                morph_ms = e;
            } else
#endif
            {
                t0 = Clock::now();
                scene.update_wrinkles(w);
                morph_ms = ms(Clock::now() - t0);
            }
            glBeginQuery(GL_TIME_ELAPSED, query);
            platform.begin_frame();
            scene.draw(draw);
            platform.end_frame();
            glEndQuery(GL_TIME_ELAPSED);
            fence();
            GLuint64 ns = 0;
            glGetQueryObjectui64v(query, GL_QUERY_RESULT, &ns);
            if (i < warmup) continue;
            sample_s.add(sample_ms);
            geometry_gpu_s.add(geometry_gpu_ms);
            rig_s.add(st.rig_ms);
            layout_s.add(st.layout_ms);
            uv_s.add(st.uv_ms);
            tangents_s.add(st.tangents_ms);
            upload_s.add(st.upload_ms);
            map_s.add(map_ms);
            unmap_s.add(unmap_ms);
            morph_s.add(morph_ms);
            draw_s.add(double(ns) * 1e-6);
        }
        glDeleteQueries(1, &query);

        // Pass 2c (CUDA morph): the morph's kernels alone, into the texture
        // mapped once for all frames (the last frame's layout, each frame's
        // weights), CUDA events around each frame's launches.
        Series morph_alone_s;
#if EMOFACE_BENCH_CUDA
        if (cuda && !pipelined) {
            void* stream_ptr = scene.morpher().cuda_stream();
            const auto s = static_cast<cudaStream_t>(stream_ptr);
            const morph::Layout target = scene.target_layout();
            const unsigned long long surface = scene.wrinkle_texture().map_surface(stream_ptr);
            for (long i = 0; i < warmup + frames; ++i) {
                const std::vector<float> w = render::key_weights(assets->keys, state_of(frame_at(i)));
                cudaEventRecord(ev0, s);
                scene.morpher().morph_to_surface(target, w, scene.morph_params(), surface);
                cudaEventRecord(ev1, s);
                cudaEventSynchronize(ev1);
                float e = 0;
                cudaEventElapsedTime(&e, ev0, ev1);
                if (i >= warmup) morph_alone_s.add(e);
            }
            scene.wrinkle_texture().unmap(stream_ptr);
        }
#endif

        // Pass 3 (GPU geometry): the kernels alone, into device memory of
        // their own (no interop), the rig alone and rig + parts, CUDA events
        // around each launch pair.
        Series rig_alone_s, kernels_alone_s, probe_draw_s, probe_kernels_s, probe_both_s;
#if EMOFACE_BENCH_CUDA
        if (scene.geometry()) {
            render::FaceGeometry rig_only(*assets->rig, face.mesh, {},
                                          {face.texture_box.min.x, face.texture_box.min.y, face.texture_box.max.x,
                                           face.texture_box.max.y});
            render::CudaGeometry rig_gpu(rig_only), all_gpu(*scene.geometry());
            std::vector<float*> shape_d, frame_d;
            for (int p = 0; p < scene.geometry()->part_count(); ++p) {
                float* sp = nullptr;
                float* fp = nullptr;
                const std::size_t bytes = std::size_t(scene.geometry()->part_size(p)) * 6 * sizeof(float);
                cudaMalloc(&sp, bytes);
                if (scene.geometry()->part(p).frames) cudaMalloc(&fp, bytes);
                shape_d.push_back(sp);
                frame_d.push_back(fp);
            }
            cudaEvent_t a0, a1;
            cudaEventCreate(&a0);
            cudaEventCreate(&a1);
            auto timed = [&](render::CudaGeometry& g, const expression::RigFrame& f, const std::vector<float*>& sh,
                             const std::vector<float*>& fr) {
                const auto st = static_cast<cudaStream_t>(g.stream());
                cudaEventRecord(a0, st);
                g.run(f, sh, fr);
                cudaEventRecord(a1, st);
                cudaEventSynchronize(a1);
                float e = 0;
                cudaEventElapsedTime(&e, a0, a1);
                return double(e);
            };
            for (long i = 0; i < warmup + frames; ++i) {
                const expression::RigFrame f = assets->rig->frame(state_of(frame_at(i)).faps);
                const double r_ms = timed(rig_gpu, f, {}, {});
                const double k_ms = timed(all_gpu, f, shape_d, frame_d);
                if (i < warmup) continue;
                rig_alone_s.add(r_ms);
                kernels_alone_s.add(k_ms);
            }
            // Pass 3b: do CUDA kernels and the GL draw run at once? The
            // geometry's kernels (into device memory, no interop, nothing
            // shared with the draw) launched kProbe times, the draw, both:
            // wall time to both done. At once: both ~ max(draw, kernels);
            // one after the other: ~ their sum.
            constexpr int kProbe = 20;
            const expression::RigFrame probe_frame = assets->rig->frame(state_of(frame_at(check_frame)).faps);
            auto kernels = [&] {
                for (int k = 0; k < kProbe; ++k) all_gpu.run(probe_frame, shape_d, frame_d);
            };
            auto drawn = [&] {
                platform.begin_frame();
                scene.draw(draw);
                platform.end_frame();
            };
            for (long i = 0; i < warmup + std::min(frames, 100); ++i) {
                auto t0 = Clock::now();
                drawn();
                fence();
                const double d = ms(Clock::now() - t0);
                t0 = Clock::now();
                kernels();
                all_gpu.finish();
                const double k = ms(Clock::now() - t0);
                t0 = Clock::now();
                kernels();
                drawn();
                fence();
                all_gpu.finish();
                const double b = ms(Clock::now() - t0);
                if (i < warmup) continue;
                probe_draw_s.add(d);
                probe_kernels_s.add(k);
                probe_both_s.add(b);
            }
            cudaEventDestroy(a0);
            cudaEventDestroy(a1);
            for (float* p : shape_d) cudaFree(p);
            for (float* p : frame_d) cudaFree(p);
        }
#endif

        std::printf("\nthesis stage table (medians over %d frames; ms)\n", frames);
        std::printf("  %-44s %10s %10s\n", "stage", "median", "p90");
        auto row = [](const char* name, double median, double p90) {
            std::printf("  %-44s %10.3f %10.3f\n", name, median, p90);
        };
        row("allocate (once: key maps on the device)", setup.allocate_ms, setup.allocate_ms);
        row("upload (once: key maps to the device)", setup.upload_ms, setup.upload_ms);
        row("per-frame morph (map + kernel + unmap)", morph_s.median(), morph_s.pct(0.9));
        row("bump-mapped draw (GL time, + MSAA resolve)", draw_s.median(), draw_s.pct(0.9));
        row("whole frame (sample .. fence)", whole.median(), whole.pct(0.9));
        std::printf("\nissue 13: host, GPU compute, draw, frame (ms)\n");
        row("host: update (parameters, layout, launches)", host_update.median(), host_update.pct(0.9));
        row("host: sample .. draw submitted", host_submit.median(), host_submit.pct(0.9));
        row("GPU: rig + normals + UVs + tangents", geometry_gpu_s.median(), geometry_gpu_s.pct(0.9));
        row("  of which kernels alone (no interop)", kernels_alone_s.median(), kernels_alone_s.pct(0.9));
        row("  of which the rig kernel alone", rig_alone_s.median(), rig_alone_s.pct(0.9));
        row("GPU: morph (map + kernel + unmap)", morph_s.median(), morph_s.pct(0.9));
        row("  of which the morph's kernels alone (no interop)", morph_alone_s.median(), morph_alone_s.pct(0.9));
        row("GPU: compute (geometry + morph, medians)", geometry_gpu_s.median() + morph_s.median(),
            geometry_gpu_s.pct(0.9) + morph_s.pct(0.9));
        row("draw (GL time, + MSAA resolve)", draw_s.median(), draw_s.pct(0.9));
        row("whole frame (sample .. fence)", whole.median(), whole.pct(0.9));
        std::printf("  whole frame - draw: %.3f ms (medians)\n", whole.median() - draw_s.median());
        std::printf("\nthroughput: %d frame(s) in flight, the host at most %d frame(s) ahead (ms)\n",
                    scene.frames_in_flight(), ahead);
        std::printf("  %-44s %10.3f\n", "frame period in steady state (wall / frames)", period_ms);
        if (!pipelined)
            std::printf("  frame period - draw: %.3f ms\n", period_ms - draw_s.median());
        else
            std::printf("  (the draw alone is timed with --frames-in-flight 1: pass 2 needs update_geometry())\n");
        row("host per frame (sample .. draw submitted)", period_host.median(), period_host.pct(0.9));
        std::printf("  single frame, nothing else in flight: the whole frame above (sample .. fence)\n");
        if (!probe_both_s.v.empty()) {
            std::printf("\nCUDA kernels beside the GL draw? (wall ms to done; no interop between them)\n");
            row("draw alone", probe_draw_s.median(), probe_draw_s.pct(0.9));
            row("geometry kernels x20 alone", probe_kernels_s.median(), probe_kernels_s.pct(0.9));
            row("both, the kernels queued first", probe_both_s.median(), probe_both_s.pct(0.9));
            std::printf("  both - max(alone): %.3f ms; both - sum: %.3f ms (near 0: one after the other)\n",
                        probe_both_s.median() - std::max(probe_draw_s.median(), probe_kernels_s.median()),
                        probe_both_s.median() - probe_draw_s.median() - probe_kernels_s.median());
        }
        std::printf("\nper-frame stages in detail (ms)\n");
        row("sample the FAP stream + face state (mix)", sample_s.median(), sample_s.pct(0.9));
        row(scene.uses_gpu_geometry() ? "geometry on the GPU: host (parameters, map, launch, unmap)"
                                      : "rig (FAPs to mesh + normals)",
            rig_s.median(), rig_s.pct(0.9));
        row("layout L* (feature points projected)", layout_s.median(), layout_s.pct(0.9));
        row("wrinkle UVs (vertices projected)", uv_s.median(), uv_s.pct(0.9));
        row("tangent frames", tangents_s.median(), tangents_s.pct(0.9));
        row("vertex upload", upload_s.median(), upload_s.pct(0.9));
        if (scene.uses_gpu_geometry() && scene.uses_interop()) {
            // update() as pass 1 ran it: one mapping for the morph and the geometry.
            row("update(), host: rig frame + layout L*", update_layout_s.median(), update_layout_s.pct(0.9));
            row("update(), host: one map + geometry launches", update_geometry_s.median(), update_geometry_s.pct(0.9));
            row("update(), host: morph launches + one unmap", update_morph_s.median(), update_morph_s.pct(0.9));
        }
        row("interop map (host)", map_s.median(), map_s.pct(0.9));
        row("interop unmap (host)", unmap_s.median(), unmap_s.pct(0.9));
        std::printf("  interop map+unmap per frame: %.1f us (median)\n",
                    (map_s.median() + unmap_s.median()) * 1000.0);
#if EMOFACE_BENCH_CUDA
        if (cuda) {
            cudaEventDestroy(ev0);
            cudaEventDestroy(ev1);
        }
        if (geometry_stream) {
            cudaEventDestroy(ev2);
            cudaEventDestroy(ev3);
        }
#endif
    } catch (const std::exception& e) {
        std::fprintf(stderr, "frame_e2e: %s\n", e.what());
        return 1;
    }
    return 0;
}
