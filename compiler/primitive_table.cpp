// The per-primitive facts that are functions: see primitive_table.h.
#include "primitive_table.h"

#include <cmath>

namespace pcsg {

// The corners of a triangle primitive (tri1, tri2, or triangle with its 9 arguments).
void triangleCorners(PrimitiveKind kind, const double* args, Vec3 corners[3]) {
    switch (kind) {
        case PrimitiveKind::Tri1:
            corners[0] = {0, 0, 0}, corners[1] = {1, 0, 0}, corners[2] = {0, 1, 0};
            return;
        case PrimitiveKind::Tri2:
            corners[0] = {0, 0, 0}, corners[1] = {-1, 0, 0}, corners[2] = {0, -1, 0};
            return;
        default:
            for (int i = 0; i < 3; ++i)
                corners[i] = {args[3 * i], args[3 * i + 1], args[3 * i + 2]};
            return;
    }
}

// The box of a primitive in its own coordinates (args: its argument values).
Box primitiveBox(PrimitiveKind kind, const double* args) {
    constexpr double inf = Box::inf;
    switch (kind) {
        case PrimitiveKind::Sphere:
        case PrimitiveKind::Cube:
        case PrimitiveKind::Tetrahedron:
            return Box{{-1, -1, -1}, {1, 1, 1}};
        case PrimitiveKind::Cylinder:
        case PrimitiveKind::Cone:
            return Box{{-1, -1, 0}, {1, 1, 1}};
        case PrimitiveKind::Torus: {
            const double e = std::fabs(args[0]) + std::fabs(args[1]), r = std::fabs(args[1]);
            return Box{{-e, -e, -r}, {e, e, r}};
        }
        case PrimitiveKind::Plane:
            return Box{{-inf, -inf, -inf}, {inf, inf, 0}};
        case PrimitiveKind::Empty:
            return Box::empty();
        // tri1's and tri2's boxes are their corners' (triangleCorners), written out: the
        // prefill and the unroller ask for one at every triangle they meet.
        case PrimitiveKind::Tri1:
            return Box{{0, 0, 0}, {1, 1, 0}};
        case PrimitiveKind::Tri2:
            return Box{{-1, -1, 0}, {0, 0, 0}};
        case PrimitiveKind::Triangle: {
            Vec3 c[3];
            triangleCorners(kind, args, c);
            Box b;
            for (const Vec3& p : c) b.extend(p);
            return b;
        }
    }
    return Box::everything();
}

}  // namespace pcsg
