// Which language features a scene uses, read from its syntax tree: `pcsg fuzz --json`'s
// coverage counts (docs/fuzz.md).
#pragma once

#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace pcsg::fuzz {

// The feature names, in the order the coverage lists them.
const std::vector<std::string>& featureNames();

// The features of featureNames() that the scene's text uses (nothing when it does not
// parse): select (a notation-A selection function), transform, calc (a C-node), paint,
// union, intersection, difference, each primitive (tri1, tri2 and triangle() count as
// triangle), notation_b (a notation-B rule or axiom), rand (rand() or rand(x)), choose;
// and section 10's items, read from the tokens: each pigment pattern (pigment_checker ...
// pigment_dents; spotted counts as pigment_bozo), color_map, frequency, phase,
// turbulence, pattern_transform (scale, rotate or translate in a pigment or normal), each
// normal pattern (normal_bumps ... normal_waves), brilliance, specular, metallic,
// fresnel, conserve_energy, filter (rgbf, rgbft), transmit (rgbt, rgbft), ior, fade
// (fade_distance), area_light, spotlight, fog, sky_sphere.
std::set<std::string> featuresOf(std::string_view text);

}  // namespace pcsg::fuzz
