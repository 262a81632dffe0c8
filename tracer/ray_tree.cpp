// The ray tree of shading.h: POV-Ray 3.7's TraceRay and the single-layer case of its
// ComputeLightedTexture, with the transparency of transparency.h.
#include <algorithm>
#include <cmath>
#include <vector>

#include "fog.h"
#include "perturb.h"
#include "pigment.h"
#include "shading.h"

namespace pcsg::tracer {

using C = ShadingConstants;

// A hit being shaded: where, the normal facing the ray, the material and its pigment there.
struct Shader::Surface {
    const TreeRay& ray;
    int level;  // the trace level of the ray that hit (the camera ray's hit: 1)
    double t;
    Vec3 p, n;
    Vec3 raw;           // the surface's own normal facing the ray (n before a normal pattern)
    Interior interior;  // its object's (transparency.h), whose material is m
    const Material& m;
    FilterColour pigment;
    Reflectivity reflection;
};

Vec3 Shader::trace(const TreeRay& ray, double weight, bool continued) {
    const Settings& st = g_.scene.settings;
    if (ray.level >= static_cast<int>(st.maxTraceLevel) || weight < st.adcBailout ||
        ray.straight > kMaxStraight)
        return Vec3{0, 0, 0};
    ++rays_;
    SurfaceHit hit;
    const bool found =
        tracer_.firstHit(ray.origin, ray.dir, C::kMinIsectDepth, C::kMaxDistance, hit);
    const Vec3 behind =
        found ? shadeHit(ray, hit, weight, continued) : skyColour(g_.scene, ray.dir);
    // Fog (fog.h) on the stretch the ray travelled through the air: add + attenuation x
    // the colour behind; rays inside a solid are not fogged.
    if (!g_.scene.fog.enabled || !ray.inside.empty()) return behind;
    const FogEffect f = fogAlong(g_.scene.fog, ray.origin, ray.dir, found ? hit.t : kFogMissDepth);
    return f.add + mul(f.attenuation, behind);
}

// The colour of the surface `ray` hit: its normal facing the ray, perturbed by the
// material's normal pattern (after the turn, as POV-Ray does), then the lighted texture.
Vec3 Shader::shadeHit(const TreeRay& ray, const SurfaceHit& hit, double weight, bool continued) {
    Vec3 n = normalize(hit.normal);
    if (!isFinite(n)) n = -ray.dir;  // degenerate normal (apex of a cone): face the viewer
    if (dot(n, ray.dir) > 0) n = -n;
    const Vec3 raw = n;
    const uint32_t mi = hit.material < g_.materials.size() ? hit.material : 0;
    const Material& m = g_.materials[mi];
    if (m.normal.kind != NormalKind::None && hit.painted) n = perturbedNormal(m.normal, hit, n);
    const FilterColour pigment = pigmentColour(m, hit);
    const double cosIncidence = -dot(ray.dir, n);
    const Interior interior{hit.interior, mi};
    const Surface s{
        ray,
        continued ? ray.level : ray.level + 1,
        hit.t,
        ray.origin + ray.dir * hit.t,
        n,
        raw,
        interior,
        m,
        pigment,
        reflectivity(m, cosIncidence, pigment.rgb, relativeIor(ray.inside, interior, g_))};
    return shadeSurface(s, weight);
}

// ComputeLightedTexture for one layer: the local colour scaled by the opacity, the
// transmitted ray filtered by what the pigment lets through, the reflected ray unless the
// transmitted one was totally reflected.
Vec3 Shader::shadeSurface(const Surface& s, double weight) {
    Vec3 colour = local(s.p, s.n, s.ray.dir, s.m, s.pigment.rgb, opacity(s.pigment), s.ray.inside);
    bool totalReflection = false;
    if (isTransparent(s.pigment)) colour += transmitted(s, weight, totalReflection);
    const Vec3& r = s.reflection.colour;
    if (!totalReflection && (r.x != 0 || r.y != 0 || r.z != 0))
        colour += mul(r, reflected(s, weight * s.reflection.weight));
    return colour;
}

namespace {
// The normal n turned to face a ray in direction d: a normal pattern may have tilted the
// normal away from the ray, and POV-Ray's ComputeRefraction refracts at it turned back.
Vec3 facingRay(const Vec3& n, const Vec3& d) {
    return dot(d, n) > 0 ? -n : n;
}
}  // namespace

// The light through the surface (ComputeRefraction, TraceRefractionRay): a straight ray
// between equal iors, a refracted one, or on total internal reflection the reflected ray.
Vec3 Shader::transmitted(const Surface& s, double weight, bool& totalReflection) {
    Vec3 passes = transmittedColour(s.pigment);
    if (s.m.conserveEnergy) passes = conserveEnergy(passes, s.reflection.colour);
    const double trans = std::min(1.0, std::fabs(greyscale(passes)));
    const double bailout = g_.scene.settings.adcBailout;
    if (!(trans > bailout)) return Vec3{0, 0, 0};
    const double w = weight * maxAbs(passes);
    TreeRay next{s.p, s.ray.dir, s.level, s.ray.inside, s.ray.straight};
    const double ior = crossSurface(next.inside, s.interior, g_);
    Vec3 light;
    if (std::fabs(ior - 1.0) < C::kEpsilon) {
        next.straight = s.ray.straight + 1;
        light = trace(next, w, true);
    } else if (const auto d = refractDirection(s.ray.dir, facingRay(s.n, s.ray.dir), ior)) {
        next.dir = normalize(*d);
        light = trace(next, w, false);
    } else {
        totalReflection = true;
        light = reflected(s, w);
    }
    // Light that travelled inside this interior fades on the way.
    if (s.ray.inside.contains(s.interior.id)) light = mul(light, fade(s.m, s.t));
    return totalReflection ? light : mul(light, passes);
}

// The ray mirrored at the surface (ComputeReflection), in the incoming ray's interiors.
// A normal pattern may tilt the normal so far that the mirrored ray goes into the surface
// (below its own normal); POV-Ray then mirrors it at the surface's own normal instead
// when it also goes against the tilted one, else mirrors it once more at the own normal
// (its "reflection bugfix" of 1998).
Vec3 Shader::reflected(const Surface& s, double weight) {
    Vec3 d = s.ray.dir - s.n * (2 * dot(s.ray.dir, s.n));
    const double below = dot(d, s.raw);
    if (below < 0) {
        if (dot(d, s.n) < 0)
            d = s.ray.dir - s.raw * (2 * dot(s.ray.dir, s.raw));
        else
            d = d + s.raw * (-2 * below);
    }
    d = normalize(d);
    return trace(TreeRay{s.p, d, s.level, s.ray.inside, s.ray.straight}, weight, false);
}

// TracePointLightShadowRay with ComputeShadowColour and ComputeShadowMedia: the shadow ray
// goes on through every surface that lets light through, filtered by it, until the light or
// an opaque surface. It starts in the interiors of the ray being lit and enters or leaves
// the interior of each surface it crosses (leaving when it is in it), so a stretch inside a
// fading interior fades.
Vec3 Shader::shadowFilter(const Vec3& p, const Vec3& l, double dist, const Interiors& lit) {
    ++rays_;
    if (!anyTransparent_)
        return tracer_.anyHit(p, l, C::kShadowTolerance, dist - C::kShadowTolerance)
                   ? Vec3{0, 0, 0}
                   : Vec3{1, 1, 1};
    Interiors inside = lit;  // the shadow ray enters and leaves interiors on its way
    Vec3 filter{1, 1, 1}, origin = p;
    double remaining = dist;
    const double bailout = g_.scene.settings.adcBailout;
    SurfaceHit hit;
    while (tracer_.firstHit(origin, l, C::kShadowTolerance, remaining - C::kShadowTolerance, hit)) {
        const uint32_t mi = hit.material < g_.materials.size() ? hit.material : 0;
        const Material& m = g_.materials[mi];
        const FilterColour pigment = pigmentColour(m, hit);
        if (!isTransparent(pigment)) return Vec3{0, 0, 0};
        Vec3 through = transmittedColour(pigment);
        if (inside.contains(hit.interior)) through = mul(through, fade(m, hit.t, true));
        if (!inside.remove(hit.interior)) inside.push(Interior{hit.interior, mi});
        if ((std::fabs(through.x) + std::fabs(through.y) + std::fabs(through.z)) / 3 < bailout)
            return Vec3{0, 0, 0};
        filter = mul(filter, through);
        if (std::fabs(filter.x) < C::kEpsilon && std::fabs(filter.y) < C::kEpsilon &&
            std::fabs(filter.z) < C::kEpsilon)
            return Vec3{0, 0, 0};
        origin = origin + l * hit.t;
        remaining -= hit.t;
        ++rays_;
    }
    return filter;
}

// Which solids contain `at`: a probe ray from it meets their surfaces from inside (the
// normal, outward from the solid hit, points along the ray) before it has entered them.
// The first one left is the innermost. Only scenes with transparency need it.
const Interiors& Shader::startInteriors(const Vec3& at) {
    if (startKnown_ && at == startAt_) return startInside_;
    startKnown_ = true;
    startAt_ = at;
    startInside_ = Interiors{};
    if (!anyTransparent_) return startInside_;
    const Vec3 d = normalize(Vec3{0.5773, 0.5774, 0.5775});  // away from the axes
    std::vector<Interior> entered, left;
    Vec3 origin = at;
    SurfaceHit hit;
    for (int k = 0; k < 100000; ++k) {
        if (!tracer_.firstHit(origin, d, C::kMinIsectDepth, C::kMaxDistance, hit)) break;
        const Interior here{hit.interior, hit.material < g_.materials.size() ? hit.material : 0};
        if (dot(hit.normal, d) > 0) {
            const auto it = std::find_if(entered.rbegin(), entered.rend(),
                                         [&](const Interior& i) { return i.id == here.id; });
            if (it != entered.rend())
                entered.erase(std::next(it).base());
            else
                left.push_back(here);
        } else {
            entered.push_back(here);
        }
        origin = origin + d * hit.t;
    }
    for (auto it = left.rbegin(); it != left.rend(); ++it) startInside_.push(*it);
    return startInside_;
}

}  // namespace pcsg::tracer
