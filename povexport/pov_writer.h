// The POV-Ray 3.7 writer: the expanded tree as scene description text that POV-Ray
// renders as the same picture as the native tracer, and fast.
//
// Mapping (docs/language.md sections 5 and 7):
//  - Geometry keeps our coordinates. Each primitive is POV-Ray's own object with the
//    accumulated object-to-world map as `matrix <...>`: our Affine is p' = L p + t
//    (column vectors), POV-Ray's matrix is p' = p·M + t (row vectors), so M = L^T.
//      sphere       sphere { <0,0,0>, 1 }
//      cube         box { <-1,-1,-1>, <1,1,1> }
//      cylinder     cylinder { <0,0,0>, <0,0,1>, 1 }            (capped)
//      cone         cone { <0,0,0>, 1, <0,0,1>, 0 }             (capped)
//      tetrahedron  the intersection of the four planes through its faces, declared once
//                   as PcsgTetrahedron with a bounded_by box
//      torus(R, r)  torus { R, r } (POV-Ray's lies about y; a rotation taking y to z is
//                   folded into the matrix)
//      plane        plane { <0,0,1>, 0 }: POV-Ray's inside is the side opposite the
//                   normal, z <= 0, as ours
//      tri1, tri2, triangle   triangle { ... } with the corners transformed to world
//                   coordinates (degenerate ones, which POV-Ray rejects, are left out)
//      empty        nothing (the expander already folded it away)
//  - Materials: each is declared once as `#declare M<i> = texture { pigment { color
//    rgb <...> } finish { ambient diffuse phong phong_size reflection ... } }` (a POV-Ray
//    `material` with its interior when any material has one). The texture stands where
//    the paint node stood (ExpandedTree's TreeNode::texture): on the union or primitive
//    the paint applies to, once, and the root carries M0. POV-Ray gives a CSG's texture to
//    the objects below that have none, so an inner paint wins, and a CSG surface keeps its
//    primitive's material. A union with a texture is not flattened into its parent.
//  - ∪ ∩ \ stay nested as derived. A union with more than maxUnionChildren operands is
//    regrouped into a balanced nest (spatially, by the operands' box centres): POV-Ray
//    tests a union's operands one after the other (its bounding hierarchy holds only
//    top-level objects unless unions are split), so nesting is its hierarchy. Every
//    intersection and difference whose box is finite gets a `bounded_by { box {...} }`
//    (POV-Ray cannot bound intersections of planes, and bounds a difference only by its
//    first operand); unions are bounded by POV-Ray from their operands' boxes.
//
// The camera (right-handed scene, left-handed POV-Ray): the geometry is not mirrored;
// the camera's `right` vector is negated, which makes POV-Ray's look_at build a
// right-handed frame (its handedness test is (up x direction) . right < 0). The block is
// exactly the one tracer/camera.h documents and reproduces:
//
//   camera { perspective location <L> right -x*W/H up y direction z sky <S>
//            look_at <P> angle A }
//
// `angle` is the horizontal field of view, the image's aspect the vertical one; POV-Ray
// applies look_at and angle after the other items. With sky <0,0,1> looking along +y,
// +x is on the right of the image, as docs/language.md section 7 says (checked against
// POV-Ray in pov_writer_test.cpp: the silhouettes of asymmetric objects match an
// independent pin-hole projection).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>

#include "expander.h"
#include "graph.h"

namespace pcsg {

struct PovOptions {
    int width = 640, height = 480;   // the image size: sets the camera's aspect ratio
    uint32_t maxUnionChildren = 32;  // larger unions are regrouped into a balanced nest
    // bounded_by boxes on unions too. Off: POV-Ray bounds a union of bounded objects
    // itself (and warns "CSG union unnecessarily bounded" for a top-level one).
    bool boundUnions = false;
    std::string title;  // the scene's name, for the header comment
};

struct PovWriteStats {
    uint64_t objects = 0;  // primitives written
    uint64_t skipped = 0;  // degenerate triangles left out
    uint64_t groups = 0;   // unions added by regrouping big unions
    uint64_t bytes = 0;    // text written
};

// Writes the whole scene (settings, camera, lights, background, materials, the tree) to
// `out`, streaming: the text is never held in memory as a whole. Throws
// std::runtime_error when the stream fails.
PovWriteStats writePov(const Graph& g, const ExpandedTree& tree, std::ostream& out,
                       const PovOptions& options = {});

// The camera block above, for a scene camera and an image size.
std::string povCamera(const Camera& camera, int width, int height);

}  // namespace pcsg
