#include "lights.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

namespace pcsg::tracer {

namespace {

constexpr double kEpsilon = 1e-10;          // POV-Ray's EPSILON
constexpr double kShadowTolerance = 1e-3;   // POV-Ray's SHADOW_TOLERANCE
constexpr double kAdaptiveThreshold = 0.1;  // corners further apart than this: subdivide

bool nearZero(const Vec3& c) {
    return std::fabs(c.x) < kEpsilon && std::fabs(c.y) < kEpsilon && std::fabs(c.z) < kEpsilon;
}

double colourDistance(const Vec3& a, const Vec3& b) {
    return std::fabs(a.x - b.x) + std::fabs(a.y - b.y) + std::fabs(a.z - b.z);
}

// POV-Ray's cubic_spline: 0 below low, 1 at or above high, 3t^2 - 2t^3 between.
double cubicSpline(double low, double high, double pos) {
    if (pos < low) return 0.0;
    if (pos >= high) return 1.0;
    const double t = (pos - low) / (high - low);
    return (3 - 2 * t) * t * t;
}

// A fixed number in [0, 1) for a lit point and a grid index: `jitter` without a random
// generator, so that renders are reproducible (and agree between threads and processes).
double jitterHash(const Vec3& p, int u, int v, int axis) {
    uint64_t h = 0x9e3779b97f4a7c15ull * static_cast<uint64_t>(u * 1315423911u + v * 2654435761u +
                                                               axis * 97u + 1);
    for (double c : {p.x, p.y, p.z}) {
        uint64_t bits;
        std::memcpy(&bits, &c, sizeof bits);
        h ^= bits + 0x9e3779b97f4a7c15ull + (h << 6) + (h >> 2);
    }
    h ^= h >> 33;
    h *= 0xff51afd7ed558ccdull;
    h ^= h >> 33;
    return static_cast<double>(h >> 11) * 0x1.0p-53;
}

// POV-Ray's recursion over a rectangle [u1, u2] x [v1, v2] of the grid
// (TraceAreaLightSubsetShadowRay), each grid point sampled at most once.
class AreaRecursion {
  public:
    AreaRecursion(int size1, int size2, int adaptive, const AreaSample& sample)
        : size2_(size2), adaptive_(adaptive), sample_(sample) {
        thread_local std::vector<Vec3> grid;
        thread_local std::vector<uint8_t> done;
        const size_t n = static_cast<size_t>(size1) * static_cast<size_t>(size2);
        grid.resize(n);
        done.assign(n, 0);
        grid_ = grid.data();
        done_ = done.data();
    }

    Vec3 region(int u1, int v1, int u2, int v2, int level) {
        Vec3 c[4] = {at(u1, v1), at(u2, v1), at(u1, v2), at(u2, v2)};
        if ((u2 - u1 > 1 || v2 - v1 > 1) &&
            (level < adaptive_ || colourDistance(c[0], c[1]) > kAdaptiveThreshold ||
             colourDistance(c[1], c[3]) > kAdaptiveThreshold ||
             colourDistance(c[3], c[2]) > kAdaptiveThreshold ||
             colourDistance(c[2], c[0]) > kAdaptiveThreshold)) {
            const int uLo = static_cast<int>(std::floor((u1 + u2) / 2.0));
            const int uHi = static_cast<int>(std::ceil((u1 + u2) / 2.0));
            const int vLo = static_cast<int>(std::floor((v1 + v2) / 2.0));
            const int vHi = static_cast<int>(std::ceil((v1 + v2) / 2.0));
            c[0] = region(u1, v1, uLo, vLo, level + 1);
            c[1] = region(uHi, v1, u2, vLo, level + 1);
            c[2] = region(u1, vHi, uLo, v2, level + 1);
            c[3] = region(uHi, vHi, u2, v2, level + 1);
        }
        return (c[0] + c[1] + c[2] + c[3]) * 0.25;
    }

  private:
    Vec3 at(int u, int v) {
        const size_t k = static_cast<size_t>(u) * static_cast<size_t>(size2_) +
                         static_cast<size_t>(v);
        if (!done_[k]) {
            grid_[k] = sample_(u, v);
            done_[k] = 1;
        }
        return grid_[k];
    }

    int size2_, adaptive_;
    const AreaSample& sample_;
    Vec3* grid_ = nullptr;
    uint8_t* done_ = nullptr;
};

// The shadow of an area light at p: the light's colour where a grid point is visible.
Vec3 areaShadow(const Light& light, const Vec3& p, const Vec3& colour, const Vec3& toCentre,
                Tracer& tracer, uint64_t& rays) {
    Vec3 axis1 = light.axis1, axis2 = light.axis2;
    if (light.orient) orientAxes(light, toCentre, axis1, axis2);
    const AreaSample sample = [&](int u, int v) {
        double ju = u, jv = v;
        if (light.jitter) {
            ju += jitterHash(p, u, v, 0) - 0.5;
            jv += jitterHash(p, u, v, 1) - 0.5;
        }
        const Vec3 l = light.position + areaOffset(light, ju, jv, axis1, axis2) - p;
        const double d = length(l);
        if (!(d > 0)) return colour;
        ++rays;
        return tracer.anyHit(p, l / d, kShadowTolerance, d - kShadowTolerance) ? Vec3{0, 0, 0}
                                                                               : colour;
    };
    return areaAverage(light.size1, light.size2, light.adaptive, sample);
}

}  // namespace

double spotAttenuation(const Light& light, const Vec3& toLight) {
    if (!light.spotlight) return 1.0;
    const Vec3 axis = light.pointAt - light.position;
    const double len = length(axis);
    // POV-Ray normalises the axis only when it is longer than EPSILON.
    const Vec3 dir = len > kEpsilon ? axis / len : axis;
    const double c = -dot(toLight, dir);
    if (!(c > 0)) return 0.0;
    double a = std::pow(c, light.tightness);
    const double rad = std::numbers::pi / 180;
    const double cosRadius = std::cos(light.radius * rad);
    const double cosFalloff = std::cos(light.falloff * rad);
    if (cosRadius > 0 && c < cosRadius) a *= cubicSpline(cosFalloff, cosRadius, c);
    return a;
}

double fadeAttenuation(const Light& light, double d) {
    if (!(light.fadePower > 0)) return 1.0;
    if (std::fabs(light.fadeDistance) >= kEpsilon)
        return 2.0 / (1.0 + std::pow(d / light.fadeDistance, light.fadePower));
    return std::pow(d, -light.fadePower);
}

Vec3 areaAverage(int size1, int size2, int adaptive, const AreaSample& sample) {
    AreaRecursion r(size1, size2, adaptive, sample);
    return r.region(0, 0, size1 - 1, size2 - 1, 0);
}

Vec3 areaOffset(const Light& light, double u, double v, const Vec3& axis1, const Vec3& axis2) {
    if (light.circular) {
        u = u / (light.size1 - 1) - 0.5 + 0.001;
        v = v / (light.size2 - 1) - 0.5 + 0.001;
        const double scale = std::max(std::fabs(u), std::fabs(v)) / std::sqrt(u * u + v * v);
        return axis1 * (u * scale) + axis2 * (v * scale);
    }
    Vec3 o{0, 0, 0};
    if (light.size1 > 1) o += axis1 * (u / (light.size1 - 1) - 0.5);
    if (light.size2 > 1) o += axis2 * (v / (light.size2 - 1) - 0.5);
    return o;
}

void orientAxes(const Light& light, const Vec3& l, Vec3& axis1, Vec3& axis2) {
    const double len = length(light.axis1);
    const Vec3 up = std::fabs(std::fabs(l.z) - 1.0) < 0.01 ? Vec3{0, 1, 0} : Vec3{0, 0, 1};
    axis1 = normalize(cross(l, up));
    axis2 = normalize(cross(l, axis1)) * len;
    axis1 = axis1 * len;
}

bool lightArriving(const Light& light, const Vec3& p, const Vec3& n, Tracer& tracer,
                   uint64_t& rays, ArrivingLight& out) {
    Vec3 l = light.position - p;
    const double d = length(l);
    if (!(d > 0)) return false;
    l = l / d;
    double attenuation = spotAttenuation(light, l);
    if (attenuation > 0) attenuation *= fadeAttenuation(light, d);
    Vec3 colour = light.color * attenuation;
    if (nearZero(colour)) return false;
    if (dot(n, l) < kEpsilon) return false;  // the light is behind the surface
    if (!light.shadowless) {
        if (light.areaLight()) {
            colour = areaShadow(light, p, colour, l, tracer, rays);
        } else {
            ++rays;
            if (tracer.anyHit(p, l, kShadowTolerance, d - kShadowTolerance)) return false;
        }
        if (nearZero(colour)) return false;
    }
    out.dir = l;
    out.colour = colour;
    out.highlights = !light.shadowless;
    return true;
}

}  // namespace pcsg::tracer
