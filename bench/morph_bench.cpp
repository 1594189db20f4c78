// bench/morph: the morph benchmark (issue 3). Sweeps sizes, line counts and
// key counts over the backends and, in the same run, the thesis's kernel
// structure; prints a Markdown table (ms per frame, G pixel-lines/s, ratio to
// the thesis structure, fast-mode position error) and the thesis's stage
// table. Links no image library, so it runs on the GPU machine as built here.
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "bench_inputs.h"
#include "emoface/common/atomic_file.h"
#include "emoface/common/error.h"
#include "emoface/common/parallel.h"
#include "emoface/common/timing.h"
#include "emoface/morph/morph.h"

#if defined(EMOFACE_BENCH_CUDA)
#include <cuda_runtime.h>

#include "thesis_morph.h"
#endif

namespace {

using namespace emoface;
using morph::Accuracy;
using morph::Backend;
using morph::Morpher;
using morph::MorphParams;

// Processor time of the whole process (all threads), ms: on a loaded
// machine, wall time overstates what a frame costs; this does not.
double process_cpu_ms() {
    timespec ts{};
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
    return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double median(std::vector<double> v) {
    if (v.empty()) return NAN;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Options {
    std::vector<int> sizes{256, 1024, 4096};
    std::vector<int> lines{40, 84, 100};
    std::vector<int> keys{2, 7};
    std::vector<std::string> backends{"cpu", "cuda", "fast", "thesis"};
    std::vector<int> fast_cells{8};
    std::vector<float> fast_reach{4.0f};
    std::vector<int> px;  // CUDA exact: points a thread to sweep (EMOFACE_MORPH_PX), empty = automatic
    int runs = 50;
    int warmup = 5;
    double cpu_budget_s = 20.0;  // per CPU row: fewer runs (at least 5) when a frame is slow
    int error_max_size = 4096;   // fast-mode position error measured up to this size
    int cpu_error_max_size = 1024;
    std::string out;  // also write the report here
    int au_keys = 0;  // > 0: also the per-AU wrinkle case, 1 neutral + au_keys small-region keys
};

struct Row {
    int size = 0, lines = 0, keys = 0;
    std::string backend;
    double ms = NAN;         // per frame, median (batched on CUDA)
    double single_ms = NAN;  // CUDA: one frame alone, median
    double graph_ms = NAN;   // CUDA: per frame, a captured batch replayed as a graph (no host work), median
    double host_us = NAN;    // CUDA: host time to validate, build and enqueue one frame, median
    double cpu_ms = NAN;     // CPU: processor time per frame over all threads, median
    int batch = 1;
    int runs = 0;
    double err_max = NAN, err_p999 = NAN;  // fast: source position error, pixels
    double gpl() const { return static_cast<double>(size) * size * lines / (ms * 1e-3) / 1e9; }
};

struct Stages {
    double allocate_ms = NAN, upload_ms = NAN, frame_ms = NAN, free_ms = NAN;
};

// Fast-mode position error against exact, over every pixel and key.
void position_error(Morpher& m, const morph::Layout& target, MorphParams fast, double& max_err, double& p999) {
    const std::size_t n = static_cast<std::size_t>(m.width()) * m.height() * m.keys();
    std::vector<float> exact(n * 2), approx(n * 2);
    MorphParams e = fast;
    e.accuracy = Accuracy::Exact;
    m.positions_to_host(target, e, exact.data());
    m.positions_to_host(target, fast, approx.data());
    std::vector<float> err(n);
    max_err = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        err[i] = std::hypot(approx[2 * i] - exact[2 * i], approx[2 * i + 1] - exact[2 * i + 1]);
        max_err = std::max(max_err, static_cast<double>(err[i]));
    }
    const std::size_t k = std::min(n - 1, static_cast<std::size_t>(0.999 * n));
    std::nth_element(err.begin(), err.begin() + k, err.end());
    p999 = err[k];
}

// How many input sets to rotate through so consecutive frames do not find
// the previous frame's keys in a 50 MB L2 (at least 2, at most 8).
int rotation(int size, int keys) {
    const double footprint = static_cast<double>(size) * size * 4 * keys;
    return std::clamp(static_cast<int>(std::ceil(3 * 50e6 / footprint)), 2, 8);
}

class Bench {
public:
    explicit Bench(Options o) : o_(std::move(o)) {}

    void run() {
        for (int size : o_.sizes)
            for (int lines : o_.lines) {
                for (int keys : o_.keys) run_config(size, lines, keys);
                if (o_.au_keys > 0) {
                    run_au_config(size, lines, true);
                    run_au_config(size, lines, false);
                }
            }
    }

    std::string report(const std::string& command) const {
        std::ostringstream s;
        s << "command: `" << command << "`\n\n";
        s << "device: " << morph::cuda_device_description() << "; host threads: " << parallel_threads()
          << "; CPU row loops: " << morph::cpu_kernels_name() << "\n\n";
        s << "| size | N | K | backend | ms/frame | single frame ms | graph ms/frame | host µs/frame | CPU ms/frame | "
             "batch | runs | G px-lines/s | x thesis | fast max err px | fast p99.9 err px |\n";
        s << "|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        for (const Row& r : rows_) {
            const double thesis = thesis_ms(r);
            s << "| " << r.size << "² | " << r.lines << " | " << r.keys << " | " << r.backend << " | "
              << fmt(r.ms, 4) << " | " << fmt(r.single_ms, 4) << " | " << fmt(r.graph_ms, 4) << " | "
              << fmt(r.host_us, 1) << " | " << fmt(r.cpu_ms, 2) << " | " << r.batch << " | " << r.runs << " | "
              << fmt(r.gpl(), 1) << " | " << (std::isnan(thesis) || r.backend == "thesis" ? "-" : fmt(thesis / r.ms, 1))
              << " | " << fmt(r.err_max, 3) << " | " << fmt(r.err_p999, 3) << " |\n";
        }
        if (!stages_.empty()) {
            s << "\nStage table (ms; allocate and upload on construction, per-frame median, free on destruction):\n\n";
            s << "| config | implementation | [1] allocate | [2] upload | [3] per frame | [4] free |\n";
            s << "|---|---|---:|---:|---:|---:|\n";
            for (const auto& [name, st] : stages_)
                s << "| " << name.first << " | " << name.second << " | " << fmt(st.allocate_ms, 3) << " | "
                  << fmt(st.upload_ms, 3) << " | " << fmt(st.frame_ms, 4) << " | " << fmt(st.free_ms, 3) << " |\n";
            s << "| 256², N = 84, K = 2 | thesis, GTX 480 (Table 6.1) | 11.67 | 0.90 | 31.81 - 32.05 | - |\n";
        }
        return s.str();
    }

private:
    static std::string fmt(double v, int digits) {
        if (std::isnan(v)) return "-";
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.*f", digits, v);
        return buf;
    }

    double thesis_ms(const Row& r) const {
        for (const Row& t : rows_)
            if (t.backend == "thesis" && t.size == r.size && t.lines == r.lines && t.keys == r.keys) return t.ms;
        return NAN;
    }

    bool wants(const char* b) const {
        return std::find(o_.backends.begin(), o_.backends.end(), b) != o_.backends.end();
    }

    void add(const Row& r) {
        rows_.push_back(r);
        std::fprintf(stderr,
                     "  %5d² N=%3d K=%d %-22s %10.4f ms/frame (single %8.4f, graph %8.4f, host %6.1f us, batch %d, "
                     "runs %d) %8.1f G px-lines/s",
                     r.size, r.lines, r.keys, r.backend.c_str(), r.ms, r.single_ms, r.graph_ms, r.host_us, r.batch,
                     r.runs, r.gpl());
        if (!std::isnan(r.err_max)) std::fprintf(stderr, "  err max %.3f p99.9 %.3f px", r.err_max, r.err_p999);
        std::fprintf(stderr, "\n");
    }

    void run_config(int size, int lines, int keys) {
        std::fprintf(stderr, "config %d² N=%d K=%d\n", size, lines, keys);
        const bool cuda = morph::cuda_available();
        const int sets = rotation(size, keys);
        std::vector<bench::InputSet> inputs;
        for (int s = 0; s < (cuda ? sets : 2); ++s) inputs.push_back(bench::make_input_set(size, lines, keys, 7 + s));
        const std::string config = std::to_string(size) + "², N = " + std::to_string(lines) + ", K = " +
                                   std::to_string(keys);
#if defined(EMOFACE_BENCH_CUDA)
        if (cuda && wants("thesis")) run_thesis(size, lines, keys, inputs[0], config);
        if (cuda && wants("cuda")) {
            if (o_.px.empty()) {
                run_cuda(size, lines, keys, inputs, Accuracy::Exact, 8, 0.0f, "cuda exact", config);
            } else {
                for (int px : o_.px) {
                    setenv("EMOFACE_MORPH_PX", std::to_string(px).c_str(), 1);
                    run_cuda(size, lines, keys, inputs, Accuracy::Exact, 8, 0.0f,
                             "cuda exact px" + std::to_string(px), config);
                }
                unsetenv("EMOFACE_MORPH_PX");
            }
        }
        if (cuda && wants("fast"))
            for (int cell : o_.fast_cells)
                for (float reach : o_.fast_reach)
                    run_cuda(size, lines, keys, inputs, Accuracy::Fast, cell, reach, fast_name("cuda", cell, reach),
                             config);
#endif
        if (wants("cpu")) {
            run_cpu(size, lines, keys, inputs, Accuracy::Exact, 8, 0.0f, "cpu exact");
            for (int cell : o_.fast_cells)
                for (float reach : o_.fast_reach)
                    run_cpu(size, lines, keys, inputs, Accuracy::Fast, cell, reach, fast_name("cpu", cell, reach));
        }
    }

    // The per-AU wrinkle case (bench_inputs.h, make_au_input_set): normal
    // maps over flat skin, weights summing to 5; rows named "... au
    // regions" (small-region keys) and "... au whole" (the same keys
    // declaring the whole map).
    void run_au_config(int size, int lines, bool regions) {
        const int keys = o_.au_keys + 1;
        std::fprintf(stderr, "config %d² N=%d K=%d per-AU keys, %s\n", size, lines, keys,
                     regions ? "small regions" : "whole maps");
        std::vector<bench::InputSet> inputs;
        for (int s = 0; s < 2; ++s) inputs.push_back(bench::make_au_input_set(size, lines, o_.au_keys, regions, 7 + s));
        const std::string suffix = regions ? " au regions" : " au whole";
        base_params_.normal_map = true;
        base_params_.rest = {0.5f, 0.5f, 1.0f, 1.0f};
#if defined(EMOFACE_BENCH_CUDA)
        const std::string config = std::to_string(size) + "², N = " + std::to_string(lines) + ", K = " +
                                   std::to_string(keys) + suffix;
        if (morph::cuda_available() && wants("cuda"))
            run_cuda(size, lines, keys, inputs, Accuracy::Exact, 8, 0.0f, "cuda exact" + suffix, config);
        if (morph::cuda_available() && wants("fast"))
            for (int cell : o_.fast_cells)
                for (float reach : o_.fast_reach)
                    run_cuda(size, lines, keys, inputs, Accuracy::Fast, cell, reach,
                             fast_name("cuda", cell, reach) + suffix, config);
#endif
        if (wants("cpu")) {
            run_cpu(size, lines, keys, inputs, Accuracy::Exact, 8, 0.0f, "cpu exact" + suffix);
            for (int cell : o_.fast_cells)
                for (float reach : o_.fast_reach)
                    run_cpu(size, lines, keys, inputs, Accuracy::Fast, cell, reach, fast_name("cpu", cell, reach) + suffix);
        }
        base_params_ = MorphParams{};
    }

    static std::string fast_name(const char* backend, int cell, float reach) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%s fast c%d r%g", backend, cell, reach);
        return buf;
    }

    void run_cpu(int size, int lines, int keys, const std::vector<bench::InputSet>& inputs, Accuracy acc, int cell,
                 float reach, const std::string& name) {
        std::vector<std::unique_ptr<Morpher>> m;
        for (int s = 0; s < 2; ++s)
            m.push_back(std::make_unique<Morpher>(size, size, morph::PixelFormat::Rgba8, inputs[s].keys(), Backend::Cpu));
        MorphParams params = base_params_;
        params.accuracy = acc;
        params.fast_cell = cell;
        params.fast_reach = reach;
        std::vector<std::uint8_t> out(static_cast<std::size_t>(size) * size * 4);
        std::vector<double> cpu;
        auto frame = [&](int i) {
            const bench::InputSet& in = inputs[i % 2];
            const int t = (i / 2) % static_cast<int>(in.targets.size());
            const double c0 = process_cpu_ms();
            const auto t0 = Clock::now();
            m[i % 2]->morph_to_host(in.targets[t], in.weights[t], params, out.data());
            cpu.push_back(process_cpu_ms() - c0);
            return ms_since(t0);
        };
        const double first = frame(0);
        const int warm = first > 1000.0 ? 0 : std::min(o_.warmup, 2);
        for (int i = 1; i <= warm; ++i) frame(i);
        const int runs = std::clamp(static_cast<int>(o_.cpu_budget_s * 1000.0 / std::max(first, 1e-3)), 5, o_.runs);
        std::vector<double> t;
        cpu.clear();
        for (int i = 0; i < runs; ++i) t.push_back(frame(i));
        Row r;
        r.cpu_ms = median(cpu);
        r.size = size;
        r.lines = lines;
        r.keys = keys;
        r.backend = name;
        r.ms = median(t);
        r.runs = runs;
        if (acc == Accuracy::Fast && size <= o_.cpu_error_max_size)
            position_error(*m[0], inputs[0].targets[0], params, r.err_max, r.err_p999);
        add(r);
    }

#if defined(EMOFACE_BENCH_CUDA)
    static void check(cudaError_t e, const char* what) {
        if (e != cudaSuccess) throw std::runtime_error(std::string(what) + ": " + cudaGetErrorString(e));
    }

    void run_cuda(int size, int lines, int keys, const std::vector<bench::InputSet>& inputs, Accuracy acc, int cell,
                  float reach, const std::string& name, const std::string& config) {
        const int sets = static_cast<int>(inputs.size());
        std::vector<std::unique_ptr<Morpher>> m;
        Stages st;
        for (int s = 0; s < sets; ++s) {
            m.push_back(std::make_unique<Morpher>(size, size, morph::PixelFormat::Rgba8, inputs[s].keys(), Backend::Cuda));
            if (s == 0) {
                st.allocate_ms = m[0]->setup_times().allocate_ms;
                st.upload_ms = m[0]->setup_times().upload_ms;
            }
        }
        MorphParams params = base_params_;
        params.accuracy = acc;
        params.fast_cell = cell;
        params.fast_reach = reach;
        void* dev = nullptr;
        std::size_t pitch = 0;
        check(cudaMallocPitch(&dev, &pitch, static_cast<std::size_t>(size) * 4, size), "cudaMallocPitch");
        cudaEvent_t e0, e1;
        check(cudaEventCreate(&e0), "cudaEventCreate");
        check(cudaEventCreate(&e1), "cudaEventCreate");
        int frame_no = 0;
        auto enqueue = [&](int set) {
            const bench::InputSet& in = inputs[set];
            const int t = frame_no++ % static_cast<int>(in.targets.size());
            m[set]->morph_to_device(in.targets[t], in.weights[t], params, dev, pitch);
        };
        auto timed = [&](int set, int batch) {
            auto stream = static_cast<cudaStream_t>(m[set]->cuda_stream());
            check(cudaEventRecord(e0, stream), "cudaEventRecord");
            for (int b = 0; b < batch; ++b) enqueue(set);
            check(cudaEventRecord(e1, stream), "cudaEventRecord");
            check(cudaEventSynchronize(e1), "cudaEventSynchronize");
            float ms = 0.0f;
            check(cudaEventElapsedTime(&ms, e0, e1), "cudaEventElapsedTime");
            return static_cast<double>(ms) / batch;
        };
        for (int s = 0; s < sets; ++s)
            for (int i = 0; i < o_.warmup; ++i) enqueue(s);
        for (auto& x : m) x->synchronize();

        std::vector<double> single;
        for (int i = 0; i < o_.runs; ++i) single.push_back(timed(i % sets, 1));
        Row r;
        r.size = size;
        r.lines = lines;
        r.keys = keys;
        r.backend = name;
        r.single_ms = median(single);
        // Back-to-back frames hide the launch and host work behind the GPU:
        // batches of about 2 ms of frames.
        r.batch = std::clamp(static_cast<int>(2.0 / r.single_ms), 1, 64);
        std::vector<double> batched, host;
        for (int i = 0; i < o_.runs; ++i) {
            const auto t0 = Clock::now();
            batched.push_back(timed(i % sets, r.batch));
            host.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count() / r.batch);
        }
        r.ms = r.batch == 1 ? r.single_ms : median(batched);
        r.runs = o_.runs;
        // Host time: the batch's wall time is the larger of host enqueue and
        // GPU time, so time the enqueue alone on frames the GPU has finished.
        {
            std::vector<double> host_times;
            for (int i = 0; i < o_.runs; ++i) {
                const int set = i % sets;
                const auto t0 = Clock::now();
                enqueue(set);
                host_times.push_back(std::chrono::duration<double, std::micro>(Clock::now() - t0).count());
                m[set]->synchronize();
            }
            r.host_us = median(host_times);
        }
        // The same frames captured once into a CUDA graph and replayed: the
        // GPU's time per frame without host work or launch gaps.
        r.graph_ms = graph_time(*m[0], [&] { enqueue(0); }, r.batch, e0, e1);
        if (acc == Accuracy::Fast && size <= o_.error_max_size)
            position_error(*m[0], inputs[0].targets[0], params, r.err_max, r.err_p999);
        add(r);

        cudaEventDestroy(e0);
        cudaEventDestroy(e1);
        cudaFree(dev);
        if (acc == Accuracy::Exact) {
            st.frame_ms = r.ms;
            const auto t0 = Clock::now();
            m.clear();
            st.free_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count() / sets;
            stages_[{config, "emoface cuda exact"}] = st;
        }
    }

    // Per-frame GPU time of `batch` frames captured into a graph, or NaN
    // where capture is not possible.
    template <class Enqueue>
    double graph_time(Morpher& m, Enqueue enqueue, int batch, cudaEvent_t e0, cudaEvent_t e1) {
        auto stream = static_cast<cudaStream_t>(m.cuda_stream());
        cudaGraph_t graph = nullptr;
        cudaGraphExec_t exec = nullptr;
        if (cudaStreamBeginCapture(stream, cudaStreamCaptureModeRelaxed) != cudaSuccess) return NAN;
        bool ok = true;
        try {
            for (int b = 0; b < batch; ++b) enqueue();
        } catch (const std::exception&) {
            ok = false;
        }
        ok = cudaStreamEndCapture(stream, &graph) == cudaSuccess && ok;
        ok = ok && cudaGraphInstantiate(&exec, graph, 0) == cudaSuccess;
        std::vector<double> t;
        for (int i = 0; ok && i < o_.runs + 3; ++i) {
            ok = cudaEventRecord(e0, stream) == cudaSuccess && cudaGraphLaunch(exec, stream) == cudaSuccess &&
                 cudaEventRecord(e1, stream) == cudaSuccess && cudaEventSynchronize(e1) == cudaSuccess;
            float ms = 0.0f;
            ok = ok && cudaEventElapsedTime(&ms, e0, e1) == cudaSuccess;
            if (i >= 3) t.push_back(static_cast<double>(ms) / batch);
        }
        if (exec) cudaGraphExecDestroy(exec);
        if (graph) cudaGraphDestroy(graph);
        cudaGetLastError();
        return ok ? median(t) : NAN;
    }

    void run_thesis(int size, int lines, int keys, const bench::InputSet& in, const std::string& config) {
        std::vector<const std::uint8_t*> images;
        for (const auto& i : in.images) images.push_back(i.data());
        Stages st;
        Row r;
        {
            bench::ThesisMorph t(size, size, images, in.layouts);
            MorphParams params;
            for (int i = 0; i < std::min(o_.warmup, 3); ++i) t.frame(in.weights[0], params);
            std::vector<double> times;
            for (int i = 0; i < o_.runs; ++i)
                times.push_back(t.frame(in.weights[i % in.weights.size()], params));
            r.size = size;
            r.lines = lines;
            r.keys = keys;
            r.backend = "thesis";
            r.ms = median(times);
            r.single_ms = r.ms;
            r.runs = o_.runs;
            t.release();
            st.allocate_ms = t.stages().allocate_ms;
            st.upload_ms = t.stages().upload_ms;
            st.free_ms = t.stages().free_ms;
            st.frame_ms = r.ms;
        }
        add(r);
        stages_[{config, "thesis structure"}] = st;
    }
#endif

    Options o_;
    MorphParams base_params_;  // what each row's frames start from (the per-AU case: normal maps over flat skin)
    std::vector<Row> rows_;
    std::map<std::pair<std::string, std::string>, Stages> stages_;
};

}  // namespace

int main(int argc, char** argv) {
    Options o;
    CLI::App app{"bench/morph: Beier-Neely morph benchmark (emoface issue 3)"};
    app.add_option("--sizes", o.sizes, "image sides")->delimiter(',');
    app.add_option("--lines", o.lines, "line counts N")->delimiter(',');
    app.add_option("--keys", o.keys, "key counts K")->delimiter(',');
    app.add_option("--backends", o.backends, "cpu, cuda (exact), fast (cuda fast), thesis")->delimiter(',');
    app.add_option("--fast-cells", o.fast_cells, "fast mode cells (pixels)")->delimiter(',');
    app.add_option("--fast-reach", o.fast_reach, "fast mode reach (cells)")->delimiter(',');
    app.add_option("--px", o.px, "CUDA exact: points a thread to sweep (1, 4, 8)")->delimiter(',');
    app.add_option("--runs", o.runs, "timed runs per row (median)");
    app.add_option("--warmup", o.warmup, "warm-up frames per input set");
    app.add_option("--cpu-budget", o.cpu_budget_s, "seconds per CPU row (at least 5 runs)");
    app.add_option("--error-max-size", o.error_max_size, "largest size whose CUDA fast error is measured");
    app.add_option("--cpu-error-max-size", o.cpu_error_max_size, "largest size whose CPU fast error is measured");
    app.add_option("--out", o.out, "also write the Markdown report to this file");
    app.add_option("--au-keys", o.au_keys,
                   "also the per-AU wrinkle case: 1 neutral + this many small-region keys (e.g. 20), 4 active")
        ->check(CLI::Range(1, Morpher::kMaxKeys - 1));
    CLI11_PARSE(app, argc, argv);

    std::string command = "bench/morph";
    for (int i = 1; i < argc; ++i) command += std::string(" ") + argv[i];
    try {
        Bench bench(o);
        bench.run();
        const std::string report = bench.report(command);
        std::printf("%s", report.c_str());
        if (!o.out.empty()) {
            write_file_atomically(o.out, report, "bench/morph");
        }
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench/morph: %s\n", e.what());
        return 1;
    }
    return 0;
}
