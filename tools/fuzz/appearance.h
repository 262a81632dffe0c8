// The appearance items of docs/language.md section 10 for `pcsg fuzz`'s systems: pigment
// patterns with their colour maps and modifiers, normal patterns, finish items,
// transparency and interiors in materials; area lights and spotlights; fog and
// sky_sphere. Drawn from the generator's own Rng, so a seed gives the same text
// everywhere (generator.h).
//
// Scales stay moderate (patterns of 0.2 to 0.9 units in their paint node's frame, a
// turbulence of at most 0.6, normal amounts of at most 0.8), so that a pattern does not
// alias at 80x60 into something that a last-bit difference in a hit point would change,
// and nothing is jittered (a jittered area light is not reproducible).
#pragma once

#include <string>

#include "generator.h"

namespace pcsg::fuzz {

// The body of material `name`'s braces: section 7's flat items, or, sometimes, blocks
// with section 10's items.
std::string materialBody(Rng& rng);

// What follows a light's position and colour: nothing, or sometimes an area light (sizes
// from the object's radius) or a spotlight pointed at `lookAt` (written with three
// decimals).
std::string lightExtras(Rng& rng, double radius, const std::string& lookAt);

// Scene statements: sometimes a fog (its distance from the object's radius; ground fog at
// `groundZ`) and sometimes a sky_sphere.
std::string sceneExtras(Rng& rng, double radius, double groundZ);

}  // namespace pcsg::fuzz
