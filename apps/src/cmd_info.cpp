// emoface info FILE... [--json]: what a FAP file holds.
#include <algorithm>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "au_label.h"
#include "clamp_warning.h"
#include "command.h"
#include "emoface/common/error.h"
#include "emoface/expression/capture.h"
#include "emoface/expression/face_state.h"
#include "emoface/fap/fap_io.h"

namespace {

using namespace emoface::fap;

struct FapRange {
    int fap;
    double min, max;
    std::size_t frames;  // frames that transmit it
};

// One FAP 1 viseme or FAP 2 expression code over the file: the frames that
// select it (by index from 0, as play --frames and inspect --frame count)
// and, for an expression, the range of its intensity there (0..63).
struct CodeUse {
    std::size_t frames = 0;
    std::size_t first = 0, last = 0;
    int min = 0, max = 0;
    void add(std::size_t frame, int value) {
        if (frames == 0) first = frame, min = max = value;
        last = frame;
        min = std::min(min, value);
        max = std::max(max, value);
        ++frames;
    }
};

struct Summary {
    std::vector<FapRange> moving;  // low-level FAPs transmitted with some non-zero value
    std::size_t viseme_frames = 0;
    std::map<int, CodeUse> visemes;      // code 1..14 -> use (0 is no viseme)
    std::size_t expression_frames = 0;
    std::map<int, CodeUse> expressions;  // code 1..6 -> use (neutral, 0, is no expression)
};

Summary summarize(const FapStream& s) {
    Summary out;
    for (int fap = 3; fap <= kFapCount; ++fap) {
        FapRange r{fap, 0, 0, 0};
        bool nonzero = false;
        for (const FapFrame& f : s.frames) {
            if (!f.has(fap)) continue;
            const double v = f.get(fap);
            r.min = r.frames == 0 ? v : std::min(r.min, v);
            r.max = r.frames == 0 ? v : std::max(r.max, v);
            ++r.frames;
            nonzero = nonzero || v != 0;
        }
        if (nonzero) out.moving.push_back(r);
    }
    for (std::size_t k = 0; k < s.frames.size(); ++k) {
        const FapFrame& f = s.frames[k];
        if (f.has(1)) {
            ++out.viseme_frames;
            // Only where each viseme shows: how the blend weighs the two
            // depends on the file's writer (a one-value FAP 1 has no blend).
            const Viseme& v = f.viseme;
            if (v.select1 != 0) out.visemes[v.select1].add(k, 0);
            if (v.select2 != 0 && v.select2 != v.select1) out.visemes[v.select2].add(k, 0);
        }
        if (f.has(2)) {
            ++out.expression_frames;
            const Expression& e = f.expression;
            if (e.select1 != 0) out.expressions[e.select1].add(k, e.intensity1);
            if (e.select2 != 0 && e.select2 != e.select1) out.expressions[e.select2].add(k, e.intensity2);
        }
    }
    return out;
}

const char* frames_word(std::size_t n) { return n == 1 ? "frame" : "frames"; }

std::string code_label(std::string_view name, int code) {
    return name.empty() ? fmt::format("code {}", code) : std::string(name);
}

void print_text(const std::string& path, const FapStream& s) {
    const Summary sum = summarize(s);
    fmt::print("{}\n", path);
    fmt::print("  version   {}\n", s.version);
    fmt::print("  name      {}\n", s.name.empty() ? "(none)" : s.name);
    fmt::print("  fps       {}\n", s.fps);
    if (s.frames.empty())
        fmt::print("  frames    0\n");
    else
        fmt::print("  frames    {} (numbered {}..{})\n", s.frames.size(), s.frames.front().number,
                   s.frames.back().number);
    fmt::print("  duration  {:.3f} s\n", s.duration());
    // What moves the face, through whichever channel: low-level FAPs, FAP 1
    // visemes, FAP 2 expressions (a file may drive it by FAP 2 alone).
    std::vector<std::string> movers;
    if (!sum.moving.empty()) movers.push_back(fmt::format("{} low-level FAPs", sum.moving.size()));
    if (!sum.visemes.empty()) movers.push_back(fmt::format("{} visemes (FAP 1)", sum.visemes.size()));
    const auto expressions = std::count_if(sum.expressions.begin(), sum.expressions.end(),
                                           [](const auto& e) { return e.second.max > 0; });
    if (expressions > 0) movers.push_back(fmt::format("{} expressions (FAP 2)", expressions));
    if (movers.empty())
        fmt::print("  moving    nothing: every frame is the neutral face\n");
    else
        fmt::print("  moving    {}{}\n", fmt::join(movers, ", "),
                   sum.moving.empty() ? "; no low-level FAP" : "");
    for (const FapRange& r : sum.moving)
        // 176, not 176.00000000000003 (a capture's interpolation); 0, not -0.
        fmt::print("    {:>2} {:<22} {:g} .. {:g}\n", r.fap, fap_info(r.fap).name, r.min + 0.0, r.max + 0.0);
    auto span = [](const CodeUse& u) {
        return fmt::format("{} {} in {}..{}", u.frames, frames_word(u.frames), u.first, u.last);
    };
    if (sum.viseme_frames == 0) {
        fmt::print("  FAP 1     not used\n");
    } else {
        fmt::print("  FAP 1     {} {}, {}\n", sum.viseme_frames, frames_word(sum.viseme_frames),
                   sum.visemes.empty() ? std::string("no viseme (code 0 only)")
                                       : fmt::format("{} visemes (frames counted from 0):", sum.visemes.size()));
        for (const auto& [code, use] : sum.visemes)
            fmt::print("    {:>2} {:<9} {}\n", code, code_label(viseme_name(code), code), span(use));
    }
    if (sum.expression_frames == 0) {
        fmt::print("  FAP 2     not used\n");
    } else {
        fmt::print("  FAP 2     {} {}, {}\n", sum.expression_frames, frames_word(sum.expression_frames),
                   sum.expressions.empty()
                       ? std::string("neutral only")
                       : fmt::format("{} expressions (intensity 0..63; frames counted from 0):",
                                     sum.expressions.size()));
        for (const auto& [code, use] : sum.expressions)
            fmt::print("    {:<9} intensity {:>2}..{:<2}  {}\n", code_label(expression_name(code), code), use.min,
                       use.max, span(use));
    }
    if (s.warnings.empty()) {
        fmt::print("  warnings  none\n");
    } else {
        fmt::print("  warnings  {}\n", s.warnings.size());
        for (const std::string& w : s.warnings) fmt::print("    {}\n", w);
    }
}

// The FACS Action Units a file shows (face_state on each frame, its AUs
// inferred from the FAPs): per AU side the peak over the frames, or with
// `frame` >= 0 that frame's (by index).
emoface::expression::AuIntensities action_units_of(const FapStream& s, const emoface::expression::EmotionProfiles& p,
                                                   int frame) {
    emoface::expression::AuIntensities out;
    const FapStream resolved = resolve_untransmitted(s);
    for (std::size_t k = 0; k < resolved.frames.size(); ++k) {
        if (frame >= 0 && k != std::size_t(frame)) continue;
        const auto aus = emoface::expression::face_state(resolved.frames[k], p).aus;
        for (int a = 0; a < emoface::expression::kAuNumberLimit; ++a) {
            out.left[a] = std::max(out.left[a], aus.left[a]);
            out.right[a] = std::max(out.right[a], aus.right[a]);
        }
    }
    return out;
}

using emoface::apps::kShownAuIntensity;

nlohmann::json to_json(const std::string& path, const FapStream& s) {
    const Summary sum = summarize(s);
    nlohmann::json j;
    j["file"] = path;
    j["version"] = s.version;
    j["name"] = s.name;
    j["fps"] = s.fps;
    j["frames"] = s.frames.size();
    j["first_frame_number"] = s.frames.empty() ? nlohmann::json() : nlohmann::json(s.frames.front().number);
    j["last_frame_number"] = s.frames.empty() ? nlohmann::json() : nlohmann::json(s.frames.back().number);
    j["duration_s"] = s.duration();
    j["moving_faps"] = nlohmann::json::array();
    for (const FapRange& r : sum.moving)
        j["moving_faps"].push_back({{"fap", r.fap},
                                    {"name", fap_info(r.fap).name},
                                    {"min", r.min},
                                    {"max", r.max},
                                    {"frames", r.frames}});
    std::vector<int> viseme_codes;
    nlohmann::json visemes = nlohmann::json::array();
    for (const auto& [code, use] : sum.visemes) {
        viseme_codes.push_back(code);
        visemes.push_back({{"code", code},
                           {"name", viseme_name(code)},
                           {"frames", use.frames},
                           {"first_frame", use.first},
                           {"last_frame", use.last}});
    }
    j["viseme"] = {{"frames", sum.viseme_frames}, {"codes", viseme_codes}, {"visemes", visemes}};
    nlohmann::json expressions = nlohmann::json::array();
    for (const auto& [code, use] : sum.expressions)
        expressions.push_back({{"code", code},
                               {"name", expression_name(code)},
                               {"min_intensity", use.min},
                               {"max_intensity", use.max},
                               {"frames", use.frames},
                               {"first_frame", use.first},
                               {"last_frame", use.last}});
    j["expression"] = {{"frames", sum.expression_frames}, {"expressions", expressions}};
    j["warnings"] = s.warnings;
    return j;
}

void add_info_command(CLI::App& root) {
    auto* sub = root.add_subcommand(
        "info",
        "Summarise animation files (FAP, OpenFace 2.0, Live Link Face or MediaPipe CSV): version, name, fps, "
        "frames, duration, moving FAPs, FAP 1/2 use, action units, warnings");
    auto files = std::make_shared<std::vector<std::string>>();
    auto json = std::make_shared<bool>(false);
    sub->add_option("files", *files, "Animation files: FAP, or OpenFace, Live Link Face or MediaPipe CSV (told from the content)")->required();
    sub->add_flag("--json", *json, "Print a JSON array, one object per file");
    auto data = std::make_shared<std::string>(EMOFACE_DATA_DIR);
    auto frame = std::make_shared<int>(-1);
    sub->add_option("--data", *data, "The project's data folder (the AU and ARKit tables)")->capture_default_str();
    sub->add_option("--frame", *frame, "Show this frame's action units (index from 0) instead of their peaks")
        ->check(CLI::NonNegativeNumber);
    sub->callback([files, json, data, frame] {
        const auto profiles = emoface::expression::load_emotion_profiles(*data + "/expression/emotions.json");
        // Every file is reported; a bad one is named on stderr and makes the
        // exit code 2 once the others are done.
        std::vector<std::string> failures;
        nlohmann::json all = nlohmann::json::array();
        for (const std::string& path : *files) {
            try {
                const auto animation = emoface::expression::read_animation_file(path, *data);
                const FapStream& s = animation.stream;
                if (*frame >= 0 && std::size_t(*frame) >= s.frames.size())
                    throw emoface::InputError(fmt::format("info: {}: --frame {} is past its {} frames", path, *frame,
                                                          s.frames.size()));
                const auto aus = action_units_of(s, profiles, *frame);
                // What play would clamp, on stderr so that --json stays clean.
                emoface::apps::warn_clamped_faps("info", path, s, *data);
                const std::string which = *frame >= 0 ? fmt::format("frame {}", *frame) : "peak";
                if (*json) {
                    nlohmann::json j = to_json(path, s);
                    j["format"] = emoface::expression::animation_format_name(animation.format);
                    nlohmann::json a = nlohmann::json::object();
                    for (int n = 1; n < emoface::expression::kAuNumberLimit; ++n) {
                        if (aus.left[n] >= kShownAuIntensity) a[fmt::format("AU{}L", n)] = aus.left[n];
                        if (aus.right[n] >= kShownAuIntensity) a[fmt::format("AU{}R", n)] = aus.right[n];
                    }
                    j["action_units"] = {{"of", which}, {"intensities", a}};
                    all.push_back(j);
                } else {
                    print_text(path, s);
                    if (animation.format != emoface::expression::AnimationFormat::Fap)
                        fmt::print("  format    {} (resampled at a constant frame rate)\n",
                                   emoface::expression::animation_format_name(animation.format));
                    fmt::print("  AUs       {} ({}; {} and above)\n", emoface::apps::au_label(aus), which,
                               kShownAuIntensity);
                }
            } catch (const emoface::Error& e) {
                failures.push_back(e.what());
                if (*json) all.push_back({{"file", path}, {"error", e.what()}});
            }
        }
        if (*json) fmt::print("{}\n", all.dump(2));
        std::fflush(stdout);
        if (failures.empty()) return;
        // main prints the last one; the others go out the same way here.
        for (std::size_t i = 0; i + 1 < failures.size(); ++i)
            std::fprintf(stderr, "emoface: %s\n", failures[i].c_str());
        throw emoface::InputError(failures.back());
    });
}

}  // namespace

EMOFACE_COMMAND(add_info_command)
