#pragma once
// The viewer's controls that are plain arithmetic (kept out of the GL and
// ImGui code so tests can check them): the mouse-driven orbit camera (yaw and
// pitch about the face's centre, a distance for zoom, a pan in the view
// plane), the directional light given by azimuth and elevation, and the rule
// that keeps the six emotion sliders summing to at most 1.
#include <array>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "emoface/render/renderer.h"

namespace emoface::apps {

struct OrbitCamera {
    glm::vec3 target{0.0f};
    float distance = 1.0f;
    float yaw = 0.0f;    // radians about +y; 0 looks down -z (frontal)
    float pitch = 0.0f;  // radians, positive looks from above
    float fovy_degrees = 20.0f;
    float radius = 1.0f;  // of the face's bounding sphere: near/far planes and zoom limits

    // Frames the face as the frontal camera does (`frontal` looks down -z at
    // a face whose bounding box is [box_min, box_max]).
    static OrbitCamera around(const render::Camera& frontal, const glm::vec3& box_min,
                              const glm::vec3& box_max, float fovy_degrees);

    glm::vec3 eye() const;
    render::Camera camera(float aspect) const;

    // Mouse gestures, in pixels of a window `height` pixels tall.
    void orbit(float dx, float dy);
    void pan(float dx, float dy, float height);
    // `steps` wheel notches; positive zooms in.
    void zoom(float steps);
};

struct LightControl {
    float azimuth = 0.0f;    // radians about +y from +z (towards the viewer)
    float elevation = 0.0f;  // radians above the horizontal
    static LightControl from(const render::Light& light);
    glm::vec4 direction() const;  // w = 0: directional
    void drag(float dx, float dy);
};

// Slider `moved` was set to `value` (clamped to [0, 1]); when the six then
// sum over 1, the other five are scaled down together so the sum is exactly
// 1 and the slider under the mouse keeps the value it was dragged to.
// Returns whether the others were scaled.
bool set_emotion_slider(std::array<float, 6>& weights, int moved, float value);

}  // namespace emoface::apps
