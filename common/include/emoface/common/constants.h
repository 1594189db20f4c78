#pragma once
// Numeric constants shared by every module (one definition each).

namespace emoface {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr float kPiF = static_cast<float>(kPi);

}  // namespace emoface
