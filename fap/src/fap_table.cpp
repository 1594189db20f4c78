// The 68-FAP table, from ISO/IEC 14496-2 Annex C as collected in
// shared/mpeg4/fap_table.tsv (units from the standard, not Xface: FAP 19 is
// IRISD). Directions follow the convention of fap_table.h.
#include "emoface/fap/fap_table.h"

#include <cctype>

#include "emoface/common/error.h"

namespace emoface::fap {

namespace {

// {number, name, description, unit, bidirectional, positive direction,
//  feature point, direction, second feature point, practical min, max}
const std::array<FapInfo, kFapCount> kFapTable{{
    {1, "viseme",
     "Viseme (FAP1: viseme_select1, viseme_select2, viseme_blend, viseme_def)",
     FapUnit::None, false, "", "", {0.f, 0.f, 0.f}, "", 0, 0},
    {2, "expression",
     "Expression (FAP2: expression_select1, expression_intensity1, expression_select2, expression_intensity2, init_face, expression_def)",
     FapUnit::None, false, "", "", {0.f, 0.f, 0.f}, "", 0, 0},
    {3, "open_jaw",
     "Vertical jaw displacement (does not affect mouth opening)",
     FapUnit::MNS, false, "down", "2.1", {0.f, -1.f, 0.f}, "", 0, 1080},
    {4, "lower_t_midlip",
     "Vertical top middle inner lip displacement",
     FapUnit::MNS, true, "down", "2.2", {0.f, -1.f, 0.f}, "", -600, 600},
    {5, "raise_b_midlip",
     "Vertical bottom middle inner lip displacement",
     FapUnit::MNS, true, "up", "2.3", {0.f, 1.f, 0.f}, "", -1860, 1860},
    {6, "stretch_l_cornerlip",
     "Horizontal displacement of left inner lip corner",
     FapUnit::MW, true, "left", "2.4", {1.f, 0.f, 0.f}, "", -600, 600},
    {7, "stretch_r_cornerlip",
     "Horizontal displacement of right inner lip corner",
     FapUnit::MW, true, "right", "2.5", {-1.f, 0.f, 0.f}, "", -600, 600},
    {8, "lower_t_lip_lm",
     "Vertical displacement of midpoint between left corner and middle of top inner lip",
     FapUnit::MNS, true, "down", "2.6", {0.f, -1.f, 0.f}, "", -600, 600},
    {9, "lower_t_lip_rm",
     "Vertical displacement of midpoint between right corner and middle of top inner lip",
     FapUnit::MNS, true, "down", "2.7", {0.f, -1.f, 0.f}, "", -600, 600},
    {10, "raise_b_lip_lm",
     "Vertical displacement of midpoint between left corner and middle of bottom inner lip",
     FapUnit::MNS, true, "up", "2.8", {0.f, 1.f, 0.f}, "", -1860, 1860},
    {11, "raise_b_lip_rm",
     "Vertical displacement of midpoint between right corner and middle of bottom inner lip",
     FapUnit::MNS, true, "up", "2.9", {0.f, 1.f, 0.f}, "", -1860, 1860},
    {12, "raise_l_cornerlip",
     "Vertical displacement of left inner lip corner",
     FapUnit::MNS, true, "up", "2.4", {0.f, 1.f, 0.f}, "", -600, 600},
    {13, "raise_r_cornerlip",
     "Vertical displacement of right inner lip corner",
     FapUnit::MNS, true, "up", "2.5", {0.f, 1.f, 0.f}, "", -600, 600},
    {14, "thrust_jaw",
     "Depth displacement of jaw",
     FapUnit::MNS, false, "forward", "2.1", {0.f, 0.f, 1.f}, "", 0, 600},
    {15, "shift_jaw",
     "Side to side displacement of jaw",
     FapUnit::MW, true, "right", "2.1", {-1.f, 0.f, 0.f}, "", -1080, 1080},
    {16, "push_b_lip",
     "Depth displacement of bottom middle lip",
     FapUnit::MNS, true, "forward", "2.3", {0.f, 0.f, 1.f}, "", -1080, 1080},
    {17, "push_t_lip",
     "Depth displacement of top middle lip",
     FapUnit::MNS, true, "forward", "2.2", {0.f, 0.f, 1.f}, "", -1080, 1080},
    {18, "depress_chin",
     "Upward and compressing movement of the chin (like in sadness)",
     FapUnit::MNS, true, "up", "2.10", {0.f, 1.f, 0.f}, "", -420, 420},
    {19, "close_t_l_eyelid",
     "Vertical displacement of top left eyelid",
     FapUnit::IRISD, true, "down", "3.1", {0.f, -1.f, 0.f}, "", -1080, 1080},
    {20, "close_t_r_eyelid",
     "Vertical displacement of top right eyelid",
     FapUnit::IRISD, true, "down", "3.2", {0.f, -1.f, 0.f}, "", -1080, 1080},
    {21, "close_b_l_eyelid",
     "Vertical displacement of bottom left eyelid",
     FapUnit::IRISD, true, "up", "3.3", {0.f, 1.f, 0.f}, "", -600, 600},
    {22, "close_b_r_eyelid",
     "Vertical displacement of bottom right eyelid",
     FapUnit::IRISD, true, "up", "3.4", {0.f, 1.f, 0.f}, "", -600, 600},
    {23, "yaw_l_eyeball",
     "Horizontal orientation of left eyeball (unit 1e-5 rad)",
     FapUnit::AU, true, "left", "3.5", {1.f, 0.f, 0.f}, "", -153600, 153600},
    {24, "yaw_r_eyeball",
     "Horizontal orientation of right eyeball (unit 1e-5 rad)",
     FapUnit::AU, true, "left", "3.6", {1.f, 0.f, 0.f}, "", -153600, 153600},
    {25, "pitch_l_eyeball",
     "Vertical orientation of left eyeball (unit 1e-5 rad)",
     FapUnit::AU, true, "down", "3.5", {0.f, -1.f, 0.f}, "", -115200, 115200},
    {26, "pitch_r_eyeball",
     "Vertical orientation of right eyeball (unit 1e-5 rad)",
     FapUnit::AU, true, "down", "3.6", {0.f, -1.f, 0.f}, "", -115200, 115200},
    {27, "thrust_l_eyeball",
     "Depth displacement of left eyeball",
     FapUnit::ES, true, "forward", "3.5", {0.f, 0.f, 1.f}, "", -600, 600},
    {28, "thrust_r_eyeball",
     "Depth displacement of right eyeball",
     FapUnit::ES, true, "forward", "3.6", {0.f, 0.f, 1.f}, "", -600, 600},
    {29, "dilate_l_pupil",
     "Dilation of left pupil",
     FapUnit::IRISD, true, "growing", "3.5", {0.f, 0.f, 0.f}, "", 0, 0},
    {30, "dilate_r_pupil",
     "Dilation of right pupil",
     FapUnit::IRISD, true, "growing", "3.6", {0.f, 0.f, 0.f}, "", 0, 0},
    {31, "raise_l_i_eyebrow",
     "Vertical displacement of left inner eyebrow",
     FapUnit::ENS, true, "up", "4.1", {0.f, 1.f, 0.f}, "", -900, 900},
    {32, "raise_r_i_eyebrow",
     "Vertical displacement of right inner eyebrow",
     FapUnit::ENS, true, "up", "4.2", {0.f, 1.f, 0.f}, "", -900, 900},
    {33, "raise_l_m_eyebrow",
     "Vertical displacement of left middle eyebrow",
     FapUnit::ENS, true, "up", "4.3", {0.f, 1.f, 0.f}, "", -900, 900},
    {34, "raise_r_m_eyebrow",
     "Vertical displacement of right middle eyebrow",
     FapUnit::ENS, true, "up", "4.4", {0.f, 1.f, 0.f}, "", -900, 900},
    {35, "raise_l_o_eyebrow",
     "Vertical displacement of left outer eyebrow",
     FapUnit::ENS, true, "up", "4.5", {0.f, 1.f, 0.f}, "", -900, 900},
    {36, "raise_r_o_eyebrow",
     "Vertical displacement of right outer eyebrow",
     FapUnit::ENS, true, "up", "4.6", {0.f, 1.f, 0.f}, "", -900, 900},
    {37, "squeeze_l_eyebrow",
     "Horizontal displacement of left eyebrow",
     FapUnit::ES, true, "right", "4.1", {-1.f, 0.f, 0.f}, "", -900, 900},
    {38, "squeeze_r_eyebrow",
     "Horizontal displacement of right eyebrow",
     FapUnit::ES, true, "left", "4.2", {1.f, 0.f, 0.f}, "", -900, 900},
    {39, "puff_l_cheek",
     "Horizontal displacement of left cheek",
     FapUnit::ES, true, "left", "5.1", {1.f, 0.f, 0.f}, "", -900, 900},
    {40, "puff_r_cheek",
     "Horizontal displacement of right cheek",
     FapUnit::ES, true, "right", "5.2", {-1.f, 0.f, 0.f}, "", -900, 900},
    {41, "lift_l_cheek",
     "Vertical displacement of left cheek",
     FapUnit::ENS, false, "up", "5.3", {0.f, 1.f, 0.f}, "", -900, 900},
    {42, "lift_r_cheek",
     "Vertical displacement of right cheek",
     FapUnit::ENS, false, "up", "5.4", {0.f, 1.f, 0.f}, "", -900, 900},
    {43, "shift_tongue_tip",
     "Horizontal displacement of tongue tip",
     FapUnit::MW, true, "right", "6.1", {-1.f, 0.f, 0.f}, "", -1080, 1080},
    {44, "raise_tongue_tip",
     "Vertical displacement of tongue tip",
     FapUnit::MNS, true, "up", "6.1", {0.f, 1.f, 0.f}, "", -1080, 1080},
    {45, "thrust_tongue_tip",
     "Depth displacement of tongue tip",
     FapUnit::MW, true, "forward", "6.1", {0.f, 0.f, 1.f}, "", -1080, 1080},
    {46, "raise_tongue",
     "Vertical displacement of tongue",
     FapUnit::MNS, true, "up", "6.2", {0.f, 1.f, 0.f}, "", -1080, 1080},
    {47, "tongue_roll",
     "Rolling of the tongue into U shape (unit 1e-5 rad)",
     FapUnit::AU, false, "concave upward", "6.3", {0.f, 0.f, 0.f}, "6.4", -300, 300},
    {48, "head_pitch",
     "Head pitch angle from top of spine (unit 1e-5 rad)",
     FapUnit::AU, true, "down", "7.1", {0.f, -1.f, 0.f}, "", -1860, 1860},
    {49, "head_yaw",
     "Head yaw angle from top of spine (unit 1e-5 rad)",
     FapUnit::AU, true, "left", "7.1", {1.f, 0.f, 0.f}, "", -1860, 1860},
    {50, "head_roll",
     "Head roll angle from top of spine (unit 1e-5 rad)",
     FapUnit::AU, true, "right", "7.1", {-1.f, 0.f, 0.f}, "", -1860, 1860},
    {51, "lower_t_midlip_o",
     "Vertical top middle outer lip displacement",
     FapUnit::MNS, true, "down", "8.1", {0.f, -1.f, 0.f}, "", -600, 600},
    {52, "raise_b_midlip_o",
     "Vertical bottom middle outer lip displacement",
     FapUnit::MNS, true, "up", "8.2", {0.f, 1.f, 0.f}, "", -1860, 1860},
    {53, "stretch_l_cornerlip_o",
     "Horizontal displacement of left outer lip corner",
     FapUnit::MW, true, "left", "8.3", {1.f, 0.f, 0.f}, "", -600, 600},
    {54, "stretch_r_cornerlip_o",
     "Horizontal displacement of right outer lip corner",
     FapUnit::MW, true, "right", "8.4", {-1.f, 0.f, 0.f}, "", -600, 600},
    {55, "lower_t_lip_lm_o",
     "Vertical displacement of midpoint between left corner and middle of top outer lip",
     FapUnit::MNS, true, "down", "8.5", {0.f, -1.f, 0.f}, "", -600, 600},
    {56, "lower_t_lip_rm_o",
     "Vertical displacement of midpoint between right corner and middle of top outer lip",
     FapUnit::MNS, true, "down", "8.6", {0.f, -1.f, 0.f}, "", -600, 600},
    {57, "raise_b_lip_lm_o",
     "Vertical displacement of midpoint between left corner and middle of bottom outer lip",
     FapUnit::MNS, true, "up", "8.7", {0.f, 1.f, 0.f}, "", -1860, 1860},
    {58, "raise_b_lip_rm_o",
     "Vertical displacement of midpoint between right corner and middle of bottom outer lip",
     FapUnit::MNS, true, "up", "8.8", {0.f, 1.f, 0.f}, "", -1860, 1860},
    {59, "raise_l_cornerlip_o",
     "Vertical displacement of left outer lip corner",
     FapUnit::MNS, true, "up", "8.3", {0.f, 1.f, 0.f}, "", -600, 600},
    {60, "raise_r_cornerlip_o",
     "Vertical displacement of right outer lip corner",
     FapUnit::MNS, true, "up", "8.4", {0.f, 1.f, 0.f}, "", -600, 600},
    {61, "stretch_l_nose",
     "Horizontal displacement of left side of nose",
     FapUnit::ENS, true, "left", "9.1", {1.f, 0.f, 0.f}, "", -540, 540},
    {62, "stretch_r_nose",
     "Horizontal displacement of right side of nose",
     FapUnit::ENS, true, "right", "9.2", {-1.f, 0.f, 0.f}, "", -540, 540},
    {63, "raise_nose",
     "Vertical displacement of nose tip",
     FapUnit::ENS, true, "up", "9.3", {0.f, 1.f, 0.f}, "", -680, 680},
    {64, "bend_nose",
     "Horizontal displacement of nose tip",
     FapUnit::ENS, true, "right", "9.3", {-1.f, 0.f, 0.f}, "", -900, 900},
    {65, "raise_l_ear",
     "Vertical displacement of left ear",
     FapUnit::ENS, true, "up", "10.1", {0.f, 1.f, 0.f}, "", -900, 900},
    {66, "raise_r_ear",
     "Vertical displacement of right ear",
     FapUnit::ENS, true, "up", "10.2", {0.f, 1.f, 0.f}, "", -900, 900},
    {67, "pull_l_ear",
     "Horizontal displacement of left ear",
     FapUnit::ENS, true, "left", "10.3", {1.f, 0.f, 0.f}, "", -900, 900},
    {68, "pull_r_ear",
     "Horizontal displacement of right ear",
     FapUnit::ENS, true, "right", "10.4", {-1.f, 0.f, 0.f}, "", -900, 900},
}};

bool equal_ignoring_case(std::string_view a, std::string_view b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i) {
        if (std::tolower(static_cast<unsigned char>(a[i])) !=
            std::tolower(static_cast<unsigned char>(b[i])))
            return false;
    }
    return true;
}

}  // namespace

const std::array<FapInfo, kFapCount>& fap_table() { return kFapTable; }

const FapInfo& fap_info(int number) {
    if (number < 1 || number > kFapCount)
        fail<InputError>("fap: fap_info: expected a FAP number 1..{}, found {}", kFapCount, number);
    return kFapTable[static_cast<std::size_t>(number - 1)];
}

std::optional<int> find_fap(std::string_view name) {
    for (const FapInfo& info : kFapTable)
        if (equal_ignoring_case(info.name, name)) return info.number;
    return std::nullopt;
}

std::string_view unit_name(FapUnit unit) {
    switch (unit) {
        case FapUnit::None: return "";
        case FapUnit::IRISD: return "IRISD";
        case FapUnit::ES: return "ES";
        case FapUnit::ENS: return "ENS";
        case FapUnit::MNS: return "MNS";
        case FapUnit::MW: return "MW";
        case FapUnit::AU: return "AU";
    }
    return "";
}

}  // namespace emoface::fap
