// POV-Ray 3.7's solid noise, exactly: the default generator (`noise_generator 2`, the
// range-corrected Perlin-style noise of source/core/material/noise.cpp), its gradient
// DNoise, and the classic turbulence built from them (octaves, omega, lambda).
//
// The hash table and the random tables are generated the way POV-Ray generates them (its
// own linear congruential generator, seeded as POV-Ray seeds it), once, in a thread-safe
// static initialiser; evaluation only reads them, so any thread may call these functions.
#pragma once

#include "geometry.h"
#include "texture.h"

namespace pcsg {

// POV-Ray's Noise(EPoint, noise_generator 2): a smooth pseudo-random value in [0, 1],
// 0.5 on average, the same at the same point in both renderers.
double noise(const Vec3& p);

// POV-Ray's DNoise: a smooth pseudo-random vector, each component roughly in [-1, 1]
// (the noise's gradient-like companion used by turbulence warps and normal patterns).
Vec3 dnoise(const Vec3& p);

// POV-Ray's Turbulence(EPoint, turb): the sum over t.octaves of
// |noise(lambda^i p) * 2 - 1| * omega^i (as POV-Ray computes it), >= 0. t.amount is not
// used here: callers scale by it as POV-Ray does.
double turbulence(const Vec3& p, const Turbulence& t);

// POV-Ray's DTurbulence(result, EPoint, turb): the sum over t.octaves of
// dnoise(lambda^i p) * omega^i. t.amount is not used here.
Vec3 dturbulence(const Vec3& p, const Turbulence& t);

// POV-Ray's wave sources, for the ripples and waves normals: with the default
// `global_settings { number_of_waves 10 }`, source i is normalize(dnoise(<i, 0, 0>)) and its
// frequency 0.01 + d * 0.000030518509476, d the i-th 15-bit draw ((r >> 16) & 0x7FFF) of the
// generator r = r * 1812433253 + 12345 started at r = -560851967 (texture.cpp,
// Initialize_Waves).
struct NoiseWaves {
    static constexpr int kCount = 10;
    Vec3 source[kCount];
    double frequency[kCount];
};
const NoiseWaves& noiseWaves();

}  // namespace pcsg
