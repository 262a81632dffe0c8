#include "camera.h"

#include <cmath>

namespace pcsg::tracer {

PinholeCamera::PinholeCamera(const Camera& cam, int width, int height)
    : location_(cam.location), width_(width), height_(height) {
    const double aspect = static_cast<double>(width) / static_cast<double>(height);
    constexpr double kPi = 3.14159265358979323846;
    // `right -x*aspect`, `up y`, `direction z`, then `angle` (see camera.h).
    const double rightLength = aspect;
    const double upLength = 1.0;
    const double directionLength = rightLength / std::tan(cam.angle * kPi / 360.0) / 2.0;

    // `look_at`: the handedness of the given vectors is negative (right-handed scene).
    Vec3 d = cam.lookAt - cam.location;
    d = normalize(d);
    Vec3 s = cross(cam.sky, d);
    constexpr double kEpsilon = 1e-10;
    if (std::fabs(s.x) < kEpsilon && std::fabs(s.y) < kEpsilon && std::fabs(s.z) < kEpsilon)
        s = Vec3{-1, 0, 0};  // POV-Ray falls back to the given right vector, -x
    s = normalize(s);
    up_ = cross(d, s) * upLength;
    direction_ = d * directionLength;
    right_ = s * -rightLength;
}

Ray PinholeCamera::ray(double x, double y) const {
    const double x0 = x / width_ - 0.5;
    const double y0 = 0.5 - y / height_;
    return Ray{location_, normalize(direction_ + right_ * x0 + up_ * y0)};
}

}  // namespace pcsg::tracer
