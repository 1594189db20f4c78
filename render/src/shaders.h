#pragma once
// GLSL 3.3 core sources of the bump-mapping program (internal).
namespace emoface::render::detail {
extern const char* const kBumpVertexShader;
extern const char* const kBumpFragmentShader;
}  // namespace emoface::render::detail
