// POV-Ray 3.7's special normal patterns (source/core/material/normal.cpp): bumps, dents,
// wrinkles, ripples and waves, with bump_size (NormalSpec::amount), frequency, phase and
// turbulence, and, for ripples and waves, POV-Ray's wave sources generated as POV-Ray
// generates them.
#pragma once

#include "geometry.h"
#include "texture.h"

namespace pcsg {

// The perturbed normal at a pattern-space point, for a pattern-space normal, exactly as
// POV-Ray's Perturb_Normal computes it for these patterns AFTER its Warp_EPoint of the
// point (the caller applies the pattern's transformations; turbulence is applied here).
// Details of normalisation and of what the caller does with the transformation are in
// the comment of normal_patterns.cpp and will be stated here once final.
Vec3 perturbNormal(const NormalSpec& spec, const Vec3& patternPoint, const Vec3& normal);

}  // namespace pcsg
