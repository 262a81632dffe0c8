// The last occluder of a thread's shadow rays: see last_occluder.h.
#include "last_occluder.h"

#include "unrolled_instances.h"

namespace pcsg::tracer {

void LastOccluder::keep(const std::vector<const Affine*>& inverses, uint64_t path,
                        uint32_t material) {
    kept_ = entering_;
    chain_.clear();
    for (const Affine* m : inverses) chain_.push_back(*m);
    path_ = path;
    material_ = material;
    valid_ = true;
}

bool LastOccluder::occludes(UnrollCache::Reader& cache, uint32_t maxDepth, const LocalRay& r,
                            double tmin, double tmax) {
    tried_ = false;
    if (!valid_) return false;
    const UnrolledInstance* x = cache.built(kept_.key, kept_.select, kept_.depth);
    if (!x || kept_.depth + x->levels() > maxDepth) return false;
    LocalRay rr = r;
    for (const Affine& m : chain_) rr = LocalRay{m.point(rr.o), m.vector(rr.d)};
    Hit hit;
    double best = tmax;
    if (x->first(rr, tmin, best, hit, {path_, material_, 0}, true, cache.scratch())) {
        ++stopped_;
        return true;
    }
    tried_ = true;
    return false;
}

}  // namespace pcsg::tracer
