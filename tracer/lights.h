// The light that reaches a surface point from one light { } (docs/language.md sections 7
// and 10): POV-Ray 3.7's point, spot, fill (shadowless) and area lights, with fading.
//
// POV-Ray 3.7 (source/backend/lighting/point.cpp: Attenuate_Light, cubic_spline;
// source/backend/render/trace.cpp: ComputeOneDiffuseLight, ComputeOneLightRay,
// TraceAreaLightShadowRay, TraceAreaLightSubsetShadowRay, ComputeOneWhiteLightRay):
//
//  - The light's direction L and distance d are those of its centre (`position`), also for
//    an area light: diffuse and highlights are computed once, from the centre.
//  - Colour = color x attenuation, the attenuation the product of
//      * a spotlight's: with c the cosine between the spot axis (position -> point_at) and
//        the direction from the light to the point, 0 when c <= 0, else c^tightness, times,
//        when cos(radius) > 0 and c < cos(radius), the cubic spline 3t^2 - 2t^3 of
//        t = (c - cos falloff) / (cos radius - cos falloff) (0 below cos falloff, 1 at or
//        above cos radius);
//      * fading, when fade_power > 0: 2 / (1 + (d / fade_distance)^fade_power), or
//        d^-fade_power when fade_distance is 0.
//    No light when every channel of that colour is below 1e-10, or when N . L < 1e-10.
//  - Shadows (not for shadowless lights, which POV-Ray calls fill lights): a point light's
//    shadow ray to the centre; an area light's shadow is the average of shadow rays to the
//    points of its size1 x size2 grid, centre + (u / (size1 - 1) - 1/2) axis1 +
//    (v / (size2 - 1) - 1/2) axis2, found by POV-Ray's recursion: a rectangle [u1, u2] x
//    [v1, v2] of grid indices (first the whole grid) samples its four corners (each grid
//    point traced once per lit point); when it is wider than 1 in u or v and its level
//    is below `adaptive` (default 100) or two neighbouring corners differ by more than
//    0.1 (sum of the channels' differences), it is split at floor/ceil of the midpoints
//    into four and its value is the mean of theirs; else the mean of its corners.
//    `circular` maps the grid's square shells onto circles, `orient` turns the axes to
//    face the lit point (both as POV-Ray does); `jitter` moves each sample by up to half a
//    cell with a fixed hash of the point (not POV-Ray's random numbers: such scenes are
//    left out of equivalence checks).
//  - Shadowless lights give diffuse light only: POV-Ray computes no highlights for them.
#pragma once

#include <cstdint>
#include <functional>

#include "graph.h"
#include "traversal.h"

namespace pcsg::tracer {

// POV-Ray's Attenuate_Light: the spotlight cone and the fading with distance, for the
// unit direction `toLight` from the point to the light and the distance d.
double spotAttenuation(const Light& light, const Vec3& toLight);
double fadeAttenuation(const Light& light, double d);

// POV-Ray's average over a size1 x size2 grid (see above): `sample(u, v)` is called at
// most once per grid point, and only where the recursion reaches it.
using AreaSample = std::function<Vec3(int u, int v)>;
Vec3 areaAverage(int size1, int size2, int adaptive, const AreaSample& sample);

// The offset from an area light's centre of its grid point (u, v) (fractional with
// jitter), along the axes given (the light's, or turned by `orient`).
Vec3 areaOffset(const Light& light, double u, double v, const Vec3& axis1, const Vec3& axis2);

// The axes an `orient` area light uses for a point whose direction to the light is `l`.
void orientAxes(const Light& light, const Vec3& l, Vec3& axis1, Vec3& axis2);

// The light arriving at p with normal n (facing the viewer): its direction (unit, toward
// the light's centre) and its colour after attenuation and shadows. False when none
// arrives. `rays` counts the shadow rays.
struct ArrivingLight {
    Vec3 dir{0, 0, 0};
    Vec3 colour{0, 0, 0};
    bool highlights = true;  // false for shadowless lights
};
bool lightArriving(const Light& light, const Vec3& p, const Vec3& n, Tracer& tracer,
                   uint64_t& rays, ArrivingLight& out);

}  // namespace pcsg::tracer
