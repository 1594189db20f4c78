#pragma once
// The two tables the skin shading model samples, computed on the CPU when a
// Renderer first draws with them (internal).
#include <cstdint>
#include <vector>

#include "emoface/render/skin_shading.h"

namespace emoface::render::detail {

// Pre-integrated scattering (Penner & Borshukov 2011): width x height RGB
// floats, row-major from row 0. Column i: N.L = -1 + 2 (i + 0.5) / width;
// row j: curvature (j + 0.5) / height * max_curvature (1/mm), row 0 being
// nearly flat. Each texel is the profile integrated over a ring of radius
// 1/curvature against the clamped cosine, divided by the profile integrated
// over the same ring: at zero curvature, max(N.L, 0) (Lambert).
std::vector<float> preintegrated_scatter_table(const SkinShading& skin, int width, int height);

// The pore map: spec.size^2 RGBA8 texels, tileable, deterministic for a spec.
// RGB = 0.5 + 0.5 n (n.x along the tile's columns, n.y along its rows, n.z
// out of the skin); A = cavity, 255 on open skin, lower in the pits.
std::vector<std::uint8_t> pore_map(const PoreMapSpec& spec);

}  // namespace emoface::render::detail
