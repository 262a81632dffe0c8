// POV-Ray 3.7.0's bumps, dents, wrinkles, ripples and waves normals (normal.cpp), in the
// order of its operations so that the results agree to rounding.
#include "normal_patterns.h"

#include <cmath>

#include "noise.h"
#include "noise_patterns.h"

namespace pcsg {
namespace {

Vec3 unit(const Vec3& v) {
    return v / std::sqrt(dot(v, v));  // POV-Ray's VNormalize divides by the length
}

Vec3 wrinkles(const Vec3& q) {
    Vec3 result{0, 0, 0};
    double scale = 1.0;
    for (int i = 0; i < 10; scale *= 2.0, ++i) {
        const Vec3 v = dnoise(q * scale);
        result.x += std::fabs(v.x / scale);
        result.y += std::fabs(v.y / scale);
        result.z += std::fabs(v.z / scale);
    }
    return result;
}

// ripples (waves = false) and waves: the sum over POV-Ray's wave sources.
Vec3 waveSum(const NormalSpec& spec, const Vec3& q, Vec3 n, bool waves) {
    const NoiseWaves& w = noiseWaves();
    const double count = NoiseWaves::kCount;
    for (int i = 0; i < NoiseWaves::kCount; ++i) {
        const Vec3 d = q - w.source[i];
        double length = std::sqrt(dot(d, d));
        if (length == 0.0) length = 1.0;
        double scalar;
        if (waves) {
            const double index =
                length * spec.pattern.frequency * w.frequency[i] + spec.pattern.phase;
            scalar = cycloidal(index) * spec.amount / w.frequency[i];
        } else {
            const double index = length * spec.pattern.frequency + spec.pattern.phase;
            scalar = cycloidal(index) * spec.amount;
        }
        n += d * (scalar / (length * count));
    }
    return n;
}

}  // namespace

Vec3 perturbNormal(const NormalSpec& spec, const Vec3& patternPoint, const Vec3& normal) {
    const Vec3 q = turbulenceWarp(spec.pattern.turbulence, patternPoint);
    Vec3 n = normal;
    switch (spec.kind) {
        case NormalKind::None:
            return normal;
        case NormalKind::Bumps:
            n += dnoise(q) * spec.amount;
            break;
        case NormalKind::Dents: {
            double s = noise(q);
            s = s * s * s * spec.amount;
            n += dnoise(q) * s;
            break;
        }
        case NormalKind::Wrinkles:
            n += wrinkles(q) * spec.amount;
            break;
        case NormalKind::Ripples:
            n = waveSum(spec, q, n, false);
            break;
        case NormalKind::Waves:
            n = waveSum(spec, q, n, true);
            break;
    }
    return unit(n);
}

Vec3 perturbNormalThrough(const NormalSpec& spec, const Affine& toPattern,
                          const Affine& fromPattern, bool transformed, const Vec3& point,
                          const Vec3& normal) {
    Vec3 n = unit(normal);
    if (transformed) n = unit(fromPattern.transposedVector(n));
    const Vec3 p = transformed ? toPattern.point(point) : point;
    Vec3 r = perturbNormal(spec, p, n);
    if (transformed) r = unit(toPattern.transposedVector(r));
    return r;
}

}  // namespace pcsg
