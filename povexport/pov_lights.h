// POV-Ray 3.7 text for the scene's lights and fog (docs/language.md sections 7 and 10).
#pragma once

#include <string>

#include "graph.h"

namespace pcsg {

// `light_source { <position> color rgb <c> ... }` with its spotlight, area_light, fading
// and shadowless items, in POV-Ray's order (spotlight before its parameters).
std::string povLight(const Light& light);

// `fog { fog_type T distance D color rgbft <...> [fog_offset O fog_alt A up z] }`, or ""
// when the scene has no fog.
std::string povFog(const Fog& fog);

}  // namespace pcsg
