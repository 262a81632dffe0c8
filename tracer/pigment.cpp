#include "pigment.h"

#include "colour_map.h"
#include "pattern.h"

namespace pcsg::tracer {

FilterColour pigmentAt(const Pigment& p, const Vec3& point) {
    const double v = patternValue(p.pattern, point);
    if (isListPattern(p.pattern.kind)) return listColour(p, v);
    return colourMapLookup(p.hasColourMap() ? p.colourMap : defaultColourMap(p.pattern.kind), v);
}

FilterColour pigmentColour(const Material& m, const SurfaceHit& hit) {
    if (m.pigment.pattern.kind == PatternKind::Plain || !hit.painted)
        return FilterColour{m.color, m.filter, m.transmit};
    return pigmentAt(m.pigment, hit.paintPoint);
}

}  // namespace pcsg::tracer
