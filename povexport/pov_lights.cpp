#include "pov_lights.h"

#include <fmt/format.h>

namespace pcsg {

namespace {

// Shortest text that reads back as the same double.
std::string num(double v) {
    if (v == 0) v = 0;  // no "-0"
    return fmt::format("{}", v);
}

std::string vec(const Vec3& v) {
    return fmt::format("<{},{},{}>", num(v.x), num(v.y), num(v.z));
}

}  // namespace

std::string povLight(const Light& l) {
    std::string s = fmt::format("light_source {{ {} color rgb {}", vec(l.position), vec(l.color));
    if (l.spotlight)
        s += fmt::format(" spotlight point_at {} radius {} falloff {} tightness {}",
                         vec(l.pointAt), num(l.radius), num(l.falloff), num(l.tightness));
    if (l.shadowless) s += " shadowless";
    if (l.fadePower > 0)
        s += fmt::format(" fade_distance {} fade_power {}", num(l.fadeDistance), num(l.fadePower));
    if (l.areaLight()) {
        s += fmt::format(" area_light {}, {}, {}, {} adaptive {}", vec(l.axis1), vec(l.axis2),
                         l.size1, l.size2, l.adaptive);
        if (l.jitter) s += " jitter";
        if (l.circular) s += " circular";
        if (l.orient) s += " orient";
    }
    return s + " }";
}

std::string povFog(const Fog& f) {
    if (!f.enabled) return {};
    std::string s =
        fmt::format("fog {{ fog_type {} distance {} color rgbft <{},{},{},{},{}>", f.type,
                    num(f.distance), num(f.color.x), num(f.color.y), num(f.color.z),
                    num(f.filter), num(f.transmit));
    if (f.type == 2)
        s += fmt::format(" fog_offset {} fog_alt {} up z", num(f.offset), num(f.alt));
    return s + " }";
}

}  // namespace pcsg
