#include "emoface/expression/action_units.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "fap_values_reader.h"
#include "json_reader.h"

namespace emoface::expression {
namespace {

// The same FAP on the face's other side, for the FAPs that have one (left
// first). A positive value means the same motion on both sides (out, up,
// towards the midline), so a symmetric AU has equal values on a pair.
constexpr std::array<std::pair<int, int>, 22> kMirrorPairs{{
    {6, 7},   {8, 9},   {10, 11}, {12, 13}, {19, 20}, {21, 22}, {25, 26}, {27, 28}, {29, 30}, {31, 32}, {33, 34},
    {35, 36}, {37, 38}, {39, 40}, {41, 42}, {53, 54}, {55, 56}, {57, 58}, {59, 60}, {61, 62}, {65, 66}, {67, 68},
}};

enum class FapSide { Midline, Left, Right };

FapSide fap_side(int fap) {
    for (auto [l, r] : kMirrorPairs) {
        if (fap == l) return FapSide::Left;
        if (fap == r) return FapSide::Right;
    }
    return FapSide::Midline;
}

int mirror_fap(int fap) {
    for (auto [l, r] : kMirrorPairs) {
        if (fap == l) return r;
        if (fap == r) return l;
    }
    return fap;
}

// One unknown of a region's fit: an AU's half (or a whole midline AU).
struct Column {
    int au;
    AuSide side;  // Both for a midline AU
    const FapValues* faps;
};

}  // namespace

bool AuIntensities::empty() const {
    for (int a = 0; a < kAuNumberLimit; ++a)
        if (left[a] != 0.0 || right[a] != 0.0) return false;
    return true;
}

std::string AuIntensities::to_string(double threshold) const {
    std::string out;
    auto add = [&](double w, int au, const char* side) {
        if (!out.empty()) out += " + ";
        out += fmt::format("{:g} AU{}{}", w, au, side);
    };
    for (int a = 1; a < kAuNumberLimit; ++a) {
        const double l = left[a] > threshold ? left[a] : 0.0, r = right[a] > threshold ? right[a] : 0.0;
        if (l == r) {
            if (l > 0) add(l, a, "");
        } else {
            if (l > 0) add(l, a, "L");
            if (r > 0) add(r, a, "R");
        }
    }
    return out.empty() ? "none" : out;
}

bool operator==(const AuIntensities& a, const AuIntensities& b) { return a.left == b.left && a.right == b.right; }
bool operator!=(const AuIntensities& a, const AuIntensities& b) { return !(a == b); }

std::optional<AuTerm> parse_au_term(std::string_view text, std::string* error) {
    error->clear();
    if (text.size() < 2 || std::tolower(static_cast<unsigned char>(text[0])) != 'a' ||
        std::tolower(static_cast<unsigned char>(text[1])) != 'u')
        return std::nullopt;
    std::string_view rest = text.substr(2);
    AuTerm t;
    const char last = rest.empty() ? '\0' : static_cast<char>(std::toupper(static_cast<unsigned char>(rest.back())));
    if (last == 'L' || last == 'R') {
        t.side = last == 'L' ? AuSide::Left : AuSide::Right;
        rest.remove_suffix(1);
    }
    const char* end = rest.data() + rest.size();
    auto [p, ec] = std::from_chars(rest.data(), end, t.number);
    if (rest.empty() || ec != std::errc() || p != end || !std::isdigit(static_cast<unsigned char>(rest[0]))) {
        *error = fmt::format("\"{}\" is not an action unit; expected AU<number>, AU<number>L or AU<number>R "
                             "(e.g. AU12, AU12L)",
                             echo_input(text, 40));
        return std::nullopt;
    }
    if (t.number < 1 || t.number >= kAuNumberLimit) {
        *error = fmt::format("\"{}\": action units are numbered 1..{}", echo_input(text, 40), kAuNumberLimit - 1);
        return std::nullopt;
    }
    return t;
}

const ActionUnit* ActionUnitTable::find(int number) const {
    for (const ActionUnit& u : units)
        if (u.number == number) return &u;
    return nullptr;
}

FapValues ActionUnitTable::faps(const AuIntensities& aus) const {
    FapValues out{};
    for (const ActionUnit& u : units) {
        const double l = aus.left[u.number], r = aus.right[u.number];
        if (l == 0.0 && r == 0.0) continue;
        for (int f = 0; f < fap::kFapCount; ++f) out[f] += l * u.left[f] + r * u.right[f];
    }
    return out;
}

std::string ActionUnitTable::numbers_text() const {
    std::string out;
    for (const ActionUnit& u : units) out += (out.empty() ? "" : ", ") + std::to_string(u.number);
    return out;
}

void ActionUnitTable::check(const AuIntensities& aus, std::string_view where) const {
    for (int a = 1; a < kAuNumberLimit; ++a) {
        if (aus.left[a] == 0.0 && aus.right[a] == 0.0) continue;
        const ActionUnit* u = find(a);
        if (!u) fail<InputError>("expression: {}: AU{} is not one the face can show (AUs {})", where, a, numbers_text());
        if (!u->sides && aus.left[a] != aus.right[a])
            fail<InputError>("expression: {}: AU{} ({}) has no sides; give it without L or R", where, a, u->name);
    }
}

std::vector<double> bounded_least_squares(const std::vector<std::vector<double>>& columns,
                                          const std::vector<double>& target, double lower, double upper) {
    const std::size_t n = columns.size();
    // Normal equations G x = c; coordinate descent with each step clamped to
    // the box converges to the box-constrained minimum (the problem is convex).
    std::vector<double> g(n * n, 0.0), c(n, 0.0), x(n, lower);
    for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t r = 0; r < target.size(); ++r) c[i] += columns[i][r] * target[r];
        for (std::size_t j = i; j < n; ++j) {
            double s = 0.0;
            for (std::size_t r = 0; r < target.size(); ++r) s += columns[i][r] * columns[j][r];
            g[i * n + j] = g[j * n + i] = s;
        }
    }
    double scale = 0.0;
    for (std::size_t i = 0; i < n; ++i) scale = std::max(scale, g[i * n + i]);
    if (scale == 0.0) return x;
    for (int sweep = 0; sweep < 5000; ++sweep) {
        double largest_step = 0.0;
        for (std::size_t i = 0; i < n; ++i) {
            const double gii = g[i * n + i];
            if (gii <= 1e-12 * scale) continue;
            double gradient = -c[i];
            for (std::size_t j = 0; j < n; ++j) gradient += g[i * n + j] * x[j];
            const double next = std::clamp(x[i] - gradient / gii, lower, upper);
            largest_step = std::max(largest_step, std::abs(next - x[i]));
            x[i] = next;
        }
        if (largest_step < 1e-9) break;
    }
    return x;
}

AuIntensities ActionUnitTable::infer(const FapValues& faps, const std::bitset<fap::kFapCount>& mask) const {
    AuIntensities out;
    FapValues left_over{};  // what the AUs fitted so far leave of the frame
    for (int f = 0; f < fap::kFapCount; ++f) left_over[f] = mask[f] ? faps[f] : 0.0;
    for (const FaceRegion& region : regions) {
        std::vector<int> rows;
        for (int f = 0; f < fap::kFapCount; ++f)
            if (region.faps[f] && mask[f]) rows.push_back(f);
        std::vector<Column> cols;
        for (const ActionUnit& u : units) {
            if (!u.inferred || u.region != region.name) continue;
            if (u.sides) {
                cols.push_back({u.number, AuSide::Left, &u.left});
                cols.push_back({u.number, AuSide::Right, &u.right});
            } else {
                cols.push_back({u.number, AuSide::Both, &u.faps});
            }
        }
        if (rows.empty() || cols.empty()) continue;
        std::vector<std::vector<double>> a(cols.size(), std::vector<double>(rows.size()));
        std::vector<double> b(rows.size());
        for (std::size_t r = 0; r < rows.size(); ++r) b[r] = left_over[rows[r]];
        for (std::size_t j = 0; j < cols.size(); ++j)
            for (std::size_t r = 0; r < rows.size(); ++r) a[j][r] = (*cols[j].faps)[rows[r]];
        const std::vector<double> x = bounded_least_squares(a, b, 0.0, 1.0);
        for (std::size_t j = 0; j < cols.size(); ++j) {
            const Column& col = cols[j];
            if (col.side != AuSide::Right) out.left[col.au] = x[j];
            if (col.side != AuSide::Left) out.right[col.au] = x[j];
            // The AU's whole vector leaves the frame, later regions included.
            for (int f = 0; f < fap::kFapCount; ++f)
                if (mask[f]) left_over[f] -= x[j] * (*col.faps)[f];
        }
    }
    return out;
}

ActionUnitTable load_action_units(const std::string& path) {
    ActionUnitTable table;
    detail::read_json_file(path, [&](detail::JsonReader& top) {
        top.comment("_about");
        std::array<int, fap::kFapCount> region_of{};  // 1-based region index per FAP, 0 = none
        for (detail::JsonReader& r : top.objects("regions")) {
            FaceRegion region;
            region.name = r.string("name");
            for (const FaceRegion& other : table.regions)
                if (other.name == region.name) r.at("name").fail("a region name used once", "\"" + region.name + "\" again");
            for (double v : r.number_list("faps")) {
                const int f = static_cast<int>(v);
                if (f != v || f < 3 || f > fap::kFapCount) r.at("faps").fail("low-level FAP numbers (3..68)", fmt::format("{:g}", v));
                if (region_of[f - 1] != 0)
                    r.at("faps").fail("each FAP in one region",
                                      fmt::format("FAP {} also in \"{}\"", f, table.regions[region_of[f - 1] - 1].name));
                region_of[f - 1] = static_cast<int>(table.regions.size()) + 1;
                region.faps[f - 1] = true;
            }
            r.finish();
            table.regions.push_back(region);
        }
        auto region_index = [&](const std::string& name) {
            for (std::size_t i = 0; i < table.regions.size(); ++i)
                if (table.regions[i].name == name) return static_cast<int>(i) + 1;
            return 0;
        };
        for (auto& [key, entry] : top.object("action_units").entries()) {
            std::string error;
            const auto term = parse_au_term(key, &error);
            if (!term || term->side != AuSide::Both)
                entry.fail("an action unit key \"AU<number>\"", "\"" + key + "\"");
            detail::JsonReader r = entry.as_object();
            ActionUnit u;
            u.number = term->number;
            u.name = r.string("name");
            u.muscle = r.string("muscle");
            u.region = r.string("region");
            const int home = region_index(u.region);
            if (home == 0) r.at("region").fail("the name of one of \"regions\"", "\"" + u.region + "\"");
            u.sides = r.at("sides").as_boolean();
            u.inferred = r.boolean("inferred", true);
            u.reasoning = r.string("reasoning");
            detail::JsonReader faps = r.at("faps");
            u.faps = detail::read_fap_values(faps, [](int f) { return f >= 3 && f <= fap::kFapCount; },
                                             "a low-level FAP (3..68)");
            for (int f = 3; f <= fap::kFapCount; ++f) {
                const double v = u.faps[f - 1];
                if (v == 0.0) continue;
                if (region_of[f - 1] != 0 && region_of[f - 1] < home)
                    faps.fail(fmt::format("FAPs of region \"{}\" or of regions fitted after it", u.region),
                              fmt::format("FAP {} ({}) of region \"{}\", fitted before", f, fap::fap_info(f).name,
                                          table.regions[region_of[f - 1] - 1].name));
                if (u.sides && u.faps[mirror_fap(f) - 1] != v)
                    faps.fail("left-right symmetric values (a bilateral AU's halves mirror each other)",
                              fmt::format("FAP {} ({}) {:g} but FAP {} ({}) {:g}", f, fap::fap_info(f).name, v,
                                          mirror_fap(f), fap::fap_info(mirror_fap(f)).name, u.faps[mirror_fap(f) - 1]));
                const FapSide side = u.sides ? fap_side(f) : FapSide::Midline;
                if (side != FapSide::Right) u.left[f - 1] = side == FapSide::Left ? v : 0.5 * v;
                if (side != FapSide::Left) u.right[f - 1] = side == FapSide::Right ? v : 0.5 * v;
            }
            r.finish();
            table.units.push_back(std::move(u));
        }
        std::sort(table.units.begin(), table.units.end(),
                  [](const ActionUnit& a, const ActionUnit& b) { return a.number < b.number; });
        for (std::size_t i = 1; i < table.units.size(); ++i)
            if (table.units[i].number == table.units[i - 1].number)
                top.at("action_units").fail("each action unit once", fmt::format("AU{} twice", table.units[i].number));
    });
    return table;
}

}  // namespace emoface::expression
