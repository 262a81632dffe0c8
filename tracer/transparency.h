// Transparency and refraction as POV-Ray 3.7 computes them (source/core/render/trace.cpp:
// ComputeLightedTexture, ComputeRefraction, TraceRefractionRay, ComputeRelativeIOR,
// ComputeShadowTexture, ComputeShadowColour; base/colour.h for the colour measures). The
// pieces here are pure functions; the ray tree that uses them is Shader's (ray_tree.cpp).
//
//  - A pigment colour (r, g, b, filter f, transmit t) lets through f * rgb + t (per channel:
//    POV-Ray's TransmittedColour), and its own lighting (ambient, diffuse) is scaled by its
//    opacity 1 - f - t. Highlights and reflection are not scaled.
//  - conserve_energy multiplies the light let through by min(1 - reflectivity, 1) per
//    channel.
//  - A transmitted ray is traced when min(1, |grey(let through)|) > adc_bailout (grey: POV-Ray's
//    0.297 r + 0.589 g + 0.114 b), with weight times the largest channel of what is let through.
//  - The interior stack (Interiors): the interiors a ray is inside, innermost last; camera
//    rays start with those of the solids containing the camera (POV-Ray's
//    InitRayContainerState; Shader::startInteriors finds them with a probe ray). An
//    interior is an object's, as POV-Ray's: that of the paint node instance that applied
//    the surface's material (the paint node with the instance path that reached it in the
//    unrolled tree, SurfaceHit::interior), which is one `material { }` of the export and
//    so one POV-Ray interior shared by the primitives below it; surfaces under no paint
//    node share the scene's default interior (the root's). Two objects of one material
//    that overlap or nest are two interiors; its ior and fade are the material's.
//    Crossing a surface of interior I (POV-Ray's rules, nested objects count as outside
//    their container):
//      * stack empty: enter I, ior ratio 1 / ior(I);
//      * I innermost: leave it, ratio ior(I) / ior(next innermost, or 1 outside);
//      * I deeper in the stack: leave it, ratio 1;
//      * else: enter I, ratio ior(innermost) / ior(I).
//    A ratio within 1e-10 of 1 continues the ray straight on without counting a trace level;
//    otherwise Heckbert's refraction, or total internal reflection when 1 + r^2 (c^2 - 1) < 0
//    (then the surface's own reflection is not added, and the reflected light is not
//    filtered).
//  - Fade (interior fade_distance d, fade_power p, fade_color c) applies to a ray whose stack
//    holds the surface's interior, over the distance t travelled inside: p >= 1000 gives
//    exp(-(1 - c) t / d), else c + (1 - c) / (1 + (t / d)^p). Shadow rays fade too (with
//    p > 0 only): each starts with the stack of the ray whose hit it lights and toggles the
//    interior of every surface it crosses (POV-Ray's ComputeShadowMedia), so the stretch
//    from a solid's near wall to its far wall fades.
//  - Shadows: a shadow ray is multiplied by what each surface it crosses lets through
//    (both walls of a solid); weight (|r| + |g| + |b|) / 3 below adc_bailout is black. No
//    caustics, no refraction of shadow rays.
#pragma once

#include <algorithm>
#include <cstdint>
#include <optional>

#include "eval.h"
#include "graph.h"

namespace pcsg::tracer {

// The interior of a paint node instance, the object a surface below it belongs to: paint
// node `n` reached by instance path `path` (never 0, the default interior). The graph walk
// and the expanded instances record the same number.
inline uint64_t paintInteriorOf(uint64_t path, NodeId n) {
    return pathChild(path, 0x80000000u | n) | 1;
}

// One object's interior: which object (the paint node instance, SurfaceHit::interior; 0:
// the default interior of surfaces under no paint node) and the material whose ior and
// fade it has.
struct Interior {
    uint64_t id = 0;
    uint32_t material = 0;
};

// The interiors a ray is inside, innermost last. Only the first size() slots are set, and
// a copy copies only those: every ray of a camera ray's tree starts with a copy of a
// stack that is mostly empty, and copying (or zeroing) all the slots, 0.5 KB, took a
// tenth of the shading of a simple hit.
class Interiors {
  public:
    static constexpr int kCapacity = 32;
    Interiors() = default;
    Interiors(const Interiors& other) : size_(other.size_) {
        std::copy_n(other.items_, size_, items_);
    }
    Interiors& operator=(const Interiors& other) {
        size_ = other.size_;
        std::copy_n(other.items_, size_, items_);
        return *this;
    }
    bool empty() const { return size_ == 0; }
    int size() const { return size_; }
    Interior innermost() const {
        return Interior{items_[size_ - 1].id, items_[size_ - 1].material};
    }
    bool contains(uint64_t id) const;
    bool remove(uint64_t id);
    void push(const Interior& interior);  // beyond kCapacity nesting levels, ignored

  private:
    struct Slot {  // an Interior without its initialisers: the unused slots are left unset
        uint64_t id;
        uint32_t material;
    };
    Slot items_[kCapacity];
    int size_ = 0;
};

// The index of refraction of material `i` (1 past the end: the atmosphere's).
double iorOf(const Graph& g, uint32_t material);

// A ray crossing a surface of interior `s` updates `in` and returns n1 / n2
// (ComputeRefraction).
double crossSurface(Interiors& in, const Interior& s, const Graph& g);

// n2 / n1 seen by a ray with stack `in` at a surface of interior `s` (ComputeRelativeIOR),
// which fresnel reflection reads.
double relativeIor(const Interiors& in, const Interior& s, const Graph& g);

// The refracted direction of unit `d` at a surface with unit normal `n` facing the ray, ratio
// n1 / n2 `ior`; nothing on total internal reflection.
std::optional<Vec3> refractDirection(const Vec3& d, const Vec3& n, double ior);

// What a pigment colour lets through: filter * rgb + transmit per channel.
inline Vec3 transmittedColour(const FilterColour& c) {
    return c.rgb * c.filter + Vec3{c.transmit, c.transmit, c.transmit};
}
inline double opacity(const FilterColour& c) {
    return 1.0 - c.filter - c.transmit;
}
inline double greyscale(const Vec3& c) {
    return 0.297 * c.x + 0.589 * c.y + 0.114 * c.z;
}
double maxAbs(const Vec3& c);
inline bool isTransparent(const FilterColour& c) {
    return c.filter != 0 || c.transmit != 0;
}

// conserve_energy: what passes, times min(1 - reflectivity, 1) per channel.
Vec3 conserveEnergy(const Vec3& passes, const Vec3& reflectivity);

// The attenuation of light that travelled `depth` inside `m`'s interior; `shadow`: POV-Ray's
// shadow-ray variant (no fading when fade_power is 0).
Vec3 fade(const Material& m, double depth, bool shadow = false);

// Whether any material may let light through (a plain colour or a colour of its pattern with
// filter or transmit): if none does, shadow rays stop at the first surface.
bool anyTransparent(const Graph& g);

}  // namespace pcsg::tracer
