#include "emoface/fap/fapu.h"

#include <cmath>

#include "emoface/common/error.h"

namespace emoface::fap {

double Fapu::of(FapUnit unit) const {
    switch (unit) {
        case FapUnit::None: return 0;
        case FapUnit::IRISD: return irisd;
        case FapUnit::ES: return es;
        case FapUnit::ENS: return ens;
        case FapUnit::MNS: return mns;
        case FapUnit::MW: return mw;
        case FapUnit::AU: return au;
    }
    return 0;
}

namespace {

const std::array<double, 3>& point(const FeaturePointPositions& p, std::string_view id) {
    return p[static_cast<std::size_t>(feature_point_index(id))];
}

double checked_unit(double distance, const char* what) {
    if (!(std::isfinite(distance) && distance > 0))
        fail<InputError>("fap: compute_fapu: expected {} > 0 on the neutral face, found {}", what,
                         distance);
    return distance / 1024.0;
}

}  // namespace

Fapu compute_fapu(const FeaturePointPositions& neutral) {
    constexpr int x = 0, y = 1;
    Fapu u;
    u.irisd = checked_unit(point(neutral, "3.1")[y] - point(neutral, "3.3")[y],
                           "IRISD0 = 3.1.y - 3.3.y");
    u.es = checked_unit(point(neutral, "3.5")[x] - point(neutral, "3.6")[x], "ES0 = 3.5.x - 3.6.x");
    u.ens = checked_unit(point(neutral, "3.5")[y] - point(neutral, "9.15")[y],
                         "ENS0 = 3.5.y - 9.15.y");
    u.mns = checked_unit(point(neutral, "9.15")[y] - point(neutral, "2.2")[y],
                         "MNS0 = 9.15.y - 2.2.y");
    u.mw = checked_unit(point(neutral, "8.3")[x] - point(neutral, "8.4")[x], "MW0 = 8.3.x - 8.4.x");
    return u;
}

}  // namespace emoface::fap
