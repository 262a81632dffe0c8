#include "perturb.h"

#include "normal_patterns.h"

namespace pcsg::tracer {

Vec3 perturbedNormal(const NormalSpec& spec, const SurfaceHit& hit, const Vec3& n) {
    // Pattern space to the world, and back: G = paint-to-world * pattern-to-paint.
    if (!hit.paintMap) return n;
    const Affine toPattern = spec.pattern.toPattern * *hit.paintMap;  // world -> pattern
    const Affine fromPattern = toPattern.inverse();
    // A normal maps by the transpose of the inverse of the points' map.
    Vec3 local = normalize(fromPattern.transposedVector(n));
    const Vec3 point = spec.pattern.toPattern.point(hit.paintPoint);
    local = perturbNormal(spec, point, local);
    const Vec3 back = normalize(toPattern.transposedVector(local));
    return isFinite(back) ? back : n;
}

}  // namespace pcsg::tracer
