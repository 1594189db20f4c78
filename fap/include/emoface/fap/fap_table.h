#pragma once
// The 68 MPEG-4 facial animation parameters (ISO/IEC 14496-2 Annex C) as data.
//
// Direction convention (used by every module): a face-centred frame with
//   x towards the face's own left (the viewer's right),
//   y up,
//   z out of the face, towards the viewer.
// `direction` is the unit vector along which a positive FAP value moves the
// FAP's feature point. For rotations (unit AU: FAPs 23-26 eyeball yaw/pitch,
// 48-50 head pitch/yaw/roll) it is the way the front of the eyeball or face
// moves for a small positive angle. FAPs that move no single point along a
// line have a zero direction: 1 viseme, 2 expression, 29/30 pupil dilation (a
// scale) and 47 tongue roll (a curl).
//
// Units are those of the standard. Note FAP 19 (close_t_l_eyelid): Xface
// scales it by MNS, the standard (and this table) by IRISD like FAPs 20-22.
#include <array>
#include <optional>
#include <string_view>

namespace emoface::fap {

inline constexpr int kFapCount = 68;
// FAPs 3..68; FAP 1 (viseme) and FAP 2 (expression) are the high-level ones.
inline constexpr int kLowLevelFapCount = 66;

// Face animation parameter units: distances on the neutral face / 1024, and
// AU = 1e-5 rad (see fapu.h). None for FAPs 1 and 2.
enum class FapUnit { None, IRISD, ES, ENS, MNS, MW, AU };

struct FapInfo {
    int number;                           // 1..68
    std::string_view name;                // "raise_l_i_eyebrow"
    std::string_view description;
    FapUnit unit;
    bool bidirectional;                   // false: the standard only defines values >= 0
    std::string_view positive_direction;  // "up", "left", "down", "forward", "growing", ...
    std::string_view feature_point;       // "2.1"; empty for FAP 1/2
    std::array<float, 3> direction;       // see the convention above
    // FAP 47 (tongue_roll) curls both tongue borders: 6.3 in feature_point and
    // 6.4 here; empty for every other FAP.
    std::string_view feature_point_2;
    // A practical value range (the slider range of Greta's FAP editor), not a
    // limit of the standard; both 0 where none is known (FAPs 1, 2, 29, 30).
    int practical_min;
    int practical_max;
};

// Indexed by FAP number - 1.
const std::array<FapInfo, kFapCount>& fap_table();

// Throws emoface::InputError for a number outside 1..68.
const FapInfo& fap_info(int number);

// FAP number for a name such as "open_jaw" (ASCII case-insensitive).
std::optional<int> find_fap(std::string_view name);

// "IRISD", "ES", "ENS", "MNS", "MW", "AU"; "" for None.
std::string_view unit_name(FapUnit unit);

}  // namespace emoface::fap
