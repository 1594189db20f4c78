#pragma once
// The two tables the skin shading model samples, computed on the CPU when a
// Renderer first draws with them (internal).
#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "emoface/render/image.h"
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
// Pits (one per cell of a jittered cells x cells grid) over the skin's
// microrelief: furrows in three families of meandering lines that cross,
// about 0.8 cells apart (2 noise_scale deep), and a faint fine noise.
// RGB = 0.5 + 0.5 n (n.x along the tile's columns, n.y along its rows, n.z
// out of the skin); A = cavity, 255 on open skin, lower in the pits (the
// furrows are too shallow to hold light: a cavity there dimmed all skin).
std::vector<std::uint8_t> pore_map(const PoreMapSpec& spec);

// The base colour's fine relief, baked once so the shader needs neither a
// second look-up of the colour nor derivatives of a height: the height is
// the linear luminance's log above its local mean (two box blurs spanning
// about 2^(mean_levels + 2) texels: what a look-up mean_levels mip levels up
// averaged at the default framing, where the base map is already about two
// levels minified), clamped to +-0.5 (the step from skin to a dark hair
// is a colour edge, not a cliff), and the result is its slopes (dh/du,
// dh/dv per unit of the base UVs), faded to 0 across the edge of hair (the
// step from skin to hair is no relief), and third the hair mask: 1 where
// the local mean's luminance is below hair_luminance[0], 0 above [1]
// (smoothstep between). Width x height RGB float triples, rows bottom first
// as the base texture is uploaded (v up). Hair strands, brow hairs and lip
// lines, lighter than the gaps between them, stand out.
std::vector<float> albedo_detail_slopes(const ImageRGBA8& image, float mean_levels,
                                        std::array<float, 2> hair_luminance);

// Per-vertex values painted into a texture of the base UVs (texel (x, y) at
// ((x + 0.5) / width, (y + 0.5) / height), rows bottom first as above),
// interpolated over each triangle; then grown `dilate` texels out past the
// triangles' edges (each empty texel takes the mean of its painted
// neighbours), so that bilinear filtering and mip levels by a UV seam see
// the values and not the gutter; texels left over hold `empty`.
std::vector<float> vertex_values_in_uv(const std::vector<glm::vec2>& uvs, const std::vector<unsigned>& triangles,
                                       const std::vector<float>& values, int width, int height, int dilate,
                                       float empty);

}  // namespace emoface::render::detail
