#pragma once
// Facial capture data as FAP streams, and back (README, "Input formats").
//
// Every format becomes a fap::FapStream, so a capture plays, converts and is
// summarised exactly like a FAP file:
//  - OpenFace 2.0 FeatureExtraction CSV: AUxx_r (0..5) are AU intensities
//    (/ 5, both sides) turned into FAPs by the AU table
//    (data/expression/action_units.json); pose_Rx/Ry/Rz (radians, camera
//    frame: x right, y down, z away) the head FAPs 48-50; gaze_angle_x/y
//    (radians) both eyes' FAPs 23-26. Rows with success 0 or confidence
//    under kMinOpenFaceConfidence hold the last good row's values (the
//    first good row's before it).
//  - ARKit blendshape CSV: Live Link Face's (Timecode HH:MM:SS:FF.fff,
//    BlendShapeCount, the 52 shapes in PascalCase, then head and eye angles)
//    or the same shapes in MediaPipe's camelCase with a time column
//    (seconds, or milliseconds when its name ends in _ms) or a frame column
//    (at kMediaPipeFrameFps). Each shape is AUs and FAPs per unit
//    coefficient (data/expression/arkit.json).
// A capture's rows are resampled at a constant frame rate (1 / the median
// interval between rows, whole when within 1 % of a whole number), values
// interpolated linearly between the rows around each frame's time.
//
// The format is told from the content: a first line (past blank lines and
// '#' comments) with commas that does not start with a digit (a FAP header
// starts with its version) is a CSV, recognised by its header; anything else
// is read as a FAP file. A CSV that
// is none of the three says which it resembles most and the columns it
// lacks. Every error is emoface::InputError
// "capture: FILE:LINE: expected ..., found ..." (FAP files: "fap: ...").
#include <bitset>
#include <string>
#include <string_view>
#include <vector>

#include "emoface/expression/action_units.h"
#include "emoface/expression/profiles.h"
#include "emoface/fap/fap_stream.h"

namespace emoface::expression {

enum class AnimationFormat { Fap, OpenFace, LiveLinkFace, MediaPipe };
// "FAP", "OpenFace 2.0 CSV", "Live Link Face CSV", "MediaPipe blendshape CSV".
const char* animation_format_name(AnimationFormat f);

inline constexpr double kMinOpenFaceConfidence = 0.5;
inline constexpr double kMediaPipeFrameFps = 30;
inline constexpr long long kMaxCaptureFileBytes = 256LL << 20;
inline constexpr int kArkitShapeCount = 52;

// The 52 shapes in Live Link Face's column order and spelling.
const std::vector<std::string>& arkit_shape_names();

// data/expression/arkit.json: each shape's FAPs per unit coefficient, and
// the angle columns' FAPs.
struct ArkitAngle {
    std::string column;  // "HeadYaw"
    int fap = 0;         // 3..68
    double per_radian = 0;
};
struct ArkitShapes {
    std::vector<FapValues> faps;  // per shape, arkit_shape_names() order
    std::vector<ArkitAngle> angles;
};
// Throws emoface::InputError naming the file and key for a missing or
// unknown shape, an AU the table lacks (or a side of a midline AU), a FAP
// that is not low-level, a shape that moves nothing.
ArkitShapes load_arkit_shapes(const std::string& path, const ActionUnitTable& aus);

// What the readers and writers need from data/: the AU table and the shapes.
struct CaptureTables {
    ActionUnitTable aus;
    ArkitShapes arkit;
};
CaptureTables load_capture_tables(const std::string& data_dir);

struct Animation {
    AnimationFormat format = AnimationFormat::Fap;
    fap::FapStream stream;
};

// Reads any known format; the tables are loaded from data_dir only for a
// capture. source_name is what messages call the text.
Animation read_animation_file(const std::string& path, const std::string& data_dir);
Animation parse_animation(std::string_view text, const std::string& source_name, const std::string& data_dir);
// The capture readers on their own (the text is known to be CSV).
fap::FapStream parse_capture_csv(std::string_view text, const std::string& source_name,
                                 const CaptureTables& tables, AnimationFormat* format = nullptr);

// One frame as the writers take it: the low-level FAPs in effect (`mask`)
// and the AUs the face shows, as face_state() gives them (FAP 1 and 2
// turned into FAPs and AUs too).
struct CaptureFrame {
    FapValues faps{};
    std::bitset<fap::kFapCount> mask;
    AuIntensities aus;
};
// face_state() of every frame of the stream, untransmitted FAPs resolved.
std::vector<CaptureFrame> capture_frames(const fap::FapStream& stream, const EmotionProfiles& emotions,
                                         const VisemeProfiles& visemes);

// OpenFace-style AU CSV: frame, face_id, timestamp, confidence, success,
// gaze_angle_x/y, pose_Rx/Ry/Rz (from FAPs 23-26 and 48-50, as the reader
// takes them), and AUxx_r = 5 x each of OpenFace's 17 AUs (the mean of its
// sides; AU45 takes AU43's closure too: a frame cannot tell a blink from
// closed eyes). Frame k at k / fps.
std::string format_openface_csv(const std::vector<CaptureFrame>& frames, double fps);
// Live Link Face CSV: Timecode at 30 timecode frames per second with
// subframes, BlendShapeCount 61, the 52 shapes fitted in [0, 1] to each
// frame's FAPs (bounded least squares; FAPs the frame does not transmit count
// at their neutral 0), then the
// angle columns of arkit.json from their FAPs and the eye roll columns 0.
// Frame k at k / fps.
std::string format_arkit_csv(const std::vector<CaptureFrame>& frames, double fps, const ArkitShapes& shapes);

}  // namespace emoface::expression
