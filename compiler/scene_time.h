// Setting the time of a frame (docs/language.md section 11): `clock` and `frame` read
// Graph::time, and the directive values that read them (Graph::timedValues) are evaluated
// into Graph::scene and Graph::materials. Every command that renders or exports a frame
// calls setTime() first, a still included (clock 0, frame 1).
#pragma once

#include <string>

#include "graph.h"

namespace pcsg {

// Sets g.time and evaluates the timed directive values at it. Throws RuntimeError (naming
// the clock and the frame) when a value is not finite, the camera angle is out of range,
// or the camera cannot see (location at look_at, sky zero or along the view) at that time.
void setTime(Graph& g, Time t);

// "clock 0.25, frame 3": for messages.
std::string describeTime(const Time& t);

}  // namespace pcsg
