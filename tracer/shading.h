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
//  - For each point light at position Lp with colour Lc, L = normalize(Lp - P):
//      * skipped if N . L < EPSILON (1e-10): the light is behind the surface;
//      * hard shadow: a shadow ray from P toward the light; blocked by any surface with
//        SHADOW_TOLERANCE (1e-3) < t < |Lp - P| - SHADOW_TOLERANCE;
//      * diffuse: Lc * pigment * diffuse * |N . L| (brilliance 1);
//      * phong: with R = D - 2 (D . N) N the mirrored view direction, if R . L > 0:
//        Lc * phong * (R . L)^phong_size (highlight in the light's colour, not metallic).
//    No light attenuation with distance (POV-Ray's default fade_power 0).
//  - Reflection `reflection r` (POV-Ray's `reflection r` sets min = max = r, falloff 1, no
//    fresnel): the colour gets + r * colour(reflected ray), the reflected ray starting at
//    P in direction D - 2 (D . N) N. The ray's weight (1 for camera rays) is multiplied by
//    r; a ray whose weight drops below adc_bailout (1/255) is not traced, and neither is
//    a ray beyond max_trace_level (5: the camera ray and at most four reflections).
//    Since reflection is linear, the tracer follows the chain of reflections in a loop.
//  - Materials: POV-Ray's defaults for items left out (ambient 0.1, diffuse 0.6, phong 0,
//    phong_size 40, reflection 0; graph.h's Material), colour <1,1,1> for the default
//    material.
//  - Output: linear colours; images are encoded as sRGB (render.h) as POV-Ray 3.7 does with
//    assumed_gamma 1.0.
#pragma once

#include <cstdint>

#include "camera.h"
#include "graph.h"
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

// The colour seen along one ray, per thread (it owns a Tracer).
class Shader {
  public:
    explicit Shader(const TraceScene& scene);

    // The linear RGB colour of a camera ray (world space, unit direction).
    Vec3 shade(const Ray& ray);

    // Rays traced so far: camera, shadow and reflection rays.
    uint64_t rays() const { return rays_; }
    uint64_t nodeVisits() const { return tracer_.nodeVisits(); }
    Tracer& tracer() { return tracer_; }

  private:
    // The local colour of a surface point (ambient, diffuse, phong; no reflection).
    Vec3 local(const Vec3& p, const Vec3& n, const Vec3& d, const Material& m);

    const Graph& g_;
    Tracer tracer_;
    uint64_t rays_ = 0;
};

}  // namespace pcsg::tracer
