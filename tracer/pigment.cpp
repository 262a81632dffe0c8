#include "pigment.h"

namespace pcsg::tracer {

FilterColour pigmentColour(const Material& m, const SurfaceHit& /*hit*/) {
    return FilterColour{m.color, m.filter, m.transmit};
}

}  // namespace pcsg::tracer
