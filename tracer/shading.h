// Lights, materials and background as docs/language.md section 7 says: POV-Ray 3.7.0's classic
// lighting for the subset of its features the language has, so that `pcsg verify` can
// compare our image with POV-Ray's pixel by pixel.
//
// The POV-Ray conventions we follow (source/backend/render/trace.cpp of 3.7.0: TraceRay,
// ComputeTextureColour, ComputeLightedTexture, ComputeOneDiffuseLight,
// ComputeDiffuseColour, ComputePhongColour, ComputeReflection, TracePointLightShadowRay;
// constants from frame.h / configcore.h), with the exporter writing
// `global_settings { assumed_gamma 1.0 }` and nothing else that changes them:
//
//  - Rays: world directions have unit length, so t is the distance. A ray's hit must have
//    MIN_ISECT_DEPTH (1e-4) < t < MAX_DISTANCE (1e7). A ray that hits nothing gets the
//    background colour (also for reflected rays).
//  - Normals are flipped to face the incoming ray: if N . D > 0, N = -N (POV-Ray's
//    "if the surface normal points away, flip its direction"). CSG surfaces and triangles
//    are therefore lit from whichever side is seen.
//  - Ambient: pigment * ambient * ambient_light, ambient_light = 1 (POV-Ray's default).
//  - For each point light at position Lp with colour Lc, L = normalize(Lp - P) (no light
//    is looked at when diffuse, phong and specular are all 0):
//      * skipped if N . L < EPSILON (1e-10): the light is behind the surface;
//      * hard shadow: a shadow ray from P toward the light; blocked by any surface with
//        SHADOW_TOLERANCE (1e-3) < t < |Lp - P| - SHADOW_TOLERANCE;
//      * diffuse (ComputeDiffuseColour): Lc * pigment * diffuse * |N . L|^brilliance;
//      * phong (ComputePhongColour): with R = D - 2 (D . N) N the mirrored view direction,
//        if R . L > 0: phong * (R . L)^phong_size, 0 when phong_size >= 60 and R . L <=
//        0.0008 (POV-Ray's cut-off);
//      * specular (ComputeSpecularColour): with H = (L - D) / 2, if c = H . N / |H| > 0:
//        specular * c^(1 / roughness);
//      * a highlight is in the light's colour; with finish `metallic k` it is Lc * (1 + k
//        (1 - F) (pigment - 1)), F POV-Ray's empirical Fresnel term of acos(N . L):
//        x = acos / (pi/2), F = clamp(0.014567225 / (x - 1.12)^2 - 0.011612903, 0, 1).
//    No light attenuation with distance (POV-Ray's default fade_power 0). Spotlights,
//    fading, shadowless and area lights: lights.h (Shader::local asks lightArriving()
//    for each light's direction and colour). Fog: fog.h (Shader::shade applies it to
//    each ray segment: colour += factor x add, factor *= attenuation).
//  - Reflection (ComputeReflectivity, reflection_type 0 or 1, falloff 1), with cos = -D . N:
//      * without fresnel, amount = min when 1 - cos is 0, max when it is 1, else (1 - cos)
//        max + cos min; the ray's weight is multiplied by max(min, max);
//      * with fresnel, f = POV-Ray's Fresnel formula for unpolarised light at the relative
//        ior (n2 / n1 by the ray's interior stack, transparency.h), amount = f max + (1 - f)
//        min (max when the square root's argument is not positive); the weight is
//        multiplied by the amount;
//      * `reflection { ... metallic k }` tints the amount by 1 + k (1 - F) (pigment - 1),
//        F as above of acos(cos);
//      * the colour gets + amount * colour(reflected ray), the reflected ray starting at P
//        in direction D - 2 (D . N) N, inside the same interiors as the incoming ray;
//        where a normal pattern tilted N so far that this direction goes below the
//        surface's own normal R (facing the ray), POV-Ray's correction: mirrored at R
//        instead when it also goes against N, else mirrored once more at R. A transmitted
//        ray is refracted at N turned towards the ray, should the pattern have tilted it
//        away (ComputeRefraction).
//  - The ray tree (ray_tree.cpp, POV-Ray's TraceRay): every surface may spawn a reflected
//    and a transmitted ray (transparency.h has filter, transmit, refraction, fade and
//    filtered shadows). A ray whose weight is below adc_bailout (settings, default 1/255)
//    or whose parent is at max_trace_level (settings, default 5: the camera ray is level 1)
//    is black; a ray continued straight through a surface between equal iors keeps its
//    parent's level (POV-Ray's continued ray), and beyond 512 such rays on one path of the
//    tree is black too (a bound on the recursion that POV-Ray does not have; only rays
//    through hundreds of fully transparent walls reach it).
//  - Materials: POV-Ray's defaults for items left out (graph.h's Material), colour <1,1,1>
//    for the default material.
//  - Output: linear colours; images are encoded as sRGB (render.h) as POV-Ray 3.7 does with
//    assumed_gamma 1.0.
#pragma once

#include <cstdint>

#include "camera.h"
#include "graph.h"
#include "transparency.h"
#include "traversal.h"

namespace pcsg::tracer {

struct ShadingConstants {
    static constexpr double kMinIsectDepth = 1e-4;
    static constexpr double kMaxDistance = 1e7;
    static constexpr double kShadowTolerance = 1e-3;
    static constexpr double kEpsilon = 1e-10;
    static constexpr double kAdcBailout = 1.0 / 255.0;
    static constexpr int kMaxTraceLevel = 5;
    static constexpr double kAmbientLight = 1.0;
};

// How much a surface reflects at an angle of incidence with cosine `cosIncidence`: the
// colour that multiplies the reflected ray's, and the factor of the ray's weight.
struct Reflectivity {
    Vec3 colour{0, 0, 0};
    double weight = 0;
};
// `relativeIor`: n2 / n1 at the surface, which fresnel reflection reads.
Reflectivity reflectivity(const Material& m, double cosIncidence, const Vec3& pigment,
                          double relativeIor);
// A ray coming from the atmosphere (relative ior: the material's).
inline Reflectivity reflectivity(const Material& m, double cosIncidence, const Vec3& pigment) {
    return reflectivity(m, cosIncidence, pigment, m.ior);
}

// The colour seen along one ray, per thread (it owns a Tracer).
class Shader {
  public:
    explicit Shader(const TraceScene& scene);

    // The linear RGB colour of a camera ray (world space, unit direction).
    Vec3 shade(const Ray& ray);

    // Rays traced so far: camera, shadow, reflected and transmitted rays.
    uint64_t rays() const { return rays_; }
    uint64_t nodeVisits() const { return tracer_.nodeVisits(); }
    Tracer& tracer() { return tracer_; }

  private:
    // A ray of the tree (ray_tree.cpp): unit direction, POV-Ray's trace level of its parent
    // (the camera ray: 0) and the interiors it travels in.
    struct TreeRay {
        Vec3 origin, dir;
        int level = 0;
        Interiors inside;
        int straight = 0;  // rays continued straight on along its path (at most kMaxStraight)
    };
    // A bound on the C++ recursion of rays continued straight through surfaces (which do
    // not count trace levels): past it a ray is black, as one past max_trace_level.
    static constexpr int kMaxStraight = 512;
    struct Surface;  // a hit being shaded (ray_tree.cpp)
    Vec3 trace(const TreeRay& ray, double weight, bool continued);
    Vec3 shadeHit(const TreeRay& ray, const SurfaceHit& hit, double weight, bool continued);
    Vec3 shadeSurface(const Surface& s, double weight);
    Vec3 transmitted(const Surface& s, double weight, bool& totalReflection);
    Vec3 reflected(const Surface& s, double weight);
    // What reaches p from a light at distance `dist` in direction l through the surfaces
    // between: white when nothing is in the way, black when an opaque surface is.
    Vec3 shadowFilter(const Vec3& p, const Vec3& l, double dist, const Interiors& inside);
    // The interiors of the solids that contain point `at` (POV-Ray's InitRayContainerState
    // for camera rays), innermost last; remembered for the last point asked about.
    const Interiors& startInteriors(const Vec3& at);

    // The local colour of a surface point (ambient, diffuse, phong; no reflection), whose
    // pigment there has colour `pigment` and opacity `opacity` (1 - filter - transmit),
    // seen by a ray inside `inside`.
    Vec3 local(const Vec3& p, const Vec3& n, const Vec3& d, const Material& m, const Vec3& pigment,
               double opacity, const Interiors& inside);
    // Diffuse, phong and specular of one light in direction l, of colour lightColour where
    // it arrives.
    Vec3 lit(const Vec3& n, const Vec3& d, const Vec3& l, const Vec3& lightColour,
             const Material& m, const Vec3& pigment, double opacity, bool highlights = true) const;

    const Graph& g_;
    Tracer tracer_;
    uint64_t rays_ = 0;
    bool anyTransparent_ = false;  // transparency.h: else shadow rays stop at any surface
    bool startKnown_ = false;      // startInteriors' memory
    Vec3 startAt_;
    Interiors startInside_;
};

}  // namespace pcsg::tracer
