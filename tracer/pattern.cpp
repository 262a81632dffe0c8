#include "pattern.h"

#include <array>
#include <cmath>
#include <numbers>

#include "noise_patterns.h"

namespace pcsg::tracer {

namespace {

constexpr double kEpsilon = 1e-10;  // POV-Ray's EPSILON

// POV-Ray's defaults per pattern kind (wave form, turbulence inside), read once.
const PatternDefaults& defaultsOf(PatternKind k) {
    static const auto table = [] {
        std::array<PatternDefaults, 15> t{};
        for (size_t i = 0; i < t.size(); ++i) t[i] = patternDefaults(static_cast<PatternKind>(i));
        return t;
    }();
    return table[static_cast<size_t>(k)];
}

// checker: the parity of the unit cube the point is in.
double checker(const Vec3& p) {
    const auto sum = static_cast<long long>(
        std::floor(p.x + kEpsilon) + std::floor(p.y + kEpsilon) + std::floor(p.z + kEpsilon));
    return (sum & 1) ? 1.0 : 0.0;
}

// The fraction of x after truncation, in [0, 1) (POV-Ray's (int) then +1 if negative).
double truncatedFraction(double x) {
    double f = x - std::trunc(x);
    if (f < 0) f += 1;
    return f;
}

// brick: 0 in the mortar, 1 in a brick; courses along y, alternate courses offset by half
// a brick in x and z (POV-Ray's brick_pattern).
double brick(const PatternSpec& s, const Vec3& p) {
    const double fudge = kEpsilon + s.mortar;
    const double x = p.x + fudge, y = p.y + fudge, z = p.z + fudge;
    const Vec3 size = s.brickSize;
    if (truncatedFraction(y / size.y) <= s.mortar / size.y) return 0;
    const bool upper = truncatedFraction(y / size.y * 0.5) > 0.5;
    const double mortarX = s.mortar / size.x, mortarZ = s.mortar / size.z;
    if (truncatedFraction(x / size.x) <= mortarX && !upper) return 0;
    if (truncatedFraction(x / size.x + 0.5) <= mortarX && upper) return 0;
    if (truncatedFraction(z / size.z) <= mortarZ && upper) return 0;
    if (truncatedFraction(z / size.z + 0.5) <= mortarZ && !upper) return 0;
    return 1;
}

// hexagon: three colours of hexagons in the x-z plane. A 6 x 6 grid of half-triangle
// blocks repeats; some blocks are one colour, the others are split along a diagonal.
double hexagon(const Vec3& p) {
    constexpr double kHalf = 0.5, kHeight = 0.866025404;  // POV-Ray's xfactor, zfactor
    const double x = std::fabs(p.x);
    const double z = p.z < 0 ? 5.196152424 - std::fabs(p.z) : p.z;
    double xs = x / kHalf, zs = z / kHeight;
    xs -= std::floor(xs / 6.0) * 6.0;
    zs -= std::floor(zs / 6.0) * 6.0;
    const int xm = static_cast<int>(std::floor(xs)) % 6;
    const int zm = static_cast<int>(std::floor(zs)) % 6;
    // Whole blocks: columns 0 and 5, and 2 and 3, by row.
    static constexpr int kEdge[6] = {0, 1, 1, 2, 2, 0};
    static constexpr int kMiddle[6] = {2, 2, 0, 0, 1, 1};
    if (xm == 0 || xm == 5) return kEdge[zm];
    if (xm == 2 || xm == 3) return kMiddle[zm];
    // Columns 1 and 4: split by the diagonal (flipped where it slopes the other way).
    double xl = xs - xm;
    const double zl = zs - zm;
    if ((xm + zm) % 2 == 1) xl = 1.0 - xl;
    if (xl == 0.0) xl = 0.0001;
    static constexpr int kBelow[6] = {0, 2, 1, 0, 2, 1};
    static constexpr int kAbove[6] = {2, 1, 0, 2, 1, 0};
    return (zl / xl) < 1.0 ? kBelow[zm] : kAbove[zm];
}

double radial(const Vec3& p) {
    if (std::fabs(p.x) < 0.001 && std::fabs(p.z) < 0.001) return 0.25;
    return 0.25 + (std::atan2(p.x, p.z) + std::numbers::pi) / (2 * std::numbers::pi);
}

double leopard(const Vec3& p) {
    const double v = (std::sin(p.x) + std::sin(p.y) + std::sin(p.z)) / 3.0;
    return v * v;
}

}  // namespace

bool isListPattern(PatternKind k) {
    return k == PatternKind::Checker || k == PatternKind::Brick || k == PatternKind::Hexagon;
}

double plainPatternValue(const PatternSpec& s, const Vec3& p) {
    switch (s.kind) {
        case PatternKind::Checker:
            return checker(p);
        case PatternKind::Brick:
            return brick(s, p);
        case PatternKind::Hexagon:
            return hexagon(p);
        case PatternKind::Gradient: {
            const double v = dot(p, s.gradient);
            return v > 1.0 ? std::fmod(v, 1.0) : v;
        }
        case PatternKind::Onion:
            return std::fmod(length(p), 1.0);
        case PatternKind::Leopard:
            return leopard(p);
        case PatternKind::Radial:
            return radial(p);
        default:
            return 0;
    }
}

double applyFrequencyPhase(const PatternSpec& s, double value) {
    if (s.frequency != 0.0) value = std::fmod(value * s.frequency + s.phase, 1.00001);
    if (value < 0.0) value -= std::floor(value);  // negative frequencies
    return applyWaveForm(defaultsOf(s.kind).wave, value);
}

double patternValue(const PatternSpec& s, const Vec3& paintPoint) {
    Vec3 p = s.transformed ? s.toPattern.point(paintPoint) : paintPoint;
    // The seven noise patterns apply their turbulence themselves (noise_patterns.h).
    const bool noisy = defaultsOf(s.kind).turbulenceInside;
    if (s.turbulence.on() && !noisy) p = turbulenceWarp(s.turbulence, p);
    if (isListPattern(s.kind)) return plainPatternValue(s, p);
    const double raw = noisy ? noisePatternValue(s, p) : plainPatternValue(s, p);
    return applyFrequencyPhase(s, raw);
}

}  // namespace pcsg::tracer
