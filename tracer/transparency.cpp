#include "transparency.h"

#include <algorithm>
#include <cmath>

namespace pcsg::tracer {

namespace {
constexpr double kEpsilon = 1e-10;
constexpr double kAtmosphereIor = 1.0;
}  // namespace

bool Interiors::contains(uint64_t id) const {
    for (int i = 0; i < size_; ++i)
        if (items_[i].id == id) return true;
    return false;
}

bool Interiors::remove(uint64_t id) {
    for (int i = size_ - 1; i >= 0; --i) {
        if (items_[i].id != id) continue;
        for (int j = i + 1; j < size_; ++j) items_[j - 1] = items_[j];
        --size_;
        return true;
    }
    return false;
}

void Interiors::push(const Interior& interior) {
    if (size_ < kCapacity) items_[size_++] = Slot{interior.id, interior.material};
}

double iorOf(const Graph& g, uint32_t material) {
    return material < g.materials.size() ? g.materials[material].ior : 1.0;
}

double crossSurface(Interiors& in, const Interior& s, const Graph& g) {
    const double ior = iorOf(g, s.material);
    if (in.empty()) {  // entering from the atmosphere
        in.push(s);
        return kAtmosphereIor / ior;
    }
    if (in.innermost().id == s.id) {  // leaving the innermost object
        in.remove(s.id);
        return ior / (in.empty() ? kAtmosphereIor : iorOf(g, in.innermost().material));
    }
    if (in.remove(s.id)) return 1.0;  // leaving an overlap: no change
    const double outside = iorOf(g, in.innermost().material);
    in.push(s);  // entering a new object from inside another
    return outside / ior;
}

double relativeIor(const Interiors& in, const Interior& s, const Graph& g) {
    const double ior = iorOf(g, s.material);
    if (in.empty()) return ior / kAtmosphereIor;
    if (in.contains(s.id))
        return (in.size() == 1 ? kAtmosphereIor : iorOf(g, in.innermost().material)) / ior;
    return ior / iorOf(g, in.innermost().material);
}

std::optional<Vec3> refractDirection(const Vec3& d, const Vec3& n, double ior) {
    const double c = -dot(d, n);  // n faces the ray: c >= 0
    const double t = 1.0 + ior * ior * (c * c - 1.0);
    if (t < 0.0) return std::nullopt;
    return d * ior + n * (ior * c - std::sqrt(t));
}

double maxAbs(const Vec3& c) {
    return std::max({std::fabs(c.x), std::fabs(c.y), std::fabs(c.z)});
}

Vec3 conserveEnergy(const Vec3& passes, const Vec3& r) {
    return Vec3{passes.x * std::min(1.0 - r.x, 1.0), passes.y * std::min(1.0 - r.y, 1.0),
                passes.z * std::min(1.0 - r.z, 1.0)};
}

Vec3 fade(const Material& m, double depth, bool shadow) {
    const Vec3 one{1, 1, 1};
    if (!(std::fabs(m.fadeDistance) > kEpsilon) || (shadow && !(m.fadePower > 0))) return one;
    const Vec3 clear = one - m.fadeColour;  // 1 - fade_color
    const double x = depth / m.fadeDistance;
    if (m.fadePower >= 1000)
        return Vec3{std::exp(-clear.x * x), std::exp(-clear.y * x), std::exp(-clear.z * x)};
    const double k = 1.0 + std::pow(x, m.fadePower);
    return m.fadeColour + clear / k;
}

bool anyTransparent(const Graph& g) {
    for (const Material& m : g.materials)
        if (m.mayLetLightThrough()) return true;
    return false;
}

}  // namespace pcsg::tracer
