// The last occluder of a thread's shadow rays: the copy of an expanded instance that the
// last occluded shadow ray met, tried first by the next one.
//
// Shadow rays from neighbouring pixels are mostly stopped by the same copy of the same
// instance (Sierpinski order 8: three in four occluded shadow rays). A shadow ray asks
// only whether any surface lies within (tmin, tmax), so it may stop at any one: when the
// copy noted holds one, the walk from the root is not needed. The copy is tried exactly as
// the walk would try it: the ray mapped through the same inverse matrices (their values,
// kept), in the same order, into the S-node's frame, and the instance looked up again in
// the shared cache by its key (nothing when it was evicted). The walk's culling never
// hides a surface (boxes are padded for the rounding of those maps), so whenever the copy
// holds one, the walk would have said "occluded" too. When the copy holds none, the walk
// that follows skips that copy (missed()): the same ray in the same frame would find
// nothing there again.
#pragma once

#include <vector>

#include "instance_boxes.h"
#include "operators.h"
#include "unroll_cache.h"

namespace pcsg::tracer {

class LastOccluder {
  public:
    // The S-node instance the walk is handing to an expanded instance (before it does).
    void entering(NodeId select, uint32_t depth, const InstanceBoxes::Key& key) {
        entering_ = {select, depth, key};
    }
    // That instance stopped the shadow ray: `inverses` are the T-nodes' inverse matrices
    // on the way from the world to the S-node, outermost first; `path` its instance path.
    void keep(const std::vector<const Affine*>& inverses, uint64_t path, uint32_t material);

    // Whether the copy noted holds a surface within (tmin, tmax) of the world ray r; false
    // also when there is none noted or its instance is no longer in the cache. Starts a
    // ray (within the caller's UnrollCache::Pin scope).
    bool occludes(UnrollCache::Reader& cache, uint32_t maxDepth, const LocalRay& r, double tmin,
                  double tmax);
    // Starts a ray that does not try the copy (one through the top level): missed() is
    // false for it, whatever the last ray that tried the copy found.
    void untried() { tried_ = false; }
    // The copy being entered (at `path`, after entering()) is the one occludes() tried for
    // this ray and found nothing in.
    bool missed(uint64_t path) const {
        return tried_ && path == path_ && entering_.select == kept_.select &&
               entering_.depth == kept_.depth && entering_.key == kept_.key;
    }

    uint64_t stopped() const { return stopped_; }  // rays occludes() answered "occluded"

  private:
    struct Instance {
        NodeId select = kNone;
        uint32_t depth = 0;
        InstanceBoxes::Key key;
    };
    Instance entering_, kept_;
    std::vector<Affine> chain_;  // the inverse matrices, outermost first
    uint64_t path_ = 0;
    uint32_t material_ = 0;
    bool valid_ = false;
    bool tried_ = false;  // occludes() tried the copy for the current ray, in vain
    uint64_t stopped_ = 0;
};

}  // namespace pcsg::tracer
