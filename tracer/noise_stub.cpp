// TEMPORARY (branch patterns only): stand-ins for the noise branch's functions so that this
// branch links before the noise branch lands. Delete this file when merging `noise`.
#include <cmath>

#include "noise_patterns.h"
#include "normal_patterns.h"

namespace pcsg {

double noisePatternValue(const PatternSpec&, const Vec3&) {
    return 0.5;
}
Vec3 turbulenceWarp(const Turbulence&, const Vec3& p) {
    return p;
}
double applyWaveForm(WaveForm w, double v) {
    if (w != WaveForm::Triangle) return v;
    const double f = v - std::floor(v);
    return f >= 0.5 ? 2 * (1 - f) : 2 * f;
}
PatternDefaults patternDefaults(PatternKind k) {
    PatternDefaults d;
    if (k == PatternKind::Wood || k == PatternKind::Marble) d.wave = WaveForm::Triangle;
    d.turbulenceInside =
        k == PatternKind::Wood || k == PatternKind::Marble || k == PatternKind::Agate;
    return d;
}
Vec3 perturbNormal(const NormalSpec&, const Vec3&, const Vec3& n) {
    return n;
}

}  // namespace pcsg
