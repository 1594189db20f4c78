#pragma once
// Internal GL helpers shared by the render sources (not installed).
#include <epoxy/gl.h>

#include "emoface/common/error.h"

namespace emoface::render::detail {

inline const char* gl_error_name(GLenum e) {
    switch (e) {
        case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
        case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
        case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
        default: return "unknown GL error";
    }
}

// Throws when GL recorded an error since the last check; `what` names the
// operation in the message.
inline void check_gl(const char* what) {
    const GLenum e = glGetError();
    if (e != GL_NO_ERROR) fail<InternalError>("render: {}: {} (0x{:04x})", what, gl_error_name(e), unsigned(e));
}

}  // namespace emoface::render::detail
