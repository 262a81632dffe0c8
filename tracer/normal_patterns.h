// POV-Ray 3.7's special normal patterns (source/backend/texture/normal.cpp: bumps, dents,
// wrinkles, ripples, waves; Perturb_Normal; warps.cpp Warp_Normal, UnWarp_Normal), with
// bump_size (NormalSpec::amount), frequency, phase and turbulence, and for ripples and
// waves POV-Ray's wave sources (noise.h noiseWaves()).
//
// What the shading code does with them, in POV-Ray's order (trace.cpp
// ComputeTextureColour and ComputeLightedTexture, normal.cpp Perturb_Normal); checked
// against povray renders in tracer/noise_povray_test.cpp:
//
//   1. Start from the surface's geometric normal already turned towards the ray (POV-Ray
//      flips its raw normal, "if the surface normal points away, flip its direction",
//      BEFORE texturing; a plane seen from behind is perturbed about the flipped normal).
//   2. Warp_Normal: n = normalize(n); with a transformed pattern,
//      n = normalize(M^T n), M = the map from pattern space to the frame the point is in
//      (PatternSpec::fromPattern composed with the paint frame), M^T its linear part
//      transposed.
//   3. Warp_EPoint: p = M^-1 (point): the point in pattern space. The turbulence is NOT
//      applied by the caller: perturbNormal does it (POV-Ray's classic warp, the last one).
//   4. r = perturbNormal(spec, p, n) (normalised).
//   5. UnWarp_Normal: with a transformed pattern, r = normalize((M^-1)^T r).
//   6. Use r for lighting and reflection as it is: POV-Ray does not flip the perturbed
//      normal again (it may face away from the ray at grazing angles; diffuse light then
//      skips it as for any N . L < 0). Refraction and the raw normal's other uses keep the
//      unperturbed normal of step 1 (trace.cpp passes both).
//
// perturbNormalThrough does 2 to 5 for a given pair of maps.
#pragma once

#include "geometry.h"
#include "texture.h"

namespace pcsg {

// The perturbed normal at a pattern-space point (after the pattern's transformations,
// before turbulence) for a unit pattern-space normal, exactly as POV-Ray's special normal
// patterns compute it, turbulence included; normalised. For NormalKind::None, n itself.
//  - bumps:    n + amount * dnoise(q)
//  - dents:    n + amount * noise(q)^3 * dnoise(q)
//  - wrinkles: n + amount * sum_{i<10} |dnoise(2^i q)| / 2^i (componentwise)
//  - ripples:  n + sum_i amount cycloidal(|d_i| f + phase) d_i / (|d_i| N)
//  - waves:    n + sum_i amount cycloidal(|d_i| f w_i + phase) / w_i d_i / (|d_i| N)
// with q the point moved by the turbulence warp, d_i = q - source_i, w_i the source's
// frequency, f the pattern's frequency, N = 10 sources. bumps, dents and wrinkles ignore
// frequency and phase, as POV-Ray does.
Vec3 perturbNormal(const NormalSpec& spec, const Vec3& patternPoint, const Vec3& normal);

// Steps 2 to 5 above: `point` and `normal` in the frame the maps start from (for
// example the paint frame), toPattern = M^-1 into pattern space, fromPattern = M back.
// `transformed` false skips the maps (POV-Ray then has no transform warp at all).
Vec3 perturbNormalThrough(const NormalSpec& spec, const Affine& toPattern,
                          const Affine& fromPattern, bool transformed, const Vec3& point,
                          const Vec3& normal);

}  // namespace pcsg
