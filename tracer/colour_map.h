// Colour maps (docs/language.md section 10) as POV-Ray 3.7 reads them
// (source/core/material/blendmap.cpp, BlendMap::Search, and pigment.cpp): the value picks
// the two entries around it and the colour is their linear interpolation, filter and
// transmit too; below the first entry the first colour, from the last entry on the last
// colour, and on an entry's value that entry's colour (so equal values make a sharp edge).
#pragma once

#include <vector>

#include "texture.h"

namespace pcsg::tracer {

FilterColour colourMapLookup(const std::vector<ColourMapEntry>& map, double value);

// POV-Ray's colour map for a pattern without one (pattern.cpp's default blend maps); for
// checker, brick and hexagon the default list colours, by index.
const std::vector<ColourMapEntry>& defaultColourMap(PatternKind k);

// A list pattern's colour for its index: the pigment's list, else the default list.
FilterColour listColour(const Pigment& p, double index);

}  // namespace pcsg::tracer
