// bench/morph_opencv: the "what a user would write" CPU baseline (issue 3):
// per frame, cv::remap of each key through its precomputed source-position
// map and cv::addWeighted to blend. The maps come from Morpher's positions
// (fast mode, within ~0.1 px of exact) and are built once, outside the
// timing, so this measures only the resampling and blending a user's own
// Beier-Neely code would still need: a lower bound for that approach. Runs
// on this machine only (links OpenCV).
#include <CLI/CLI.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cstdio>
#include <vector>

#include "bench_inputs.h"
#include "emoface/morph/morph.h"

int main(int argc, char** argv) {
    std::vector<int> sizes{256, 512, 1024, 4096};
    std::vector<int> keys{2, 7};
    int lines = 84, runs = 50;
    double budget_s = 20.0;
    CLI::App app{"bench/morph_opencv: OpenCV remap + addWeighted baseline"};
    app.add_option("--sizes", sizes)->delimiter(',');
    app.add_option("--keys", keys)->delimiter(',');
    app.add_option("--lines", lines);
    app.add_option("--runs", runs);
    app.add_option("--cpu-budget", budget_s, "seconds per row (at least 5 runs)");
    CLI11_PARSE(app, argc, argv);

    using namespace emoface;
    std::printf("OpenCV %s, %d threads\n\n", CV_VERSION, cv::getNumThreads());
    std::printf("| size | N | K | opencv remap+addWeighted ms/frame | CPU ms/frame | runs |\n"
                "|---:|---:|---:|---:|---:|---:|\n");
    for (int size : sizes)
        for (int k : keys) {
            const bench::InputSet in = bench::make_input_set(size, lines, k, 7, 1);
            morph::Morpher m(size, size, morph::PixelFormat::Rgba8, in.keys(), morph::Backend::Cpu);
            std::vector<float> pos(static_cast<std::size_t>(size) * size * k * 2);
            morph::MorphParams fast;
            fast.accuracy = morph::Accuracy::Fast;
            m.positions_to_host(in.targets[0], fast, pos.data());
            std::vector<cv::Mat> src, mapx, mapy;
            for (int s = 0; s < k; ++s) {
                src.emplace_back(size, size, CV_8UC4, const_cast<std::uint8_t*>(in.images[s].data()));
                cv::Mat mx(size, size, CV_32FC1), my(size, size, CV_32FC1);
                for (int y = 0; y < size; ++y)
                    for (int x = 0; x < size; ++x) {
                        const std::size_t i = ((static_cast<std::size_t>(y) * size + x) * k + s) * 2;
                        mx.at<float>(y, x) = pos[i] - 0.5f;  // OpenCV puts pixel centres on integers
                        my.at<float>(y, x) = pos[i + 1] - 0.5f;
                    }
                mapx.push_back(mx);
                mapy.push_back(my);
            }
            cv::Mat warped, out;
            std::vector<double> cpu;
            auto frame = [&] {
                timespec c0{}, c1{};
                clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
                const auto t0 = std::chrono::steady_clock::now();
                for (int s = 0; s < k; ++s) {
                    cv::remap(src[s], warped, mapx[s], mapy[s], cv::INTER_LINEAR, cv::BORDER_REPLICATE);
                    if (s == 0)
                        warped.convertTo(out, -1, in.weights[0][0]);
                    else
                        cv::addWeighted(out, 1.0, warped, in.weights[0][s], 0.0, out);
                }
                const double ms =
                    std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
                clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
                cpu.push_back((c1.tv_sec - c0.tv_sec) * 1e3 + (c1.tv_nsec - c0.tv_nsec) * 1e-6);
                return ms;
            };
            const double first = frame();
            const int n = std::clamp(static_cast<int>(budget_s * 1000.0 / std::max(first, 1e-3)), 5, runs);
            std::vector<double> t;
            cpu.clear();
            for (int i = 0; i < n; ++i) t.push_back(frame());
            std::sort(t.begin(), t.end());
            std::sort(cpu.begin(), cpu.end());
            std::printf("| %d² | %d | %d | %.3f | %.3f | %d |\n", size, lines, k, t[t.size() / 2], cpu[cpu.size() / 2],
                        n);
            std::fflush(stdout);
        }
    return 0;
}
