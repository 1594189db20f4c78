#pragma once
// FACS Action Units: the layer between FAPs and what a face shows
// (data/expression/action_units.json, with the muscle and reasoning of each).
// An AU is a low-level FAP vector at its full intensity (FACS "E" = 1);
// a bilateral AU has a left and a right half that are scored apart. Emotion
// prototypes are AU intensities (profiles.h), and a frame that carries only
// low-level FAPs is read back into AU intensities region by region
// (ActionUnitTable::infer).
#include <array>
#include <bitset>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "emoface/expression/fap_values.h"

namespace emoface::expression {

// AU numbers run 1..64 (head 51-58, eyes 61-64); arrays are indexed by number.
inline constexpr int kAuNumberLimit = 65;

// AU intensities of one face, per side, in [0, 1] (1 = FACS "E"). A midline
// AU (no sides: AU26, AU17, head and eye AUs) has left == right.
struct AuIntensities {
    std::array<double, kAuNumberLimit> left{};
    std::array<double, kAuNumberLimit> right{};

    bool empty() const;
    double mean(int au) const { return 0.5 * (left[au] + right[au]); }
    // "0.3 AU4 + 0.5 AU12L + 0.2 AU12R": AUs in number order, both sides as
    // one term where they are equal, intensities under `threshold` left out;
    // "none" when nothing is left. parse_emotion_mix() reads it back.
    std::string to_string(double threshold = 0.0) const;
};
bool operator==(const AuIntensities& a, const AuIntensities& b);
bool operator!=(const AuIntensities& a, const AuIntensities& b);

enum class AuSide { Both, Left, Right };

// "AU12" (both sides), "AU12L", "AU12R" (ASCII case-insensitive "au").
struct AuTerm {
    int number = 0;
    AuSide side = AuSide::Both;
};
// Not an AU term (does not start with "AU"): nullopt with `error` empty. A
// term that starts with "AU" but is malformed ("AU", "AU12X", "AU0",
// "AU99"): nullopt with `error` saying why.
std::optional<AuTerm> parse_au_term(std::string_view text, std::string* error);

struct ActionUnit {
    int number = 0;
    std::string name;       // "lip corner puller"
    std::string muscle;     // "zygomaticus major"
    std::string region;     // the region it is inferred from
    bool sides = false;     // bilateral: a left and a right half
    bool inferred = true;   // false: the FAPs cannot tell it from others
    std::string reasoning;
    FapValues faps{};       // full intensity, both sides
    FapValues left{};       // left-side FAPs + half the midline FAPs (midline AU: faps / 2)
    FapValues right{};
};

// A group of FAPs fitted on its own; regions are fitted in file order.
struct FaceRegion {
    std::string name;
    std::bitset<fap::kFapCount> faps;  // by FAP number - 1
};

class ActionUnitTable {
public:
    std::vector<ActionUnit> units;    // in file order
    std::vector<FaceRegion> regions;  // in fit order

    const ActionUnit* find(int number) const;
    // Σ left × left half + right × right half over the table's AUs.
    FapValues faps(const AuIntensities& aus) const;
    // The AU intensities that explain `faps` over the FAPs in `mask`, region
    // by region: for each region in order, the inferred AUs homed there
    // (each half of a bilateral AU its own unknown) are fitted to what the
    // AUs of earlier regions left of the region's transmitted FAPs, by
    // least squares with every intensity in [0, 1]. FAPs outside the mask
    // count for nothing. AUs that are not inferred stay 0.
    AuIntensities infer(const FapValues& faps, const std::bitset<fap::kFapCount>& mask) const;
    // Throws emoface::InputError, message "expression: <where>: ...", for an
    // intensity on an AU the table lacks or on one side of a midline AU.
    void check(const AuIntensities& aus, std::string_view where) const;
    // "1, 2, 4, 5, ..." for messages.
    std::string numbers_text() const;
};

// Reads data/expression/action_units.json: {"regions": {"nose": {"faps":
// [61, ...]}, ...}, "action_units": {"AU1": {"name", "muscle", "region",
// "sides", "inferred" (optional, default true), "reasoning", "faps": {FAP
// name or number: value}}, ...}}. Throws emoface::InputError naming the file
// and the key for: an unknown or missing key, a FAP that is not low-level,
// a region no AU or FAP list names, a FAP in two regions, an AU moving a FAP
// of a region fitted before its own, a bilateral AU that is not left-right
// symmetric, a midline AU ("sides": false) marked as bilateral elsewhere.
ActionUnitTable load_action_units(const std::string& path);

// min |Σ_j x_j columns[j] - target|² with lower <= x_j <= upper (projected
// coordinate descent on the normal equations; columns of zero length stay
// at `lower`). Used for the AU fit and for an emotion mix from AUs.
std::vector<double> bounded_least_squares(const std::vector<std::vector<double>>& columns,
                                          const std::vector<double>& target, double lower, double upper);

}  // namespace emoface::expression
