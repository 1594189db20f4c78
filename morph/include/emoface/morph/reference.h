#pragma once
// A double-precision reference of the warp and blend, written from the
// textbook formulas (thesis 3.2.2 c) with plain loops and no shared code with
// kernel.h, for tests. Same conventions as Morpher (morph.h): normalised line
// coordinates, distances in units of the longer side, pixel centres at
// i + 0.5, bilinear sampling clamped to the edge. No input checks: give it
// what Morpher accepts. Slow: W·H·N·K work in double on one thread.
#include <vector>

#include "emoface/morph/morph.h"

namespace emoface::morph {

// out: width * height * K * 2 doubles, laid out like Morpher::positions_to_host.
void reference_positions(int width, int height, const std::vector<Layout>& key_layouts, const Layout& target,
                         const MorphParams& params, std::vector<double>& out);

// out: width * height pixels of `format`, tightly packed. RGBA8 rounds to
// nearest. params.accuracy is ignored (always exact). Follows morph.h's
// formula: Σ w_k key_k + (1 − Σ w) rest, each key rest outside its region,
// evaluated everywhere (no bounds).
void reference_morph(int width, int height, PixelFormat format, const std::vector<KeyMap>& keys,
                     const Layout& target, const std::vector<float>& weights, const MorphParams& params, void* out);

}  // namespace emoface::morph
