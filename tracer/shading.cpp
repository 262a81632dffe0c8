#include "shading.h"

#include <cmath>

namespace pcsg::tracer {

using C = ShadingConstants;

Shader::Shader(const TraceScene& scene) : g_(scene.graph()), tracer_(scene) {}

Vec3 Shader::local(const Vec3& p, const Vec3& n, const Vec3& d, const Material& m) {
    Vec3 colour = m.color * (m.ambient * C::kAmbientLight);
    for (const Light& light : g_.scene.lights) {
        Vec3 l = light.position - p;
        const double dist = length(l);
        if (!(dist > 0)) continue;
        l = l / dist;
        const double cosAngle = dot(n, l);
        if (cosAngle < C::kEpsilon) continue;  // the light is behind the surface
        ++rays_;
        if (tracer_.anyHit(p, l, C::kShadowTolerance, dist - C::kShadowTolerance)) continue;
        if (m.diffuse > 0) colour += mul(light.color, m.color) * (m.diffuse * std::fabs(cosAngle));
        if (m.phong > 0) {
            const Vec3 r = d - n * (2 * dot(d, n));
            const double c = dot(r, l);
            if (c > 0) colour += light.color * (m.phong * std::pow(c, m.phongSize));
        }
    }
    return colour;
}

Vec3 Shader::shade(const Ray& ray) {
    Vec3 colour{0, 0, 0};
    Vec3 origin = ray.origin, dir = ray.dir;
    double weight = 1.0;  // POV-Ray's ray weight, for adc_bailout
    double factor = 1.0;  // the product of the reflection coefficients so far
    for (int level = 1; level <= C::kMaxTraceLevel; ++level) {
        ++rays_;
        SurfaceHit hit;
        if (!tracer_.firstHit(origin, dir, C::kMinIsectDepth, C::kMaxDistance, hit)) {
            colour += g_.scene.background * factor;
            break;
        }
        const Vec3 p = origin + dir * hit.t;
        Vec3 n = normalize(hit.normal);
        if (!isFinite(n)) n = -dir;  // degenerate normal (apex of a cone): face the viewer
        if (dot(n, dir) > 0) n = -n;
        const Material& m = g_.materials[hit.material < g_.materials.size() ? hit.material : 0];
        colour += local(p, n, dir, m) * factor;
        if (!(m.reflection > 0)) break;
        weight *= m.reflection;
        if (weight < C::kAdcBailout) break;
        factor *= m.reflection;
        dir = normalize(dir - n * (2 * dot(dir, n)));
        origin = p;
    }
    return colour;
}

}  // namespace pcsg::tracer
