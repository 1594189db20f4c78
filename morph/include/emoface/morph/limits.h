#pragma once
// The morph's limits that the public API (morph.h) and the kernel body
// (kernel.h, also compiled by nvcc) share, so each is written once.
namespace emoface::morph {

// Key maps a Morpher holds: a neutral key plus one key per wrinkling FACS
// Action Unit and side (about 20) fit with room to spare.
inline constexpr int kMaxKeys = 32;

}  // namespace emoface::morph
