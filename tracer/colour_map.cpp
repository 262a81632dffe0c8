#include "colour_map.h"

#include <array>

namespace pcsg::tracer {

namespace {

FilterColour mix(const FilterColour& a, double wa, const FilterColour& b, double wb) {
    return FilterColour{a.rgb * wa + b.rgb * wb, a.filter * wa + b.filter * wb,
                        a.transmit * wa + b.transmit * wb};
}

ColourMapEntry entry(double v, double r, double g, double b) {
    return ColourMapEntry{v, FilterColour{Vec3{r, g, b}}};
}

}  // namespace

FilterColour colourMapLookup(const std::vector<ColourMapEntry>& map, double value) {
    if (map.empty()) return FilterColour{};
    if (value >= map.back().value) return map.back().colour;
    size_t next = 0;
    while (value > map[next].value) ++next;  // stops at the last entry at the latest
    if (next == 0 || value == map[next].value) return map[next].colour;
    const ColourMapEntry& lo = map[next - 1];
    const ColourMapEntry& hi = map[next];
    const double span = hi.value - lo.value;
    return mix(lo.colour, (hi.value - value) / span, hi.colour, (value - lo.value) / span);
}

const std::vector<ColourMapEntry>& defaultColourMap(PatternKind k) {
    static const std::vector<ColourMapEntry> grey = {entry(0, 0, 0, 0), entry(1, 1, 1, 1)};
    static const std::vector<ColourMapEntry> agate = {
        entry(0.0, 1.0, 1.0, 1.0), entry(0.5, 0.95, 0.75, 0.5), entry(0.5, 0.9, 0.7, 0.5),
        entry(0.6, 0.9, 0.7, 0.4), entry(0.6, 1.0, 0.7, 0.4),   entry(1.0, 0.6, 0.3, 0.0)};
    static const std::vector<ColourMapEntry> bozo = {entry(0.4, 1, 1, 1), entry(0.4, 0, 1, 0),
                                                     entry(0.6, 0, 1, 0), entry(0.6, 0, 0, 1),
                                                     entry(0.8, 0, 0, 1), entry(0.8, 1, 0, 0)};
    static const std::vector<ColourMapEntry> brick = {entry(0, 0.5, 0.5, 0.5),
                                                      entry(1, 0.6, 0.15, 0.15)};
    static const std::vector<ColourMapEntry> checker = {entry(0, 0, 0, 1), entry(1, 0, 1, 0)};
    static const std::vector<ColourMapEntry> hexagon = {entry(0, 0, 0, 1), entry(1, 0, 1, 0),
                                                        entry(2, 1, 0, 0)};
    static const std::vector<ColourMapEntry> marble = {
        entry(0.0, 0.9, 0.8, 0.8), entry(0.9, 0.9, 0.08, 0.08), entry(0.9, 0, 0, 0)};
    static const std::vector<ColourMapEntry> radial = {entry(0.0, 0, 1, 1), entry(0.333, 1, 1, 0),
                                                       entry(0.666, 1, 0, 1), entry(1.0, 0, 1, 1)};
    static const std::vector<ColourMapEntry> wood = {entry(0.6, 0.666, 0.312, 0.2),
                                                     entry(0.6, 0.4, 0.1333, 0.066)};
    switch (k) {
        case PatternKind::Agate:
            return agate;
        case PatternKind::Bozo:
            return bozo;
        case PatternKind::Brick:
            return brick;
        case PatternKind::Checker:
            return checker;
        case PatternKind::Hexagon:
            return hexagon;
        case PatternKind::Marble:
            return marble;
        case PatternKind::Radial:
            return radial;
        case PatternKind::Wood:
            return wood;
        default:
            return grey;
    }
}

FilterColour listColour(const Pigment& p, double index) {
    const auto i = static_cast<size_t>(index);
    if (i < p.listColours.size()) return p.listColours[i];
    const auto& d = defaultColourMap(p.pattern.kind);
    return d[i < d.size() ? i : d.size() - 1].colour;
}

}  // namespace pcsg::tracer
