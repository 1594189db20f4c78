// The capture readers (capture.h): a CSV's header tells the format, its rows
// become FAP vectors at their times, and those are resampled into a FAP
// stream at a constant frame rate.
#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <optional>

#include <fmt/format.h>

#include "csv_table.h"
#include "emoface/common/error.h"
#include "emoface/common/input_file.h"
#include "emoface/expression/capture.h"
#include "emoface/fap/fap_io.h"
#include "fap_values_reader.h"
#include "json_reader.h"

namespace emoface::expression {
namespace {

using detail::CsvRow;
using detail::CsvTable;

constexpr double kFapPerRadian = 1e5;  // FAP angle unit (AU): 1e-5 rad
constexpr double kOpenFaceAuMax = 5;   // OpenFace's AUxx_r run 0..5 (FACS A..E)
// Coefficients a hair outside [0, 1] are rounding (MediaPipe's scores);
// further out is not an ARKit coefficient.
constexpr double kCoefficientSlack = 0.01;
constexpr double kMaxRowGapFrames = 100;

const std::array<const char*, kArkitShapeCount> kShapeNames{
    "EyeBlinkLeft",     "EyeLookDownLeft",    "EyeLookInLeft",       "EyeLookOutLeft",    "EyeLookUpLeft",
    "EyeSquintLeft",    "EyeWideLeft",        "EyeBlinkRight",       "EyeLookDownRight",  "EyeLookInRight",
    "EyeLookOutRight",  "EyeLookUpRight",     "EyeSquintRight",      "EyeWideRight",      "JawForward",
    "JawLeft",          "JawRight",           "JawOpen",             "MouthClose",        "MouthFunnel",
    "MouthPucker",      "MouthLeft",          "MouthRight",          "MouthSmileLeft",    "MouthSmileRight",
    "MouthFrownLeft",   "MouthFrownRight",    "MouthDimpleLeft",     "MouthDimpleRight",  "MouthStretchLeft",
    "MouthStretchRight", "MouthRollLower",    "MouthRollUpper",      "MouthShrugLower",   "MouthShrugUpper",
    "MouthPressLeft",   "MouthPressRight",    "MouthLowerDownLeft",  "MouthLowerDownRight", "MouthUpperUpLeft",
    "MouthUpperUpRight", "BrowDownLeft",      "BrowDownRight",       "BrowInnerUp",       "BrowOuterUpLeft",
    "BrowOuterUpRight", "CheekPuff",          "CheekSquintLeft",     "CheekSquintRight",  "NoseSneerLeft",
    "NoseSneerRight",   "TongueOut"};

// MediaPipe's Face Landmarker has no tongue.
constexpr std::string_view kShapeMediaPipeLacks = "TongueOut";

std::string camel(std::string_view pascal) {
    std::string s(pascal);
    if (!s.empty()) s[0] = static_cast<char>(std::tolower(static_cast<unsigned char>(s[0])));
    return s;
}

// "AU01_r" -> 1; not such a column -> 0.
int openface_au_column(std::string_view name) {
    if (name.size() != 6 || name.substr(0, 2) != "AU" || name.substr(4) != "_r") return 0;
    if (!std::isdigit(static_cast<unsigned char>(name[2])) || !std::isdigit(static_cast<unsigned char>(name[3])))
        return 0;
    return (name[2] - '0') * 10 + (name[3] - '0');
}

std::string stream_name(const std::string& source) {
    std::string name = std::filesystem::path(source).filename().string();
    for (char& c : name)
        if (static_cast<unsigned char>(c) < 0x20) c = ' ';
    const auto first = name.find_first_not_of(' ');
    if (first == std::string::npos) return "capture";
    name = name.substr(first, name.find_last_not_of(' ') - first + 1);
    return name;
}

// One capture row as FAPs, at its time.
struct Sample {
    double time = 0;
    FapValues faps{};
};

struct Capture {
    std::vector<Sample> samples;
    std::bitset<fap::kFapCount> mask;
    std::vector<std::string> warnings;
};

void mark(std::bitset<fap::kFapCount>& mask, const FapValues& v) {
    for (int f = 2; f < fap::kFapCount; ++f)
        if (v[f] != 0.0) mask.set(f);
}

// Times must grow row by row.
void check_order(const CsvTable& t, const CsvRow& row, const std::vector<Sample>& samples, double time,
                 std::string_view column) {
    if (!samples.empty() && !(time > samples.back().time))
        t.fail(row.line, fmt::format("a {} later than the row before's {:g}", column, samples.back().time),
               fmt::format("{:g} (rows out of time order)", time));
}

// Constant-rate frames over the samples' span: fps from the median interval.
fap::FapStream resample(const Capture& c, const std::string& source, const CsvTable& t) {
    // Frames that transmit no FAP are no animation (the FAP reader drops
    // them), so a capture none of whose columns moves the face is refused.
    if (c.mask.none())
        t.fail(t.header_line, "a column that moves the face (an AU, shape, pose or gaze column the tables know)",
               "none");
    fap::FapStream s;
    s.name = stream_name(source);
    double fps = kMediaPipeFrameFps;
    if (c.samples.size() > 1) {
        std::vector<double> dt;
        for (std::size_t i = 1; i < c.samples.size(); ++i) dt.push_back(c.samples[i].time - c.samples[i - 1].time);
        const double longest = *std::max_element(dt.begin(), dt.end());
        std::nth_element(dt.begin(), dt.begin() + static_cast<std::ptrdiff_t>(dt.size() / 2), dt.end());
        const double median = dt[dt.size() / 2];
        // Without gaps the whole span gives the rate best (timestamps
        // rounded to milliseconds make single intervals uneven).
        fps = longest < 1.5 * median ? static_cast<double>(dt.size()) / (c.samples.back().time - c.samples.front().time)
                                     : 1.0 / median;
        if (std::abs(fps - std::round(fps)) <= 0.01 * fps) fps = std::round(fps);
        if (!(fps >= 0.1 && fps <= 1000))
            t.fail(t.rows.front().line, "rows 1 ms to 10 s apart (a frame rate of 0.1..1000)",
                   fmt::format("a median interval of {:g} s", 1.0 / fps));
    }
    // A gap of many frames between two rows is not a recording (and would
    // cost memory out of all proportion to the file).
    for (std::size_t i = 1; i < c.samples.size(); ++i)
        if ((c.samples[i].time - c.samples[i - 1].time) * fps > kMaxRowGapFrames)
            t.fail(t.rows[i].line, fmt::format("rows at most {} frames apart at {:g} fps", kMaxRowGapFrames, fps),
                   fmt::format("{:g} s after the row before", c.samples[i].time - c.samples[i - 1].time));
    const double t0 = c.samples.front().time, span = c.samples.back().time - t0;
    const double frames = std::floor(span * fps + 0.5) + 1;
    if (frames > static_cast<double>(fap::kMaxFapFrames))
        t.fail(t.rows.front().line, fmt::format("at most {} frames at {:g} fps", fap::kMaxFapFrames, fps),
               fmt::format("{:g} s of rows", span));
    s.fps = fps;
    s.warnings = c.warnings;
    const std::size_t n = static_cast<std::size_t>(frames);
    s.frames.resize(n);
    std::size_t j = 0;  // samples[j].time <= time < samples[j + 1].time
    for (std::size_t k = 0; k < n; ++k) {
        const double time = t0 + static_cast<double>(k) / fps;
        while (j + 1 < c.samples.size() && c.samples[j + 1].time <= time) ++j;
        const Sample& a = c.samples[j];
        const Sample& b = j + 1 < c.samples.size() ? c.samples[j + 1] : a;
        const double w = &a == &b ? 0.0 : std::clamp((time - a.time) / (b.time - a.time), 0.0, 1.0);
        fap::FapFrame& f = s.frames[k];
        f.number = static_cast<long long>(k);
        for (int i = 2; i < fap::kFapCount; ++i)
            if (c.mask[i]) f.set(i + 1, (1 - w) * a.faps[i] + w * b.faps[i]);
    }
    return s;
}

// --- OpenFace ------------------------------------------------------------------

Capture read_openface(const CsvTable& t, const CaptureTables& tables) {
    const int time_col = t.column("timestamp"), success_col = t.column("success"),
              confidence_col = t.column("confidence");
    struct AuColumn {
        int col, au;
    };
    std::vector<AuColumn> aus;
    Capture c;
    for (std::size_t i = 0; i < t.header.size(); ++i) {
        const int au = openface_au_column(t.header[i]);
        if (au == 0) continue;
        if (!tables.aus.find(au)) {
            c.warnings.push_back(fmt::format("{}:{}: column {}: AU{} is not in the AU table; ignored", t.source,
                                             t.header_line, t.header[i], au));
            continue;
        }
        aus.push_back({static_cast<int>(i), au});
    }
    const int pose[3] = {t.column("pose_Rx"), t.column("pose_Ry"), t.column("pose_Rz")};
    const int gaze[2] = {t.column("gaze_angle_x"), t.column("gaze_angle_y")};

    std::vector<bool> good;
    std::size_t held = 0;
    for (const CsvRow& row : t.rows) {
        const double time = t.number(row, time_col);
        check_order(t, row, c.samples, time, "timestamp");
        const double success = t.number(row, success_col), confidence = t.number(row, confidence_col);
        Sample s;
        s.time = time;
        AuIntensities in;
        for (const AuColumn& a : aus) {
            const double v = t.number(row, a.col);
            if (!(v >= 0 && v <= kOpenFaceAuMax))
                t.fail(row.line, fmt::format("an intensity 0..5 in column {}", t.header[std::size_t(a.col)]),
                       fmt::format("{:g}", v));
            const ActionUnit* u = tables.aus.find(a.au);
            in.left[a.au] = v / kOpenFaceAuMax;
            in.right[a.au] = u->sides ? v / kOpenFaceAuMax : in.left[a.au];
        }
        s.faps = tables.aus.faps(in);
        // Camera frame (x right, y down, z away from the camera), radians:
        // +Rx tips the head's top towards the camera (down, FAP 48 +), +Ry
        // turns the face to its own right (FAP 49 -), +Rz tilts the top to
        // the face's left (FAP 50 -).
        if (pose[0] >= 0) s.faps[47] = kFapPerRadian * t.number(row, pose[0]);
        if (pose[1] >= 0) s.faps[48] = -kFapPerRadian * t.number(row, pose[1]);
        if (pose[2] >= 0) s.faps[49] = -kFapPerRadian * t.number(row, pose[2]);
        // gaze_angle_x + looks to the face's left (FAP 23/24 +), _y + down (25/26 +).
        if (gaze[0] >= 0) s.faps[22] = s.faps[23] = kFapPerRadian * t.number(row, gaze[0]);
        if (gaze[1] >= 0) s.faps[24] = s.faps[25] = kFapPerRadian * t.number(row, gaze[1]);
        const bool ok = success != 0 && confidence >= kMinOpenFaceConfidence;
        good.push_back(ok);
        if (!ok) ++held;
        c.samples.push_back(s);
    }
    // Pose, gaze and every AU column's FAPs are in the stream from frame 0,
    // even where they stay 0: the capture says so.
    for (const AuColumn& a : aus) mark(c.mask, tables.aus.find(a.au)->faps);
    for (int i = 0; i < 3; ++i)
        if (pose[i] >= 0) c.mask.set(std::size_t(47 + i));
    if (gaze[0] >= 0) c.mask.set(22).set(23);
    if (gaze[1] >= 0) c.mask.set(24).set(25);

    const auto first_good = std::find(good.begin(), good.end(), true);
    if (first_good == good.end())
        t.fail(t.rows.front().line,
               fmt::format("at least one row with success 1 and confidence >= {:g}", kMinOpenFaceConfidence),
               "none (no face was tracked)");
    const FapValues* last = &c.samples[std::size_t(first_good - good.begin())].faps;
    for (std::size_t i = 0; i < c.samples.size(); ++i) {
        if (good[i]) last = &c.samples[i].faps;
        else c.samples[i].faps = *last;
    }
    if (held > 0)
        c.warnings.push_back(fmt::format("{}: {} of {} rows have success 0 or confidence under {:g}: they hold the "
                                         "last good row's values",
                                         t.source, held, t.rows.size(), kMinOpenFaceConfidence));
    return c;
}

// --- ARKit: Live Link Face and MediaPipe ----------------------------------------

// "HH:MM:SS:FF" with an optional ".fff" subframe (';' too, drop-frame): the
// seconds of the whole part and the frames, or nullopt.
struct Timecode {
    double seconds = 0;  // HH:MM:SS
    double frames = 0;   // FF.fff
};
std::optional<Timecode> parse_timecode(std::string_view s) {
    int parts[4] = {};
    std::size_t pos = 0;
    for (int i = 0; i < 4; ++i) {
        const auto [end, ec] = std::from_chars(s.data() + pos, s.data() + s.size(), parts[i]);
        const std::size_t used = std::size_t(end - (s.data() + pos));
        if (ec != std::errc() || used == 0 || used > 2 || parts[i] < 0) return std::nullopt;
        pos += used;
        if (i < 3) {
            if (pos >= s.size() || (s[pos] != ':' && s[pos] != ';')) return std::nullopt;
            ++pos;
        }
    }
    double sub = 0;
    if (pos < s.size()) {
        if (s[pos] != '.') return std::nullopt;
        const std::string_view digits = s.substr(pos + 1);
        if (digits.empty() || digits.size() > 9) return std::nullopt;
        double scale = 0.1;
        for (char ch : digits) {
            if (!std::isdigit(static_cast<unsigned char>(ch))) return std::nullopt;
            sub += scale * (ch - '0');
            scale *= 0.1;
        }
    }
    if (parts[1] > 59 || parts[2] > 59) return std::nullopt;
    return Timecode{parts[0] * 3600.0 + parts[1] * 60.0 + parts[2], parts[3] + sub};
}

Capture read_arkit(const CsvTable& t, const CaptureTables& tables, AnimationFormat format) {
    Capture c;
    std::vector<int> shape_cols(kArkitShapeCount, -1);
    for (int i = 0; i < kArkitShapeCount; ++i)
        shape_cols[std::size_t(i)] =
            t.column(format == AnimationFormat::LiveLinkFace ? std::string(kShapeNames[std::size_t(i)])
                                                              : camel(kShapeNames[std::size_t(i)]));
    std::vector<std::pair<int, const ArkitAngle*>> angle_cols;
    for (const ArkitAngle& a : tables.arkit.angles)
        if (const int col = t.column(format == AnimationFormat::LiveLinkFace ? a.column : camel(a.column)); col >= 0)
            angle_cols.push_back({col, &a});

    // The time: Live Link's timecode; MediaPipe's time or frame column.
    int time_col = -1;
    double time_scale = 1;  // seconds per unit of the column
    std::string time_name;
    if (format == AnimationFormat::LiveLinkFace) {
        time_col = t.column("Timecode");
    } else {
        for (const char* name : {"timestamp_ms", "time_ms", "timestamp", "time", "seconds", "time_s", "frame"}) {
            if ((time_col = t.column(name)) >= 0) {
                time_name = name;
                break;
            }
        }
        const bool ms = time_name.size() > 3 && time_name.substr(time_name.size() - 3) == "_ms";
        time_scale = time_name == "frame" ? 1.0 / kMediaPipeFrameFps : ms ? 1e-3 : 1.0;
        if (time_name == "frame")
            c.warnings.push_back(fmt::format("{}:{}: timing from column frame at {:g} frames per second (no time "
                                             "column)",
                                             t.source, t.header_line, kMediaPipeFrameFps));
    }

    std::vector<Timecode> timecodes;
    for (const CsvRow& row : t.rows) {
        Sample s;
        if (format == AnimationFormat::LiveLinkFace) {
            const auto tc = parse_timecode(row.fields[std::size_t(time_col)]);
            if (!tc)
                t.fail(row.line, "a Timecode HH:MM:SS:FF or HH:MM:SS:FF.fff",
                       fmt::format("\"{}\"", echo_input(row.fields[std::size_t(time_col)], 40)));
            timecodes.push_back(*tc);
        } else {
            s.time = time_scale * t.number(row, time_col);
            check_order(t, row, c.samples, s.time, time_name);
        }
        for (int i = 0; i < kArkitShapeCount; ++i) {
            const int col = shape_cols[std::size_t(i)];
            if (col < 0) continue;
            double w = t.number(row, col);
            if (!(w >= -kCoefficientSlack && w <= 1 + kCoefficientSlack))
                t.fail(row.line, fmt::format("a coefficient 0..1 in column {}", t.header[std::size_t(col)]),
                       fmt::format("{:g}", w));
            w = std::clamp(w, 0.0, 1.0);
            const FapValues& v = tables.arkit.faps[std::size_t(i)];
            for (int f = 2; f < fap::kFapCount; ++f) s.faps[f] += w * v[f];
        }
        // The angle columns give their FAPs outright (the eye-look shapes'
        // share of the eyeball FAPs gives way to the measured angles).
        for (const auto& [col, angle] : angle_cols) s.faps[angle->fap - 1] = angle->per_radian * t.number(row, col);
        c.samples.push_back(s);
    }
    for (int i = 0; i < kArkitShapeCount; ++i)
        if (shape_cols[std::size_t(i)] >= 0) mark(c.mask, tables.arkit.faps[std::size_t(i)]);
    for (const auto& [col, angle] : angle_cols) c.mask.set(std::size_t(angle->fap - 1));

    if (format == AnimationFormat::LiveLinkFace) {
        // The timecode's own rate is not in the file: the smallest common
        // rate above every frame field seen (a second of rows shows them all).
        double top = 0;
        for (const Timecode& tc : timecodes) top = std::max(top, std::floor(tc.frames));
        double rate = 0;
        for (double r : {24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 120.0})
            if (top < r) {
                rate = r;
                break;
            }
        if (rate == 0)
            t.fail(t.rows.front().line, "Timecode frame fields under 120",
                   fmt::format("a frame field of {:g}", top));
        if (top < 23) {
            rate = 30;
            c.warnings.push_back(fmt::format("{}: the Timecode's frame fields stay under 23: read at 30 timecode "
                                             "frames per second",
                                             t.source));
        }
        for (std::size_t i = 0; i < c.samples.size(); ++i) {
            const double time = timecodes[i].seconds + timecodes[i].frames / rate;
            if (i > 0 && !(time > c.samples[i - 1].time))
                t.fail(t.rows[i].line, "a Timecode later than the row before's",
                       fmt::format("\"{}\" (rows out of time order)",
                                   echo_input(t.rows[i].fields[std::size_t(time_col)], 40)));
            c.samples[i].time = time;
        }
    }
    return c;
}

// --- which format ---------------------------------------------------------------

struct Candidate {
    AnimationFormat format;
    int found = 0;                     // of its columns, present
    std::vector<std::string> missing;  // required and absent
};

std::string list(const std::vector<std::string>& names) {
    std::string out;
    const std::size_t shown = std::min<std::size_t>(names.size(), 8);
    for (std::size_t i = 0; i < shown; ++i) out += (i ? ", " : "") + names[i];
    if (names.size() > shown) out += fmt::format(" and {} more", names.size() - shown);
    return out;
}

std::vector<Candidate> candidates(const CsvTable& t) {
    Candidate of{AnimationFormat::OpenFace, 0, {}}, llf{AnimationFormat::LiveLinkFace, 0, {}},
        mp{AnimationFormat::MediaPipe, 0, {}};
    auto need = [&](Candidate& c, const std::string& name) {
        if (t.column(name) >= 0) ++c.found;
        else c.missing.push_back(name);
    };
    auto bonus = [&](Candidate& c, const std::string& name) {
        if (t.column(name) >= 0) ++c.found;
    };
    for (const char* name : {"timestamp", "success", "confidence"}) need(of, name);
    int au_columns = 0;
    for (const std::string& h : t.header) au_columns += openface_au_column(h) != 0;
    of.found += au_columns;
    if (au_columns == 0) of.missing.push_back("AUxx_r intensity columns (AU01_r ...)");
    for (const char* name : {"frame", "face_id", "pose_Rx", "pose_Ry", "pose_Rz", "gaze_angle_x", "gaze_angle_y"})
        bonus(of, name);

    need(llf, "Timecode");
    need(llf, "BlendShapeCount");
    for (const char* name : kShapeNames) need(llf, name);

    bool time = false;
    for (const char* name : {"timestamp_ms", "time_ms", "timestamp", "time", "seconds", "time_s", "frame"})
        time = time || t.column(name) >= 0;
    if (!time) mp.missing.push_back("a time column (timestamp_ms, time_ms, timestamp, time, seconds, time_s or frame)");
    for (const char* name : kShapeNames)
        if (name == kShapeMediaPipeLacks) bonus(mp, camel(name));
        else need(mp, camel(name));
    return {of, llf, mp};
}

}  // namespace

const char* animation_format_name(AnimationFormat f) {
    switch (f) {
        case AnimationFormat::Fap: return "FAP";
        case AnimationFormat::OpenFace: return "OpenFace 2.0 CSV";
        case AnimationFormat::LiveLinkFace: return "Live Link Face CSV";
        case AnimationFormat::MediaPipe: return "MediaPipe blendshape CSV";
    }
    return "?";
}

const std::vector<std::string>& arkit_shape_names() {
    static const std::vector<std::string> names(kShapeNames.begin(), kShapeNames.end());
    return names;
}

ArkitShapes load_arkit_shapes(const std::string& path, const ActionUnitTable& aus) {
    ArkitShapes out;
    out.faps.assign(kArkitShapeCount, FapValues{});
    detail::read_json_file(path, [&](detail::JsonReader& top) {
        top.comment("_about");
        detail::JsonReader shapes = top.object("shapes");
        for (int i = 0; i < kArkitShapeCount; ++i) {
            const std::string name = kShapeNames[std::size_t(i)];
            if (!shapes.has(name)) shapes.fail(fmt::format("all 52 ARKit shapes, {} among them", name), "it missing");
            detail::JsonReader s = shapes.object(name);
            s.comment("why");
            FapValues& v = out.faps[std::size_t(i)];
            if (s.has("aus")) {
                for (auto& [key, value] : s.object("aus").entries()) {
                    std::string error;
                    const auto term = parse_au_term(key, &error);
                    if (!term) value.fail("an action unit term (AU12, AU12L, AU12R)", "\"" + key + "\"");
                    const double w = value.as_number_in(-2, 2);
                    AuIntensities in;
                    if (term->side != AuSide::Right) in.left[term->number] = w;
                    if (term->side != AuSide::Left) in.right[term->number] = w;
                    const ActionUnit* u = aus.find(term->number);
                    if (!u) value.fail(fmt::format("an AU of the AU table ({})", aus.numbers_text()), "\"" + key + "\"");
                    if (!u->sides && term->side != AuSide::Both)
                        value.fail(fmt::format("AU{} without L or R (it has no sides)", term->number), "\"" + key + "\"");
                    const FapValues f = aus.faps(in);
                    for (int k = 0; k < fap::kFapCount; ++k) v[k] += f[k];
                }
            }
            if (s.has("faps")) {
                const FapValues f = detail::read_fap_values(
                    s.at("faps"), [](int n) { return n >= 3 && n <= fap::kFapCount; }, "a low-level FAP (3..68)");
                for (int k = 0; k < fap::kFapCount; ++k) v[k] += f[k];
            }
            if (std::all_of(v.begin(), v.end(), [](double x) { return x == 0.0; }))
                s.fail("\"aus\" or \"faps\" that move the face", "a shape that moves nothing");
            s.finish();
        }
        shapes.finish();
        for (auto& [key, entry] : top.object("angles").entries()) {
            detail::JsonReader a = entry.as_object();
            a.comment("why");
            ArkitAngle angle;
            angle.column = key;
            const std::string fap_name = a.string("fap");
            const auto f = fap::find_fap(fap_name);
            constexpr std::array<int, 7> kAngleFaps{23, 24, 25, 26, 48, 49, 50};
            if (!f || std::find(kAngleFaps.begin(), kAngleFaps.end(), *f) == kAngleFaps.end())
                a.at("fap").fail("an eyeball or head angle FAP (yaw_l_eyeball ... head_roll)");
            angle.fap = *f;
            angle.per_radian = a.number_in("per_radian", -1e7, 1e7);
            a.finish();
            out.angles.push_back(angle);
        }
    });
    return out;
}

CaptureTables load_capture_tables(const std::string& data_dir) {
    CaptureTables t;
    t.aus = load_action_units(data_dir + "/expression/action_units.json");
    t.arkit = load_arkit_shapes(data_dir + "/expression/arkit.json", t.aus);
    return t;
}

fap::FapStream parse_capture_csv(std::string_view text, const std::string& source, const CaptureTables& tables,
                                 AnimationFormat* format_out) {
    const CsvTable t = detail::parse_csv(text, source);
    std::vector<Candidate> all = candidates(t);
    const auto best = std::max_element(all.begin(), all.end(), [](const Candidate& a, const Candidate& b) {
        return a.found - int(a.missing.size()) < b.found - int(b.missing.size());
    });
    if (best->found == 0) {
        std::string header;
        for (const std::string& h : t.header) header += (header.empty() ? "" : ",") + h;
        t.fail(t.header_line,
               "a FAP file, or a CSV whose header is OpenFace 2.0's (timestamp, success, confidence, AU01_r ...), "
               "Live Link Face's (Timecode, BlendShapeCount, EyeBlinkLeft ...) or MediaPipe blendshapes' "
               "(timestamp_ms or frame, eyeBlinkLeft ...)",
               fmt::format("the header \"{}\"", echo_input(header, 60)));
    }
    if (!best->missing.empty())
        t.fail(t.header_line,
               fmt::format("the columns of a {} (the file resembles one)", animation_format_name(best->format)),
               fmt::format("no {}", list(best->missing)));
    if (t.rows.empty()) t.fail(t.header_line + 1, "rows of data after the header", "none");
    const Capture c = best->format == AnimationFormat::OpenFace ? read_openface(t, tables)
                                                                : read_arkit(t, tables, best->format);
    if (format_out) *format_out = best->format;
    return resample(c, source, t);
}

Animation parse_animation(std::string_view text, const std::string& source, const std::string& data_dir) {
    Animation a;
    if (!detail::looks_like_csv(text)) {
        a.stream = fap::parse_fap(text, source);
        return a;
    }
    const CaptureTables tables = load_capture_tables(data_dir);
    a.stream = parse_capture_csv(text, source, tables, &a.format);
    return a;
}

Animation read_animation_file(const std::string& path, const std::string& data_dir) {
    // Before a byte is read the format is unknown: a missing or unreadable
    // file is named as the FAP reader always named it, unless it is a .csv.
    const std::string ext = std::filesystem::path(path).extension().string();
    const bool csv = ext.size() == 4 && std::tolower(static_cast<unsigned char>(ext[1])) == 'c' &&
                     std::tolower(static_cast<unsigned char>(ext[2])) == 's' &&
                     std::tolower(static_cast<unsigned char>(ext[3])) == 'v';
    const std::string text =
        read_input_file(path, static_cast<std::uint64_t>(kMaxCaptureFileBytes), csv ? "capture" : "fap");
    return parse_animation(text, path, data_dir);
}

}  // namespace emoface::expression
