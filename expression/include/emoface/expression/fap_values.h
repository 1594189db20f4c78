#pragma once
// A full vector of FAP values, the rig's and the profiles' currency.
#include <array>

#include "emoface/fap/fap_table.h"

namespace emoface::expression {

// One value per FAP, index FAP number - 1 (as fap::FapFrame::values), in the
// FAP's own units (FAPU); FAPs 1 and 2 (viseme, expression) stay 0.
using FapValues = std::array<double, fap::kFapCount>;

}  // namespace emoface::expression
