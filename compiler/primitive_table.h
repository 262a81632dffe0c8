// The primitives of docs/language.md section 5, one row each: the facts every stage needs
// (the keyword, the arguments, surface or solid, the box in its own coordinates, the
// corners, and the POV-Ray object it is exported as). A new primitive is a new row here,
// its intersection in tracer/primitives.cpp and nothing else that lists primitives.
#pragma once

#include <cstdint>

#include "geometry.h"
#include "graph.h"

namespace pcsg {

struct PrimitiveInfo {
    PrimitiveKind kind;
    const char* name;  // the keyword
    uint32_t args;     // argument count: torus R r, triangle 9 coordinates
    bool surface;      // a triangle: no inside, only under unions (section 5)
    // POV-Ray 3.7 text of the object in its own coordinates, up to its closing brace,
    // for the kinds without arguments (the exporter writes the others itself).
    const char* pov;
};

inline constexpr PrimitiveInfo kPrimitiveTable[] = {
    {PrimitiveKind::Sphere, "sphere", 0, false, "sphere{<0,0,0>,1"},
    {PrimitiveKind::Cube, "cube", 0, false, "box{<-1,-1,-1>,<1,1,1>"},
    {PrimitiveKind::Cylinder, "cylinder", 0, false, "cylinder{<0,0,0>,<0,0,1>,1"},
    {PrimitiveKind::Cone, "cone", 0, false, "cone{<0,0,0>,1,<0,0,1>,0"},
    {PrimitiveKind::Tetrahedron, "tetrahedron", 0, false, "object{PcsgTetrahedron"},
    {PrimitiveKind::Torus, "torus", 2, false, nullptr},
    {PrimitiveKind::Plane, "plane", 0, false, "plane{<0,0,1>,0"},
    {PrimitiveKind::Empty, "empty", 0, false, nullptr},
    {PrimitiveKind::Tri1, "tri1", 0, true, nullptr},
    {PrimitiveKind::Tri2, "tri2", 0, true, nullptr},
    {PrimitiveKind::Triangle, "triangle", 9, true, nullptr},
};

constexpr const PrimitiveInfo& primitiveInfo(PrimitiveKind k) {
    return kPrimitiveTable[static_cast<int>(k)];
}
static_assert(primitiveInfo(PrimitiveKind::Triangle).kind == PrimitiveKind::Triangle,
              "kPrimitiveTable is in PrimitiveKind order");

constexpr const char* primitiveName(PrimitiveKind k) {
    return primitiveInfo(k).name;
}
constexpr uint32_t primitiveArgCount(PrimitiveKind k) {
    return primitiveInfo(k).args;
}
constexpr bool isTriangle(PrimitiveKind k) {
    return primitiveInfo(k).surface;
}

// The tetrahedron's vertices: the face opposite vertex v lies in the plane -v.p = 1, its
// inside is -v.p <= 1.
inline constexpr Vec3 kTetraVertices[4] = {{1, 1, 1}, {-1, -1, 1}, {1, -1, -1}, {-1, 1, -1}};

// The corners of a triangle primitive (tri1, tri2, or triangle with its 9 arguments).
void triangleCorners(PrimitiveKind kind, const double* args, Vec3 corners[3]);

// The box of a primitive in its own coordinates (args: its argument values).
Box primitiveBox(PrimitiveKind kind, const double* args);

}  // namespace pcsg
