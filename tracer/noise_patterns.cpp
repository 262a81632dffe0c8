// POV-Ray 3.7.0's noise-based patterns, with noise_generator 2 (the default), from
// source/backend/pattern/pattern.cpp (agate_pattern, granite_pattern, marble_pattern,
// wood_pattern, wrinkles_pattern, dents_pattern, Evaluate_TPat: bozo and spotted are Noise
// itself), source/backend/pattern/warps.cpp (Warp_EPoint) and texture.cpp (cycloidal,
// Triangle_Wave). Our words for what they compute are in noise_patterns.h.
#include "noise_patterns.h"

#include <algorithm>
#include <cmath>

#include "noise.h"

namespace pcsg {
namespace {

constexpr double kTwoPi = 6.283185307179586476925286766559;  // POV-Ray's TWO_M_PI

// granite: 6 octaves of |1 - 2 noise(4 p 2^i)| (at most 0.5) / 2^i.
double granite(const Vec3& p) {
    const Vec3 base = p * 4.0;
    double sum = 0.0, freq = 1.0;
    for (int i = 0; i < 6; freq *= 2.0, ++i) {
        double t = std::fabs(1.0 - 2.0 * noise(base * freq));
        if (t > 0.5) t = 0.5;
        sum += t / freq;
    }
    return sum;
}

// wrinkles (the pigment pattern): 10 octaves of clamp(2 noise - 0.5, 0, 1), lambda 2,
// omega 0.5, halved.
double wrinkles(const Vec3& p) {
    double lambda = 2.0, omega = 0.5;
    double value = std::clamp(noise(p) * 2.0 - 0.5, 0.0, 1.0);
    for (int i = 1; i < 10; ++i) {
        value += omega * std::clamp(noise(p * lambda) * 2.0 - 0.5, 0.0, 1.0);
        lambda *= 2.0;
        omega *= 0.5;
    }
    return value / 2.0;
}

double dents(const Vec3& p) {
    const double n = noise(p);
    return n * n * n;
}

// wood: the distance from the z axis of the point moved by the turbulence (POV-Ray's
// Warp_EPoint skips the classic warp for wood).
double wood(const Vec3& p, const Turbulence& t) {
    double x = 0.0, y = 0.0;
    if (t.on()) {
        const Vec3 d = dturbulence(p, t);
        x = cycloidal((p.x + d.x) * t.amount.x);
        y = cycloidal((p.y + d.y) * t.amount.y);
    }
    x += p.x;
    y += p.y;
    return std::sqrt(x * x + y * y);  // POV-Ray's VLength with z = 0
}

// marble: x plus the turbulence (no warp either).
double marble(const Vec3& p, const Turbulence& t) {
    const double turb = t.on() ? t.amount.x * turbulence(p, t) : 0.0;
    return p.x + turb;
}

// agate: POV-Ray warps the point (agate is not among the patterns Warp_EPoint skips), then
// reads the turbulence again, scaled by agate_turb.
double agate(const Vec3& p, const Turbulence& t, double agateTurb) {
    const double turb = agateTurb * turbulence(p, t);
    double v = 0.5 * (cycloidal(1.3 * turb + 1.1 * p.z) + 1.0);
    if (v < 0.0) return 0.0;
    v = std::min(1.0, v);
    return std::pow(v, 0.77);
}

}  // namespace

double cycloidal(double v) {
    if (v >= 0.0) return std::sin(((v - std::floor(v)) * 50000.0) / 50000.0 * kTwoPi);
    return 0.0 - std::sin(((0.0 - (v + std::floor(0.0 - v))) * 50000.0) / 50000.0 * kTwoPi);
}

double triangleWave(double v) {
    const double offset = v >= 0.0 ? v - std::floor(v) : v + 1.0 + std::floor(std::fabs(v));
    return offset >= 0.5 ? 2.0 * (1.0 - offset) : 2.0 * offset;
}

Vec3 turbulenceWarp(const Turbulence& t, const Vec3& p) {
    if (!t.on()) return p;
    const Vec3 d = dturbulence(p, t);
    return Vec3{p.x + d.x * t.amount.x, p.y + d.y * t.amount.y, p.z + d.z * t.amount.z};
}

double noisePatternValue(const PatternSpec& spec, const Vec3& p) {
    const Turbulence& t = spec.turbulence;
    switch (spec.kind) {
        case PatternKind::Bozo:
            return noise(turbulenceWarp(t, p));
        case PatternKind::Granite:
            return granite(turbulenceWarp(t, p));
        case PatternKind::Wrinkles:
            return wrinkles(turbulenceWarp(t, p));
        case PatternKind::Dents:
            return dents(turbulenceWarp(t, p));
        case PatternKind::Agate:
            return agate(turbulenceWarp(t, p), t, spec.agateTurb);
        case PatternKind::Wood:
            return wood(p, t);
        case PatternKind::Marble:
            return marble(p, t);
        default:
            return 0.0;
    }
}

double applyWaveForm(WaveForm w, double v) {
    switch (w) {
        case WaveForm::Ramp:
            return v;
        case WaveForm::Sine:
            return (1.0 + cycloidal(v)) * 0.5;
        case WaveForm::Triangle:
            return triangleWave(v);
        case WaveForm::Scallop:
            return std::fabs(cycloidal(v * 0.5));
        case WaveForm::Cubic:
            return v * v * ((-2.0 * v) + 3.0);
    }
    return v;
}

double waveValue(double raw, double frequency, double phase, WaveForm w) {
    double v = raw;
    if (frequency != 0.0) v = std::fmod(v * frequency + phase, 1.00001);
    if (v < 0.0) v -= std::floor(v);
    return applyWaveForm(w, v);
}

}  // namespace pcsg
