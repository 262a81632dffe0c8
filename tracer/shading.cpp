#include "shading.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "fog.h"
#include "lights.h"
#include "perturb.h"
#include "pigment.h"

namespace pcsg::tracer {

using C = ShadingConstants;

Shader::Shader(const TraceScene& scene) : g_(scene.graph()), tracer_(scene) {}

namespace {

// POV-Ray's empirical Fresnel term for metallic highlights and reflection: the share of the
// surface colour in the reflected light at an angle whose cosine is `cosAngle`.
double metallicShare(double cosAngle) {
    const double x = std::fabs(std::acos(std::clamp(cosAngle, -1.0, 1.0))) / (std::numbers::pi / 2);
    const double f = 0.014567225 / ((x - 1.12) * (x - 1.12)) - 0.011612903;
    return 1.0 - std::clamp(f, 0.0, 1.0);
}

// A highlight of `intensity` in the light's colour, or with finish metallic tinted by the
// pigment's colour.
Vec3 highlight(double intensity, const Vec3& lightColour, const Material& m, const Vec3& pigment,
               double ndotl) {
    if (!(m.metallic > 0)) return lightColour * intensity;
    const double k = m.metallic * metallicShare(ndotl);
    const Vec3 tint{1 + k * (pigment.x - 1), 1 + k * (pigment.y - 1), 1 + k * (pigment.z - 1)};
    return mul(lightColour, tint) * intensity;
}

}  // namespace

// Diffuse, phong and specular of one light seen along direction l (unit, toward the light).
Vec3 Shader::lit(const Vec3& n, const Vec3& d, const Vec3& l, const Vec3& lightColour,
                 const Material& m, const Vec3& pigment, bool highlights) const {
    Vec3 colour{0, 0, 0};
    const double cosAngle = dot(n, l);
    if (m.diffuse > 0) {
        const double c = std::fabs(cosAngle);
        const double intensity = m.brilliance != 1 ? std::pow(c, m.brilliance) : c;
        colour += mul(lightColour, pigment) * (intensity * m.diffuse);
    }
    if (!highlights) return colour;
    if (m.phong > 0) {
        const Vec3 r = d - n * (2 * dot(d, n));
        const double c = dot(r, l);
        if (c > 0) {
            const double intensity =
                (m.phongSize < 60 || c > 0.0008) ? m.phong * std::pow(c, m.phongSize) : 0.0;
            colour += highlight(intensity, lightColour, m, pigment, cosAngle);
        }
    }
    if (m.specular > 0) {
        const Vec3 h = (l - d) * 0.5;  // halfway between the light and the viewer
        const double len = length(h);
        const double c = len > 0 ? dot(h, n) / len : 0.0;
        if (c > 0) {
            const double exponent = m.roughness != 0 ? 1 / m.roughness : 0.0;
            colour +=
                highlight(m.specular * std::pow(c, exponent), lightColour, m, pigment, cosAngle);
        }
    }
    return colour;
}

Vec3 Shader::local(const Vec3& p, const Vec3& n, const Vec3& d, const Material& m,
                   const Vec3& pigment) {
    Vec3 colour = pigment * (m.ambient * C::kAmbientLight);
    if (!(m.diffuse != 0 || m.phong != 0 || m.specular != 0)) return colour;
    for (const Light& light : g_.scene.lights) {
        ArrivingLight a;  // lights.h: spot, fade, area and shadowless lights
        if (lightArriving(light, p, n, tracer_, rays_, a))
            colour += lit(n, d, a.dir, a.colour, m, pigment, a.highlights);
    }
    return colour;
}

Reflectivity reflectivity(const Material& m, double cosIncidence, const Vec3& pigment) {
    const double hi = m.reflection, lo = m.minReflection();
    Reflectivity out;
    double amount;
    if (m.fresnel) {
        // POV-Ray's Fresnel formula for unpolarised light; the ray comes from the
        // atmosphere (ior 1), so the relative ior is the interior's.
        const double c = cosIncidence;
        const double sqx = m.ior * m.ior + c * c - 1;
        if (sqx > 0) {
            const double g = std::sqrt(sqx);
            double f = 0.5 * ((g - c) * (g - c)) / ((g + c) * (g + c));
            const double a = c * (g + c) - 1, b = c * (g - c) + 1;
            f = std::clamp(f * (1 + (a * a) / (b * b)), 0.0, 1.0);
            amount = f * hi + (1 - f) * lo;
        } else {
            amount = hi;
        }
        out.weight = amount;
    } else {
        const double frac = 1 - cosIncidence;  // falloff 1
        if (std::fabs(frac) < C::kEpsilon)
            amount = lo;
        else if (std::fabs(frac - 1) < C::kEpsilon)
            amount = hi;
        else
            amount = frac * hi + (1 - frac) * lo;
        out.weight = std::max(hi, lo);
    }
    out.colour = Vec3{amount, amount, amount};
    if (m.reflectMetallic != 0) {
        const double k = m.reflectMetallic * metallicShare(cosIncidence);
        out.colour = mul(out.colour, Vec3{1 + k * (pigment.x - 1), 1 + k * (pigment.y - 1),
                                          1 + k * (pigment.z - 1)});
    }
    return out;
}

Vec3 Shader::shade(const Ray& ray) {
    Vec3 colour{0, 0, 0};
    Vec3 origin = ray.origin, dir = ray.dir;
    double weight = 1.0;         // POV-Ray's ray weight, for adc_bailout
    Vec3 factor{1.0, 1.0, 1.0};  // the product of the reflectivities so far
    for (int level = 1; level <= C::kMaxTraceLevel; ++level) {
        ++rays_;
        SurfaceHit hit;
        const bool found = tracer_.firstHit(origin, dir, C::kMinIsectDepth, C::kMaxDistance, hit);
        if (g_.scene.fog.enabled) {  // fog.h: colour = add + attenuation x the colour behind
            const FogEffect f = fogAlong(g_.scene.fog, origin, dir, found ? hit.t : kFogMissDepth);
            colour += mul(f.add, factor);
            factor = mul(factor, f.attenuation);
        }
        if (!found) {
            colour += mul(skyColour(g_.scene, dir), factor);
            break;
        }
        const Vec3 p = origin + dir * hit.t;
        Vec3 n = normalize(hit.normal);
        if (!isFinite(n)) n = -dir;  // degenerate normal (apex of a cone): face the viewer
        if (dot(n, dir) > 0) n = -n;
        const Material& m = g_.materials[hit.material < g_.materials.size() ? hit.material : 0];
        if (m.normal.kind != NormalKind::None && hit.painted) n = perturbedNormal(m.normal, hit, n);
        const FilterColour pigment = pigmentColour(m, hit);
        colour += mul(local(p, n, dir, m, pigment.rgb), factor);
        const Reflectivity r = reflectivity(m, -dot(dir, n), pigment.rgb);
        if (r.colour.x == 0 && r.colour.y == 0 && r.colour.z == 0) break;
        weight *= r.weight;
        if (weight < C::kAdcBailout) break;
        factor = mul(factor, r.colour);
        dir = normalize(dir - n * (2 * dot(dir, n)));
        origin = p;
    }
    return colour;
}

}  // namespace pcsg::tracer
