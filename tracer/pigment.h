// A pigment's colour at a surface point (docs/language.md section 10): the material's plain
// colour, or its pattern evaluated at the hit point in the frame of the paint node that
// applied the material (SurfaceHit::paintPoint).
#pragma once

#include "graph.h"
#include "traversal.h"

namespace pcsg::tracer {

FilterColour pigmentColour(const Material& m, const SurfaceHit& hit);

// What a ray that meets nothing sees: the sky_sphere's pigment at its direction (scene
// coordinates, normalised), else the background.
Vec3 skyColour(const Scene& scene, const Vec3& dir);

// A pigment with a pattern at a point in its paint node's frame (also the sky_sphere's,
// at a direction).
FilterColour pigmentAt(const Pigment& p, const Vec3& point);

}  // namespace pcsg::tracer
