#include "viewer_controls.h"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "emoface/common/constants.h"

namespace emoface::apps {

namespace {
constexpr float kMaxPitch = 85.0f * kPiF / 180.0f;
constexpr float kRadiansPerPixel = 0.008f;
}  // namespace

OrbitCamera OrbitCamera::around(const render::Camera& frontal, const glm::vec3& box_min,
                                const glm::vec3& box_max, float fovy_degrees) {
    OrbitCamera c;
    const glm::vec3 centre = 0.5f * (box_min + box_max);
    c.radius = std::max(0.5f * glm::length(box_max - box_min), 1e-6f);
    // The frontal camera looks down -z: keep its x, y (what it framed) and
    // orbit about the box's middle depth.
    c.target = {frontal.position.x, frontal.position.y, centre.z};
    c.distance = std::max(frontal.position.z - centre.z, 0.1f * c.radius);
    c.fovy_degrees = fovy_degrees;
    return c;
}

glm::vec3 OrbitCamera::eye() const {
    const float cp = std::cos(pitch);
    return target + distance * glm::vec3(cp * std::sin(yaw), std::sin(pitch), cp * std::cos(yaw));
}

render::Camera OrbitCamera::camera(float aspect) const {
    // Near and far hug the face's bounding sphere so depth keeps its precision.
    const float near_plane = std::max(distance - 2.0f * radius, 0.01f * distance);
    const float far_plane = distance + 2.0f * radius;
    return render::Camera::look_at(eye(), target, {0.0f, 1.0f, 0.0f}, fovy_degrees, aspect,
                                   near_plane, far_plane);
}

void OrbitCamera::orbit(float dx, float dy) {
    yaw -= dx * kRadiansPerPixel;
    pitch = std::clamp(pitch + dy * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

void OrbitCamera::pan(float dx, float dy, float height) {
    // One pixel moves the target by the size a pixel has at the target's depth.
    const float per_pixel =
        2.0f * distance * std::tan(0.5f * fovy_degrees * kPiF / 180.0f) / std::max(height, 1.0f);
    const glm::vec3 forward = glm::normalize(target - eye());
    const glm::vec3 right = glm::normalize(glm::cross(forward, glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::vec3 up = glm::cross(right, forward);
    target += per_pixel * (-dx * right + dy * up);
}

void OrbitCamera::zoom(float steps) {
    distance = std::clamp(distance * std::pow(0.9f, steps), 0.3f * radius, 20.0f * radius);
}

LightControl LightControl::from(const render::Light& light) {
    glm::vec3 d(light.position);
    if (light.position.w != 0.0f || glm::length(d) == 0.0f) d = {0.0f, 0.0f, 1.0f};
    d = glm::normalize(d);
    LightControl l;
    l.azimuth = std::atan2(d.x, d.z);
    l.elevation = std::asin(std::clamp(d.y, -1.0f, 1.0f));
    return l;
}

glm::vec4 LightControl::direction() const {
    const float ce = std::cos(elevation);
    return {ce * std::sin(azimuth), std::sin(elevation), ce * std::cos(azimuth), 0.0f};
}

void LightControl::drag(float dx, float dy) {
    azimuth += dx * kRadiansPerPixel;
    if (azimuth > kPiF) azimuth -= 2.0f * kPiF;
    if (azimuth < -kPiF) azimuth += 2.0f * kPiF;
    elevation = std::clamp(elevation - dy * kRadiansPerPixel, -kMaxPitch, kMaxPitch);
}

bool set_emotion_slider(std::array<float, 6>& weights, int moved, float value) {
    weights.at(std::size_t(moved)) = std::clamp(value, 0.0f, 1.0f);
    float others = 0.0f;
    for (std::size_t i = 0; i < weights.size(); ++i)
        if (int(i) != moved) others += weights[i];
    const float room = 1.0f - weights[std::size_t(moved)];
    if (others <= room) return false;
    const float scale = room / others;  // others > room >= 0
    for (std::size_t i = 0; i < weights.size(); ++i)
        if (int(i) != moved) weights[i] *= scale;
    return true;
}

}  // namespace emoface::apps
