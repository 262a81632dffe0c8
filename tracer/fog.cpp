#include "fog.h"

#include <algorithm>
#include <cmath>

namespace pcsg::tracer {

namespace {

constexpr double kEpsilon = 1e-10;  // POV-Ray's EPSILON

// The mean ground-fog density between heights s and e (in fog_alt units above fog_offset).
double groundDensity(double s, double e) {
    if (s <= 0) return e <= 0 ? 1.0 : (std::atan(e) - s) / (e - s);
    if (e <= 0) return (std::atan(s) - e) / (s - e);
    const double delta = s - e;
    if (std::fabs(delta) > kEpsilon) return (std::atan(s) - std::atan(e)) / delta;
    return 1.0 / (s * s + 1.0);
}

}  // namespace

double fogTransmittance(const Fog& fog, const Vec3& origin, const Vec3& dir, double depth) {
    if (fog.type != 2) return std::exp(-depth / fog.distance);
    const Vec3 end = origin + dir * depth;
    const double s = (origin.z - fog.offset) / fog.alt;
    const double e = (end.z - fog.offset) / fog.alt;
    return std::exp(-depth * groundDensity(s, e) / fog.distance);
}

FogEffect fogAlong(const Fog& fog, const Vec3& origin, const Vec3& dir, double depth) {
    FogEffect out;
    if (!fog.enabled || !(std::fabs(fog.distance) > kEpsilon)) return out;
    const double a = std::max(fogTransmittance(fog, origin, dir, depth), fog.transmit);
    const Vec3 filtered{(1 - fog.filter) + fog.filter * fog.color.x,
                        (1 - fog.filter) + fog.filter * fog.color.y,
                        (1 - fog.filter) + fog.filter * fog.color.z};
    out.attenuation = filtered * a;
    out.add = fog.color * (1 - a);
    return out;
}

}  // namespace pcsg::tracer
