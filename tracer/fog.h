// fog { } (docs/language.md section 10): POV-Ray 3.7's constant and ground fog
// (source/backend/render/trace.cpp: ComputeFog, ComputeConstantFogDepth,
// ComputeGroundFogDepth), applied to every ray's colour, the camera's and the reflected
// ones, over the ray's length (2e10, POV-Ray's BOUND_HUGE, for a ray that hits nothing);
// not to shadow rays.
//
//  - Constant fog (type 1): the share of the colour behind that gets through is
//    a = exp(-depth / distance).
//  - Ground fog (type 2): the density is 1 below `fog_offset` and 1 / (1 + h^2) above it,
//    h the height above fog_offset in units of `fog_alt`, height measured along z (our up;
//    the exporter writes `up z`). With s and e the heights of the ray's start and end,
//    the mean density m is 1 when both are <= 0; (atan e - s) / (e - s) when only s is
//    (and the mirror case); (atan s - atan e) / (s - e) when both are above, or 1 / (1 + s^2)
//    when |s - e| <= 1e-10. a = exp(-depth m / distance).
//  - With the fog's colour C, filter f and transmit t: a is at least t; the colour seen is
//    (1 - a) C + a ((1 - f) + f C) x the colour behind.
#pragma once

#include "graph.h"

namespace pcsg::tracer {

// The fog along a ray: the colour seen is `add` + `attenuation` x the colour behind.
struct FogEffect {
    Vec3 add{0, 0, 0};
    Vec3 attenuation{1, 1, 1};
};

inline constexpr double kFogMissDepth = 2.0e10;  // POV-Ray's BOUND_HUGE

// The share of light a fog lets through along a ray from `origin` in unit direction `dir`
// over `depth` (before the minimum of transmit).
double fogTransmittance(const Fog& fog, const Vec3& origin, const Vec3& dir, double depth);

FogEffect fogAlong(const Fog& fog, const Vec3& origin, const Vec3& dir, double depth);

}  // namespace pcsg::tracer
