#pragma once
// Face animation parameter units: FAP values are integers in these units, so
// one FAP stream drives faces of any size. Each distance unit is a distance
// on the neutral face divided by 1024; AU is 1e-5 rad.
#include <array>

#include "emoface/fap/fap_table.h"
#include "emoface/fap/feature_points.h"

namespace emoface::fap {

struct Fapu {
    double irisd = 0;  // IRISD0 / 1024, IRISD0 = 3.1.y - 3.3.y (upper to lower left eyelid)
    double es = 0;     // ES0 / 1024,    ES0    = 3.5.x - 3.6.x (pupil to pupil)
    double ens = 0;    // ENS0 / 1024,   ENS0   = 3.5.y - 9.15.y (eyes to nose)
    double mns = 0;    // MNS0 / 1024,   MNS0   = 9.15.y - 2.2.y (nose to mouth)
    double mw = 0;     // MW0 / 1024,    MW0    = 8.3.x - 8.4.x (mouth width)
    double au = 1e-5;  // radians
    double of(FapUnit unit) const;  // None -> 0
};

// Neutral-face positions of the 84 feature points, indexed by
// feature_point_index(), in the frame of fap_table.h (x = face's left, y up).
using FeaturePointPositions = std::array<std::array<double, 3>, kFeaturePointCount>;

// Uses 3.1, 3.3, 3.5, 3.6, 9.15, 2.2, 8.3 and 8.4. Throws emoface::InputError
// naming the distance when one is not positive (e.g. a mirrored face).
Fapu compute_fapu(const FeaturePointPositions& neutral);

}  // namespace emoface::fap
