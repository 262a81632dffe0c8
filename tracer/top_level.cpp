// The two-level structure: see top_level.h.
#include "top_level.h"

#include <algorithm>
#include <unordered_map>

#include "traversal.h"

namespace pcsg::tracer {

// Where expandTop stops: the expanded instances, one per (instance key, depth), shared by
// their copies, and with the expansion cache where it has built them. A dry run only counts the
// copies and the instances (it refers every copy to an empty instance), so that a scene whose
// instances are all unique is refused before any is expanded.
class TopLevel::Cuts final : public UnrolledInstance::Cuts {
  public:
    Cuts(const TraceScene& scene, const UnrollCache& cache, size_t maxBytes, TopLevel& out,
         bool dry)
        : scene_(scene), cache_(cache), maxBytes_(maxBytes), out_(out), dry_(dry) {}

    size_t instances() const { return index_.size(); }

    // kMaxVisits, and kVisitsPerCopy more for each copy met, within the budget (one visit
    // per kBudgetPerVisit bytes): a scene of many copies (Sierpinski order 12's 4,096) is not
    // refused for them, one without any (a terrain's upper levels) stops as soon as before.
    uint64_t maxVisits() const override {
        return std::min<uint64_t>(kMaxVisits + kVisitsPerCopy * out_.copies_,
                                  std::max<uint64_t>(kMaxVisits, maxBytes_ / kBudgetPerVisit));
    }

    const UnrolledInstance* cut(NodeId select, const PathState& s, uint32_t depth) override {
        const InstanceBoxes& boxes = *scene_.instanceBoxes();
        if (!boxes.unrollAt(select, depth)) return nullptr;
        const UnrollCache::Level level = cache_.level(select, depth);
        if (level.built == 0 || level.refused > 0) return nullptr;  // expanded deeper, if at all
        if (level.off) throw UnrolledInstance::Refused{};  // the cache found them not worth it
        ++out_.copies_;
        const InstanceBoxes::Key k = boxes.keyOf(select, s.frame, s.path);
        const auto [it, added] = index_.try_emplace(Slot{k, depth}, kNone);
        if (dry_) {  // (as the real run refuses, so that unique copies stop it early)
            const size_t n = index_.size();
            if (n > 64 && 2 * n > out_.copies_) throw UnrolledInstance::Refused{};
            return &empty_;
        }
        if (!added) return it->second == kNone ? nullptr : out_.owned_[it->second].get();
        std::shared_ptr<const UnrolledInstance> x = instance(k, select, depth, s);
        if (!x || x->bytes() > maxBytes_ / 8) return nullptr;  // (noted: expanded in place)
        if (depth + x->levels() > scene_.graph().scene.settings.maxDepth)
            throw UnrolledInstance::Refused{};  // (the walk raises the error)
        out_.bytes_ += x->bytes();
        it->second = static_cast<uint32_t>(out_.owned_.size());
        out_.owned_.push_back(std::move(x));
        const size_t n = out_.owned_.size();
        if (out_.bytes_ > maxBytes_ || (n > 64 && 2 * n > out_.copies_))
            throw UnrolledInstance::Refused{};
        return out_.owned_.back().get();
    }

  private:
    // The cache's instance of key k (so that it exists once), or, where the cache has none
    // built, one of the top level's own.
    std::shared_ptr<const UnrolledInstance> instance(const InstanceBoxes::Key& k, NodeId select,
                                                     uint32_t depth, const PathState& s) {
        if (auto x = cache_.share(k)) {
            ++out_.shared_;
            return x;
        }
        return UnrolledInstance::expand(scene_, select, depth, s.frame, s.path,
                                        scene_.instanceBoxes()->maxUnrollWeight());
    }

    struct Slot {
        InstanceBoxes::Key key;
        uint32_t depth;
        bool operator==(const Slot&) const = default;
    };
    struct SlotHash {
        size_t operator()(const Slot& s) const { return s.key.a ^ (s.key.b * 31) ^ s.depth; }
    };
    const TraceScene& scene_;
    const UnrollCache& cache_;
    const size_t maxBytes_;
    TopLevel& out_;
    const bool dry_;
    const UnrolledInstance empty_;
    std::unordered_map<Slot, uint32_t, SlotHash> index_;  // into owned_ (kNone: refused)
};

// Where a top level of deferred cuts stops: at the first S-node on a path where the
// expansion cache expands instances (whether or not it has built this one), with the
// instance's exact box (InstanceBoxes), so that a ray reaches the patch it meets through
// one hierarchy instead of the walk above it.
class TopLevel::DeferredCuts final : public UnrolledInstance::Cuts {
  public:
    DeferredCuts(const TraceScene& scene, const UnrollCache& cache, size_t maxBytes)
        : scene_(scene),
          cache_(cache),
          maxBytes_(maxBytes),
          worker_(scene.instanceBoxes()->makeWorker()) {}

    uint64_t maxVisits() const override { return maxBytes_ / kBytesPerDeferredVisit; }
    const UnrolledInstance* cut(NodeId, const PathState&, uint32_t) override { return nullptr; }
    bool defer(NodeId select, const PathState& s, uint32_t depth, Box& box,
               InstanceBoxes::Key& key) override {
        const InstanceBoxes& boxes = *scene_.instanceBoxes();
        if (!boxes.unrollAt(select, depth)) return false;
        const UnrollCache::Level level = cache_.level(select, depth);
        if (level.refused > 0 || level.off || !expandsAt(depth)) return false;  // (deeper)
        key = boxes.keyOf(select, s.frame, s.path);
        box = boxes.box(*worker_, key, select, depth, s.frame, s.path);
        return true;
    }

    // Whether the cache expands at some depth (else there is nowhere to cut).
    bool anywhere() {
        for (uint32_t d = 0; d <= scene_.graph().scene.settings.maxDepth; ++d)
            if (expandsAt(d)) return true;
        return false;
    }

  private:
    // Whether the cache has built instances at this depth, of any module, and not stopped
    // expanding there (the terrain's two triangle modules reach a depth together, but the
    // first rays may have built patches of one only).
    bool expandsAt(uint32_t depth) {
        if (depth >= expands_.size()) expands_.resize(depth + 1, -1);
        if (expands_[depth] < 0) {
            expands_[depth] = 0;
            const Graph& g = scene_.graph();
            for (NodeId n = 0; n < g.nodes.size(); ++n) {
                if (g.nodes[n].kind != NodeKind::Select) continue;
                const UnrollCache::Level l = cache_.level(n, depth);
                if (l.built > 0 && l.refused == 0 && !l.off) expands_[depth] = 1;
            }
        }
        return expands_[depth] == 1;
    }

    const TraceScene& scene_;
    const UnrollCache& cache_;
    const size_t maxBytes_;
    InstanceBoxes::WorkerPtr worker_;
    std::vector<int8_t> expands_;  // per depth: expandsAt's answer (-1: not asked yet)
};

std::unique_ptr<TopLevel> TopLevel::build(const TraceScene& scene, const UnrollCache& cache,
                                          size_t maxBytes, bool* manyCopies) {
    if (!scene.instanceBoxes() || maxBytes == 0) return nullptr;
    auto t = std::make_unique<TopLevel>();
    Cuts dry(scene, cache, maxBytes, *t, true);
    const bool whole = UnrolledInstance::expandTop(scene, dry) != nullptr;
    const bool shared = dry.instances() > 0 && 2 * dry.instances() <= t->copies_;
    const bool many = !whole && shared && t->copies_ > kManyCopies;
    if (manyCopies) *manyCopies = many;
    if (!whole || !shared) return many ? nullptr : buildDeferred(scene, cache, maxBytes);
    t->copies_ = 0;
    Cuts cuts(scene, cache, maxBytes, *t, false);
    t->top_ = UnrolledInstance::expandTop(scene, cuts);
    if (!t->top_ || t->top_->empty() || t->owned_.empty()) return nullptr;
    t->bytes_ += t->top_->bytes();
    if (t->bytes_ > maxBytes) return nullptr;
    return t;
}

// A top level whose cuts are deferred (DeferredCuts), for a scene whose instances where the
// cache expands are all but unique (a terrain's patches): nullptr where it is refused
// (more than maxBytes, or no cut).
std::unique_ptr<TopLevel> TopLevel::buildDeferred(const TraceScene& scene, const UnrollCache& cache,
                                                  size_t maxBytes) {
    if (!scene.paintFrames.empty()) return nullptr;  // (the walk records paint frames)
    DeferredCuts cuts(scene, cache, maxBytes);
    if (!cuts.anywhere()) return nullptr;
    auto t = std::make_unique<TopLevel>();
    t->top_ = UnrolledInstance::expandTop(scene, cuts);
    if (!t->top_ || t->top_->empty() || t->top_->deferredNodes() == 0) return nullptr;
    t->bytes_ = t->top_->bytes();
    if (t->bytes_ > maxBytes) return nullptr;
    return t;
}

}  // namespace pcsg::tracer
