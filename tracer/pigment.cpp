#include "pigment.h"

#include "colour_map.h"
#include "pattern.h"

namespace pcsg::tracer {

FilterColour pigmentAt(const Pigment& p, const Vec3& point) {
    const double v = patternValue(p.pattern, point);
    if (isListPattern(p.pattern.kind)) return listColour(p, v);
    if (p.hasColourMap()) return colourMapLookup(p.colourMap, v);
    const PatternKind mapOf = p.pattern.spotted ? PatternKind::Gradient : p.pattern.kind;
    return colourMapLookup(defaultColourMap(mapOf), v);  // spotted: the grey map
}

Vec3 skyColour(const Scene& scene, const Vec3& dir) {
    if (!scene.skySphere) return scene.background;
    if (scene.skyPigment.pattern.kind == PatternKind::Plain) return scene.skyColour.rgb;
    return pigmentAt(scene.skyPigment, normalize(dir)).rgb;
}

FilterColour pigmentColour(const Material& m, const SurfaceHit& hit) {
    if (m.pigment.pattern.kind == PatternKind::Plain || !hit.painted)
        return FilterColour{m.color, m.filter, m.transmit};
    return pigmentAt(m.pigment, hit.paintPoint);
}

}  // namespace pcsg::tracer
