// Section 10's appearance items for the fuzz generator: see appearance.h.
#include "appearance.h"

#include <fmt/format.h>

#include <cstdint>

namespace pcsg::fuzz {

namespace {

std::string n(Rng& rng, int64_t lo, int64_t hi) {
    return milli(rng.range(lo, hi));
}
std::string vec(Rng& rng, int64_t lo, int64_t hi) {
    return fmt::format("<{}, {}, {}>", n(rng, lo, hi), n(rng, lo, hi), n(rng, lo, hi));
}
std::string fixed(double v) {
    return milli(static_cast<int64_t>(v * 1000 + (v < 0 ? -0.5 : 0.5)));
}

// A pigment colour: opaque, or (transparent) with a filter, a transmit or both, which
// together let at most 0.9 through.
std::string colour(Rng& rng, bool transparent) {
    if (!transparent) return "rgb " + vec(rng, 50, 1000);
    const std::string rgb =
        fmt::format("{}, {}, {}", n(rng, 300, 1000), n(rng, 300, 1000), n(rng, 300, 1000));
    switch (rng.below(3)) {
        case 0:
            return fmt::format("rgbf <{}, {}>", rgb, n(rng, 300, 900));
        case 1:
            return fmt::format("rgbt <{}, {}>", rgb, n(rng, 300, 900));
        default:
            return fmt::format("rgbft <{}, {}, {}>", rgb, n(rng, 200, 450), n(rng, 200, 450));
    }
}

// color_map { [v color c] ... } with 2 to 4 entries in increasing order.
std::string colourMap(Rng& rng, bool transparent) {
    const int count = int(rng.range(2, 4));
    std::string s = "color_map {";
    int64_t v = rng.range(0, 200);
    for (int k = 0; k < count; ++k) {
        s += fmt::format(" [{} color {}]", milli(v), colour(rng, transparent && rng.percent(60)));
        v = std::min<int64_t>(1000, v + rng.range(150, 500));
    }
    return s + " }";
}

// A pattern's own transformation: a scale of 0.2 to 0.9, sometimes a rotation and a
// translation.
std::string patternTransform(Rng& rng) {
    std::string s = rng.percent(70) ? fmt::format(" scale {}", n(rng, 200, 900))
                                    : fmt::format(" scale {}", vec(rng, 250, 900));
    if (rng.percent(40)) s += fmt::format(" rotate {}", vec(rng, -90000, 90000));
    if (rng.percent(40)) s += fmt::format(" translate {}", vec(rng, -500, 500));
    return s;
}

// frequency, phase (colour-map patterns only) and turbulence.
std::string waveModifiers(Rng& rng, bool mapped) {
    std::string s;
    if (mapped && rng.percent(35)) s += fmt::format(" frequency {}", n(rng, 1000, 3000));
    if (mapped && rng.percent(30)) s += fmt::format(" phase {}", n(rng, 0, 1000));
    if (rng.percent(30)) {
        s += rng.percent(70) ? fmt::format(" turbulence {}", n(rng, 50, 600))
                             : fmt::format(" turbulence {}", vec(rng, 50, 500));
        if (rng.percent(30)) s += fmt::format(" octaves {}", rng.range(2, 6));
    }
    return s;
}

// The pattern word with what belongs right after it; `mapped`: it takes a colour map.
std::string patternWord(Rng& rng, bool transparent, bool& mapped) {
    static const char* const noise[] = {"leopard", "bozo",  "spotted",  "granite", "wood",
                                        "marble",  "agate", "wrinkles", "dents",   "onion"};
    mapped = true;
    const uint64_t k = rng.below(15);
    switch (k) {
        case 0:
            mapped = false;
            return fmt::format("checker color {} color {}", colour(rng, transparent),
                               colour(rng, false));
        case 1:
            mapped = false;
            return fmt::format("brick color {} color {} brick_size {} mortar {}",
                               colour(rng, false), colour(rng, transparent), vec(rng, 200, 600),
                               n(rng, 10, 50));
        case 2:
            mapped = false;
            return fmt::format("hexagon color {} color {} color {}", colour(rng, transparent),
                               colour(rng, false), colour(rng, false));
        case 3: {
            static const char* const axes[] = {"x", "y", "z"};
            return rng.percent(70) ? fmt::format("gradient {}", axes[rng.below(3)])
                                   : fmt::format("gradient {}", vec(rng, -1000, 1000));
        }
        case 4:
            return fmt::format("radial frequency {}", rng.range(2, 8));
        default:
            return noise[k - 5];
    }
}

std::string pigmentBlock(Rng& rng, bool transparent) {
    if (rng.percent(transparent ? 50 : 25))
        return fmt::format("pigment {{ color {} }}", colour(rng, transparent));
    bool mapped = true;
    std::string s = "pigment { " + patternWord(rng, transparent, mapped);
    // Every map pattern but spotted has a colour map (POV-Ray's default maps of the noise
    // patterns are checked too, where none is given).
    if (mapped && (rng.percent(80) || transparent)) s += " " + colourMap(rng, transparent);
    s += waveModifiers(rng, mapped);
    if (rng.percent(85)) s += patternTransform(rng);
    return s + " }";
}

std::string normalBlock(Rng& rng) {
    static const char* const kinds[] = {"bumps", "dents", "wrinkles", "ripples", "waves"};
    const uint64_t k = rng.below(5);
    std::string s = fmt::format("normal {{ {} {}", kinds[k], n(rng, 100, 800));
    if (k >= 3 && rng.percent(60)) s += fmt::format(" frequency {}", n(rng, 1000, 4000));
    if (k >= 3 && rng.percent(40)) s += fmt::format(" phase {}", n(rng, 0, 1000));
    if (rng.percent(25)) s += fmt::format(" turbulence {}", n(rng, 50, 400));
    return s + patternTransform(rng) + " }";
}

// finish { ... }; `fresnel`: it has a fresnel reflection (which reads the interior's ior).
std::string finishBlock(Rng& rng, bool transparent, bool& fresnel) {
    std::string s = fmt::format("finish {{ ambient {} diffuse {}", n(rng, 0, 250),
                                transparent ? n(rng, 0, 300) : n(rng, 300, 900));
    if (rng.percent(30)) s += fmt::format(" brilliance {}", n(rng, 500, 4000));
    if (rng.percent(40))
        s += fmt::format(" phong {} phong_size {}", n(rng, 0, 900), n(rng, 5000, 80000));
    if (rng.percent(35))
        s += fmt::format(" specular {} roughness {}", n(rng, 100, 900), n(rng, 5, 100));
    if (rng.percent(20)) s += rng.percent(50) ? " metallic" : " metallic " + n(rng, 200, 1000);
    fresnel = false;
    if (rng.percent(40)) {
        fresnel = rng.percent(50);
        s += fmt::format(" reflection {{ {}, {}{}", n(rng, 0, 150), n(rng, 200, 800),
                         fresnel ? " fresnel on" : "");
        if (rng.percent(20)) s += " metallic";
        s += " }";
    }
    if (rng.percent(transparent ? 40 : 10)) s += " conserve_energy";
    return s + " }";
}

std::string interiorBlock(Rng& rng) {
    std::string s = fmt::format("interior {{ ior {}", n(rng, 1000, 1600));
    if (rng.percent(35)) {
        s += fmt::format(" fade_distance {} fade_power {}", n(rng, 300, 3000),
                         rng.percent(30) ? "1001" : n(rng, 1000, 3000));
        if (rng.percent(60)) s += " fade_color " + vec(rng, 200, 1000);
    }
    return s + " }";
}

// Section 7's flat items (the generator's materials before section 10).
std::string flatBody(Rng& rng) {
    std::string s = fmt::format("color {}  ambient {}  diffuse {}", vec(rng, 150, 1000),
                                n(rng, 0, 300), n(rng, 300, 900));
    if (rng.percent(50))
        s += fmt::format("  phong {}  phong_size {}", n(rng, 0, 900), n(rng, 5000, 80000));
    if (rng.percent(25)) s += fmt::format("  reflection {}", n(rng, 50, 400));
    return s;
}

}  // namespace

std::string materialBody(Rng& rng) {
    if (rng.percent(40)) return flatBody(rng);
    const bool transparent = rng.percent(35);
    std::string s = pigmentBlock(rng, transparent);
    if (rng.percent(40)) s += " " + normalBlock(rng);
    bool fresnel = false;
    s += " " + finishBlock(rng, transparent, fresnel);
    if (transparent || fresnel || rng.percent(10)) s += " " + interiorBlock(rng);
    return s;
}

std::string lightExtras(Rng& rng, double radius, const std::string& lookAt) {
    const uint64_t kind = rng.below(100);
    if (kind < 15) {  // an area light, never jittered
        const double a = radius * double(rng.range(300, 1500)) / 1000;
        const double b = radius * double(rng.range(300, 1500)) / 1000;
        std::string s =
            fmt::format("  area_light <{}, 0, 0>, <0, {}, 0>, {}, {}  adaptive {}", fixed(a),
                        fixed(b), rng.range(2, 4), rng.range(2, 4), rng.range(0, 1));
        if (rng.percent(20)) s += "  circular";
        return s;
    }
    if (kind < 30) {
        const int64_t radiusDeg = rng.range(8000, 25000);
        return fmt::format("  spotlight  point_at {}  radius {}  falloff {}  tightness {}", lookAt,
                           milli(radiusDeg), milli(radiusDeg + rng.range(2000, 20000)),
                           n(rng, 0, 20000));
    }
    return "";
}

std::string sceneExtras(Rng& rng, double radius, double groundZ) {
    std::string s;
    if (rng.percent(15)) {
        s += fmt::format("fog {{ distance {}  color {}",
                         fixed(radius * rng.range(1500, 8000) / 1000), vec(rng, 200, 900));
        if (rng.percent(30)) s += fmt::format("  filter {}", n(rng, 0, 500));
        if (rng.percent(30)) s += fmt::format("  transmit {}", n(rng, 0, 400));
        if (rng.percent(30))
            s += fmt::format("  fog_type 2  fog_offset {}  fog_alt {}",
                             fixed(groundZ + radius * rng.range(200, 1200) / 1000),
                             fixed(radius * rng.range(100, 800) / 1000));
        s += " }\n";
    }
    if (rng.percent(15)) {
        std::string map = "color_map {";
        int64_t v = 0;
        for (int k = 0; k < 3; ++k, v += rng.range(200, 500))
            map +=
                fmt::format(" [{} rgb {}]", milli(std::min<int64_t>(v, 1000)), vec(rng, 0, 1000));
        map += " }";
        s += rng.percent(70) ? fmt::format("sky_sphere {{ pigment {{ gradient z {} }} }}\n", map)
                             : fmt::format("sky_sphere {{ pigment {{ bozo {} scale {} }} }}\n", map,
                                           n(rng, 300, 800));
    }
    return s;
}

}  // namespace pcsg::fuzz
