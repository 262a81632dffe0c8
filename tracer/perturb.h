// A material's normal { } pattern at a hit (docs/language.md section 10), in POV-Ray 3.7's
// order (trace.cpp and normal.cpp): the surface normal, already turned to face the ray, is
// taken into the paint node's frame and into pattern space (Warp_Normal: by the transpose
// of each map back to the world, normalised), perturbed there at the hit's pattern-space
// point (normal_patterns.h), and brought back by the inverse maps (UnWarp_Normal) and
// normalised. POV-Ray does not turn the perturbed normal towards the ray again.
#pragma once

#include "graph.h"
#include "traversal.h"

namespace pcsg::tracer {

// The perturbed normal (unit length) for facing normal `n` (unit length). The hit must be
// painted with its paint frame's map (SurfaceHit::paintMap), and no other ray may have
// been traced by that tracer since: shading perturbs right after the hit.
Vec3 perturbedNormal(const NormalSpec& spec, const SurfaceHit& hit, const Vec3& n);

}  // namespace pcsg::tracer
