// The walk of rays through the cyclic graph: see traversal.h.
#include "traversal.h"

#include <fmt/format.h>
#include <pthread.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>

#include "operators.h"
#include "sanitizer.h"
#include "transparency.h"

namespace pcsg::tracer {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

constexpr size_t kBytesPerVisit = kAddressSanitizer ? 4096 : 512;

// Room left below the guard for a primitive's intersection, the evaluation code and an
// exception's unwinding.
constexpr uintptr_t kStackMargin = 256 * 1024;

uintptr_t threadStackLimit() {
    static thread_local uintptr_t limit = [] {
        pthread_attr_t attr;
        if (pthread_getattr_np(pthread_self(), &attr) != 0) return uintptr_t(0);
        void* addr = nullptr;
        size_t size = 0;
        const bool ok = pthread_attr_getstack(&attr, &addr, &size) == 0;
        pthread_attr_destroy(&attr);
        return ok ? reinterpret_cast<uintptr_t>(addr) + kStackMargin : uintptr_t(0);
    }();
    return limit;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// TraceScene

// Materials whose pigment has a pattern need the hit point in their paint node's frame;
// those with a normal pattern also the map into it. In scenes with transparency every
// paint node records its instance (the interiors of transparency.h). Other scenes
// record nothing.
void TraceScene::markPaintFrames() {
    std::vector<uint8_t> marks(g_.materials.size(), 0);
    bool any = false;
    interiors = anyTransparent(g_);
    for (size_t i = 0; i < marks.size(); ++i) {
        const Material& m = g_.materials[i];
        if (interiors) marks[i] |= kPaintInterior;
        if (m.pigment.pattern.kind != PatternKind::Plain) marks[i] |= kPaintPoint;
        if (m.normal.kind != NormalKind::None) marks[i] |= kPaintPoint | kPaintMap;
        any = any || marks[i] != 0;
        paintMaps = paintMaps || (marks[i] & kPaintMap);
    }
    if (any) paintFrames = std::move(marks);
}

namespace {

// Whether the first hit below node m is one primitive's, found without evaluating anything:
// a chain of paint nodes and constant T-nodes down to a primitive without arguments.
bool cheapLeaf(const Graph& g, NodeId m) {
    for (uint32_t k = 0; k < g.nodes.size(); ++k) {
        const Node& node = g.nodes[m];
        if (node.kind == NodeKind::Primitive)
            return primitiveArgCount(g.primitives[node.payload].kind) == 0;
        const bool step = node.kind == NodeKind::Paint ||
                          (node.kind == NodeKind::Transform && g.transforms[node.payload].constant);
        if (!step) return false;
        m = g.child(m);
    }
    return false;
}

}  // namespace

void TraceScene::markUnionLeads() {
    unionLeads.assign(g_.nodes.size(), 0);
    for (NodeId n = 0; n < g_.nodes.size(); ++n) {
        const Node& node = g_.nodes[n];
        if (node.kind != NodeKind::Operator || node.op() != CsgOp::Union) continue;
        uint32_t lead = 0;
        bool other = false;
        for (uint32_t i = 0; i < node.childCount; ++i) {
            if (i < 32 && cheapLeaf(g_, g_.child(n, i)))
                lead |= 1u << i;
            else
                other = true;
        }
        if (other) unionLeads[n] = lead;
    }
}

TraceScene::TraceScene(const Graph& g, Bounds bounds, bool useInstanceBoxes,
                       const InstanceBoxOptions& instanceBoxOptions)
    : TraceScene(g, std::move(bounds), useInstanceBoxes, instanceBoxOptions, FixedSlots(g)) {}

// The tracer's walks all start at the axiom: their memo keys and the instance keys leave
// out the fixed slots (the terrain's C-nodes then read few enough values to be memoised
// at all).
TraceScene::TraceScene(const Graph& g, Bounds bounds, bool useInstanceBoxes,
                       const InstanceBoxOptions& instanceBoxOptions, const FixedSlots& fixed)
    : g_(g), sem_(g), memoPlan_(g, &fixed), bounds_(std::move(bounds)) {
    const size_t n = g.nodes.size();
    if (bounds_.node.size() != n) bounds_.node.assign(n, Box::everything());
    markPaintFrames();
    markUnionLeads();
    if (useInstanceBoxes && !g.modules.empty())
        instanceBoxes_ = std::make_unique<InstanceBoxes>(g, bounds_, instanceBoxOptions, fixed);
    // Longest chain of nested visits between two S-nodes (the graph without the edges into
    // S-nodes is acyclic), then the whole walk's bound.
    std::vector<uint32_t> indeg(n, 0), order;
    for (NodeId m = 0; m < n; ++m)
        for (uint32_t i = 0; i < g.nodes[m].childCount; ++i)
            if (g.nodes[g.child(m, i)].kind != NodeKind::Select) ++indeg[g.child(m, i)];
    std::deque<NodeId> q;
    for (NodeId m = 0; m < n; ++m)
        if (indeg[m] == 0) q.push_back(m);
    while (!q.empty()) {
        const NodeId m = q.front();
        q.pop_front();
        order.push_back(m);
        for (uint32_t i = 0; i < g.nodes[m].childCount; ++i) {
            const NodeId c = g.child(m, i);
            if (g.nodes[c].kind != NodeKind::Select && --indeg[c] == 0) q.push_back(c);
        }
    }
    std::vector<uint64_t> longest(n, 1);
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        const NodeId m = *it;
        for (uint32_t i = 0; i < g.nodes[m].childCount; ++i) {
            const NodeId c = g.child(m, i);
            const uint64_t below = g.nodes[c].kind == NodeKind::Select ? 1 : longest[c];
            longest[m] = std::max(longest[m], below + 1);
        }
    }
    uint64_t k = 1;
    for (uint64_t l : longest) k = std::max(k, l);
    if (order.size() != n) k = n + 1;  // not acyclic between S-nodes: be generous
    recursionBound_ = (static_cast<uint64_t>(g.scene.settings.maxDepth) + 2) * k;
}

size_t TraceScene::stackBytesNeeded() const {
    const double bytes = static_cast<double>(recursionBound_) * kBytesPerVisit + 4.0 * 1024 * 1024;
    return static_cast<size_t>(std::min(bytes, 64.0 * 1024 * 1024 * 1024));
}

// ---------------------------------------------------------------------------------------
// Tracer

Tracer::FrameStack::FrameStack(size_t frameSize)
    : frameSize_(std::max<size_t>(frameSize, 1)),
      perBlock_(std::max<size_t>(4096 / frameSize_, 16)),
      slot_(perBlock_) {}

// The top block is full (or there is none): the next one, made the first time.
void Tracer::FrameStack::nextBlock() {
    const size_t b = used_ / perBlock_;
    if (b == blocks_.size()) blocks_.push_back(std::make_unique<double[]>(perBlock_ * frameSize_));
    block_ = blocks_[b].get();
    slot_ = 0;
}

// The top block became empty: the one below it, full.
void Tracer::FrameStack::previousBlock() {
    slot_ = perBlock_;
    block_ = used_ == 0 ? nullptr : blocks_[used_ / perBlock_ - 1].get();
}

Tracer::Tracer(const TraceScene& scene)
    : scene_(scene), g_(scene.g_), frames_(scene.g_.slotCount()) {
    rootFrame_.assign(std::max<size_t>(g_.slotCount(), 1), 0.0);
    initFrame(g_, rootFrame_.data());
    if (scene.instanceBoxes_) boxWorker_ = scene.instanceBoxes_->makeWorker();
    if (scene.stepMemoLog2 > 0)
        memo_ = std::make_unique<StepMemo>(g_, scene.memoPlan_, scene.stepMemoLog2);
    if (scene.instanceBoxes_ && scene.expansionBytes > 0) {
        expansion_ = std::make_unique<UnrollCache::Reader>(scene.expansionCache());
        expansion_->scratch().walker = this;
    }
}

Tracer::~Tracer() = default;

UnrollCache& TraceScene::expansionCache() const {
    std::call_once(expansionOnce_, [this] {
        expansionCache_ = std::make_unique<UnrollCache>(*this, expansionBytes, expansionStartBytes);
    });
    return *expansionCache_;
}

size_t TraceScene::expansionBudget() const {
    return expansionCache_ ? expansionCache_->budget() : 0;
}

const TopLevel* TraceScene::buildTopLevel(uint32_t maxTries) const {
    if (const TopLevel* t = topLevel()) return t;
    if (!useBounds || !instanceBoxes_ || expansionBytes == 0 || !twoLevel) return nullptr;
    if (beforeTopLock) beforeTopLock();
    const std::unique_lock lock(topMutex_, std::try_to_lock);
    if (!lock.owns_lock()) return nullptr;
    // Again under the lock: another tracer may have built it between the look above and
    // the lock, and building it again would free the one published, which other tracers
    // may be tracing (a rare crash in frame sequences: a ray in the freed top level).
    if (const TopLevel* t = topLevel()) return t;
    if (topTries_ >= maxTries) return nullptr;
    ++topTries_;
    bool manyCopies = false;
    try {
        topOwned_ = TopLevel::build(*this, expansionCache(), expansionBytes, &manyCopies);
    } catch (const RuntimeError&) {
        return nullptr;  // (the walk raises it where a ray meets it)
    }
    // Too many copies of small instances (Sierpinski order 12 cut at the 256-KB instances
    // of a 2 MB budget: 16,384 copies): the level waiting above them gets its budget, so
    // that the next try cuts at a quarter as many copies of its larger instances.
    if (manyCopies) expansionCache().growForWaitingLevel();
    top_.store(topOwned_.get(), std::memory_order_release);
    return topOwned_.get();
}

// The scene's top level, built (tried) once kWalksBeforeTop rays entered the scene through
// the walk, and again, at most every kWalksBeforeTop walks, while the expansion cache makes
// new instances (it cuts only where the cache has expanded).
const TopLevel* Tracer::topLevel() {
    if (!expansion_) return nullptr;  // (its scratch space is the expansions')
    if (const TopLevel* t = scene_.topLevel()) return t;
    if (walks_ < nextTopTry_) return nullptr;
    const uint64_t made = expansion_->cache().expansions();
    if (made == expansionsTried_) return nullptr;
    nextTopTry_ = walks_ + kWalksBeforeTop;
    expansionsTried_ = made;
    return scene_.buildTopLevel();
}

// The unrolled instance to trace instead of walking below S-node n, if there is one: after
// builtAt, which found it not built, its meeting (a note or an expansion; meet() finds an
// instance built meanwhile too, as get() would).
const UnrolledInstance* Tracer::unrolledAt(NodeId n, const Ctx& c, uint32_t depth,
                                           std::optional<InstanceBoxes::Key>& key) {
    if (!expansion_ || !scene_.useBounds || !scene_.instanceBoxes_->unrollAt(n, depth))
        return nullptr;
    if (!key) key = scene_.instanceBoxes_->keyOf(n, c.frame, c.path);
    const UnrolledInstance* x = expansion_->meet(*key, n, depth, c.frame, c.path, anyHit_);
    // Used only where its deepest S-node stays within max_depth (else the walk reports it).
    if (x && depth + x->levels() > g_.scene.settings.maxDepth) return nullptr;
    if (x && anyHit_) occluder_.entering(n, depth, *key);
    return x;
}

// The instance expanded already (by any thread), if there is one: it is traced without its
// exact box from the cache (which, for an instance too small to be stored there, would be
// unrolled again), since the expansion clips rays to a box of its own.
const UnrolledInstance* Tracer::builtAt(NodeId n, const Ctx& c, uint32_t depth,
                                        std::optional<InstanceBoxes::Key>& key) {
    if (!expansion_ || !scene_.useBounds || !scene_.instanceBoxes_->unrollAt(n, depth))
        return nullptr;
    if (!key) key = scene_.instanceBoxes_->keyOf(n, c.frame, c.path);
    const UnrolledInstance* x = expansion_->built(*key, n, depth);
    if (x && depth + x->levels() > g_.scene.settings.maxDepth) return nullptr;
    if (x && anyHit_) occluder_.entering(n, depth, *key);
    return x;
}

// Whether the ray misses the S-node n (at `depth`) within [tmin, tmax]: its box at that
// depth, then (exactCulled), where it pays, the exact box of this instance. The part of
// [tmin, tmax] within the box is left in [t0, t1].
bool Tracer::staticCulled(NodeId n, const LocalRay& r, uint32_t depth, double& t0, double& t1) {
    return scene_.useBounds && !clipToBox(scene_.bounds_.select(g_, n, depth), r, t0, t1);
}

// The instance's key, when computed here, is left in `key` for unrolledAt.
bool Tracer::exactCulled(NodeId n, const LocalRay& r, const Ctx& c, uint32_t depth, double t0,
                         double t1, std::optional<InstanceBoxes::Key>& key) {
    if (!scene_.useBounds) return false;
    const InstanceBoxes* boxes = scene_.instanceBoxes_.get();
    if (!boxes || !boxes->useAt(n, depth)) return false;
    if (!key) key = boxes->keyOf(n, c.frame, c.path);
    const Box exact = boxes->box(*boxWorker_, *key, n, depth, c.frame, c.path);
    return !clipToBox(exact, r, t0, t1);
}

// The walk is below stackLimit_: learns the limit the first time, else throws.
void Tracer::checkStackLimit(uintptr_t here) {
    if (stackLimit_ == UINTPTR_MAX) {
        stackLimit_ = threadStackLimit();
        if (here >= stackLimit_) return;
    }
    throw StackExhausted(fmt::format(
        "the ray tracer's stack is too small for this scene's recursion depth (max_depth {})",
        g_.scene.settings.maxDepth));
}

// The graph walk's own stacks, for a walk from the root or below a top level's Deferred
// nodes (a walk that threw leaves them as they were; the top level's own walk keeps its
// state in the expansions' scratch, and its hits have no paint frame of the graph walk's).
void Tracer::resetWalk() {
    frames_.reset();
    spans_.clear();
    order_.clear();
    paintRays_.clear();
    paintInteriors_.clear();
    paintMaps_.clear();
    inverses_.clear();
}

bool Tracer::walk(const Vec3& origin, const Vec3& dir, double tmin, double tmax, SurfaceHit& out) {
    if (g_.axiom == kNone) return false;
    const UnrollCache::Pin pin(expansion_.get());     // the instances met stay valid till here
    if (expansion_ && !scene_.paintFrames.empty()) {  // (surfaces painted in expansions)
        expansion_->scratch().interiors.clear();
        expansion_->scratch().points.clear();
    }
    const Ctx c{rootFrame_.data(), kRootPath, 0, 0, 0};
    const LocalRay r{origin, dir};
    Hit hit;
    double best = tmax;
    if (const TopLevel* top = topLevel()) {
        if (top->deferred() > 0) {  // (the walk below them, which asks missed())
            resetWalk();
            occluder_.untried();
        }
        if (!top->first(r, tmin, best, hit, anyHit_, expansion_->scratch())) return false;
    } else {
        resetWalk();
        if (anyHit_ && expansion_ &&
            occluder_.occludes(*expansion_, g_.scene.settings.maxDepth, r, tmin, tmax))
            return true;
        if (scene_.useBounds) {
            double t0 = tmin, t1 = tmax;
            if (!clipToBox(scene_.bounds_.node[g_.axiom], origin, dir, t0, t1)) return false;
        }
        ++walks_;
        if (!first(g_.axiom, r, c, tmin, best, hit)) return false;
    }
    out.t = hit.t;
    out.normal = hit.normal;
    out.material = hit.material;
    out.path = hit.key;
    // (painted: the point is in the paint node's frame, for the material's patterns; a
    // material that records only its interior has none, here or in an expansion)
    out.painted = hit.paint != 0 && (scene_.paintFrames[hit.material] & TraceScene::kPaintPoint);
    out.interior = 0;
    if (hit.paint & UnrolledInstance::kScratchPaint) {  // painted inside an expansion
        const UnrolledInstance::Scratch& s = expansion_->scratch();
        const uint32_t k = hit.paint & ~UnrolledInstance::kScratchPaint;
        out.interior = s.interiors[k];
        out.paintPoint = s.points[k];
    } else if (hit.paint != 0) {
        out.interior = paintInteriors_[hit.paint - 1];
        const LocalRay& p = paintRays_[hit.paint - 1];
        out.paintPoint = p.o + p.d * hit.t;
        if (scene_.paintMaps) out.paintMap = &paintMaps_[hit.paint - 1];
    }
    return true;
}

bool Tracer::firstHit(const Vec3& origin, const Vec3& dir, double tmin, double tmax,
                      SurfaceHit& hit) {
    anyHit_ = false;
    return walk(origin, dir, tmin, tmax, hit);
}

bool Tracer::anyHit(const Vec3& origin, const Vec3& dir, double tmin, double tmax) {
    anyHit_ = true;
    SurfaceHit hit;
    return walk(origin, dir, tmin, tmax, hit);
}

// A top level's Deferred node (top_level.h): its S-node instance, the ray in the S-node's
// frame, as unary() hands it on once the instance's boxes have let it through (the top
// level's hierarchy tested the exact box): expanded, or the walk below the S-node. (No
// last occluder: the walk from the root, which would try it, is the top level's now.)
bool Tracer::firstDeferred(const UnrolledInstance::Deferred& d, const double* frame,
                           const LocalRay& r, double tmin, double& tmax, Hit& hit,
                           uint32_t material) {
    const Ctx c{frame, d.path, d.stateDepth, material, 0};
    std::optional<InstanceBoxes::Key> key = d.key;
    try {
        checkStack();
        const UnrolledInstance* x = builtAt(d.select, c, d.depth, key);
        if (!x) x = unrolledAt(d.select, c, d.depth, key);
        if (x)
            return x->first(r, tmin, tmax, hit, {c.path, c.material, 0}, anyHit_,
                            expansion_->scratch());
        StepScratch scratch;
        scratch.memo = memo_.get();
        const Step st = scene_.sem_.enter(d.select, c, scratch);
        return first(st.child, r, st.state, tmin, tmax, hit,
                     operandBoxesOf(d.select, *key, d.depth, st));
    } catch (RuntimeError& e) {
        e.enterModule(g_.modules[g_.nodes[d.select].payload].name);
        throw;
    }
}

// The unary nodes on the way down, shared by first() and spans(): the one step of
// semantics.h, after an S-node's culling by its boxes (or the hand-over to an unrolled
// instance), with the ray mapped into a T-node's child's frame. `below(node, ray, state)`
// walks on from the node the step leads to; `unrolled(x, state)` traces an unrolled
// instance instead; `transformBack(inv, walkBelow)` runs the walk below a T-node and
// brings the normals it found back through the T-node.
template <bool kOperands, class Below, class Unrolled, class TransformBack>
[[gnu::always_inline]] inline auto Tracer::unary(NodeId n, const LocalRay& r, const Ctx& c,
                                                 double tmin, double tmax, Below below,
                                                 Unrolled unrolled, TransformBack transformBack) {
    using Result = decltype(below(n, r, c, nullptr));
    const Semantics& sem = scene_.sem_;
    const NodeKind kind = g_.nodes[n].kind;
    StepScratch scratch;
    scratch.memo = memo_.get();
    if (kind == NodeKind::Select) {
        try {
            const uint32_t depth = sem.selectDepth(n, c);
            checkStack();
            double t0 = tmin, t1 = tmax;
            if (staticCulled(n, r, depth, t0, t1)) return Result{};
            std::optional<InstanceBoxes::Key> key;
            if (const UnrolledInstance* x = builtAt(n, c, depth, key)) return unrolled(*x, c);
            if (exactCulled(n, r, c, depth, t0, t1, key)) return Result{};
            if (const UnrolledInstance* x = unrolledAt(n, c, depth, key)) return unrolled(*x, c);
            const Step st = sem.enter(n, c, scratch);
            const OperandBoxes::Entry* operands =
                kOperands && key ? operandBoxesOf(n, *key, depth, st) : nullptr;
            return below(st.child, r, st.state, operands);
        } catch (RuntimeError& e) {
            e.enterModule(g_.modules[g_.nodes[n].payload].name);
            throw;
        }
    }
    if (kind == NodeKind::Calc) scratch.frame = frames_.push();
    Step st = sem.enter(n, c, scratch);
    if (kind == NodeKind::Paint && !anyHit_ && scene_.paintFrameOf(st.state.material)) {
        paintRays_.push_back(r);  // a paint node keeps the frame: r is the ray in its frame
        // and its instance: the node and its instance path (never 0, the default interior)
        paintInteriors_.push_back(paintInteriorOf(c.path, n));
        st.state.paint = static_cast<uint32_t>(paintRays_.size());
        if (scene_.paintMaps) paintMaps_.push_back(paintMapHere(st.state.material));
    }
    Result found;
    if (st.inverse) {
        const LocalRay rr{st.inverse->point(r.o), st.inverse->vector(r.d)};
        if (scene_.paintMaps || anyHit_) inverses_.push_back(st.inverse);
        found = transformBack(*st.inverse, [&] { return below(st.child, rr, st.state, nullptr); });
        if (scene_.paintMaps || anyHit_) inverses_.pop_back();
    } else {
        found = below(st.child, r, st.state, nullptr);
    }
    if (kind == NodeKind::Calc) frames_.pop();
    return found;
}

// The boxes of the operands of the union that S-node instance (select, key) at `depth` leads
// to by its step `st`, each in the union's frame (operand_boxes.h): computed on the first
// visit of the instance, then found. Null where the step leads to no union of at most
// kMaxOperands operands, or computing a box threw (the walk meets the error itself, where a
// ray reaches it). Not for a union with leading operands either: firstOfUnion walks them
// before it tests the others' boxes, and that walk may reuse this entry's slot.
const OperandBoxes::Entry* Tracer::operandBoxesOf(NodeId select, const InstanceBoxes::Key& key,
                                                  uint32_t depth, const Step& st) {
    const Node& u = g_.nodes[st.child];
    if (!scene_.operandBoxes || u.kind != NodeKind::Operator || u.op() != CsgOp::Union ||
        u.childCount > OperandBoxes::kMaxOperands || scene_.unionLeads[st.child] != 0 ||
        !operandBoxes_.wanted(depth))
        return nullptr;
    if (const OperandBoxes::Entry* e = operandBoxes_.find(select, key, depth)) {
        operandBoxes_.found(depth);
        return e;
    }
    operandBoxes_.computed(depth);
    OperandBoxes::Entry& e = operandBoxes_.slot(key);
    try {
        for (uint32_t i = 0; i < u.childCount; ++i) e.box[i] = operandBox(st.child, i, st.state);
    } catch (const RuntimeError&) {
        return nullptr;
    }
    OperandBoxes::keep(e, select, key, depth);
    return &e;
}

// Operand i of union u (entered in state cu): its box in the union's frame. An operand that
// is a chain of unary steps down to an S-node gets that S-node instance's box (its exact box
// where the instance boxes are used at its depth, else its static box there) mapped up by
// the chain's matrices and padded again for their rounding, so that it holds whatever the
// walk below would find; any other operand its static box, as the union tests it without.
Box Tracer::operandBox(NodeId u, uint32_t i, const Ctx& cu) {
    NodeId m = g_.child(u, i);
    Ctx c = Semantics::operand(cu, i);
    Affine up = Affine::identity();
    StepScratch scratch;
    scratch.memo = memo_.get();
    struct Frames {  // the C-steps' frames, popped however the chain ends
        FrameStack& stack;
        uint32_t pushed = 0;
        ~Frames() {
            while (pushed--) stack.pop();
        }
    } frames{frames_};
    for (NodeKind kind; (kind = g_.nodes[m].kind) != NodeKind::Select;) {
        if (kind == NodeKind::Operator || kind == NodeKind::Primitive)
            return scene_.bounds_.node[g_.child(u, i)];
        if (kind == NodeKind::Calc) scratch.frame = frames_.push(), ++frames.pushed;
        const Step st = scene_.sem_.enter(m, c, scratch);
        if (st.forward) up = up * *st.forward;
        m = st.child, c = st.state;
    }
    const uint32_t depth = scene_.sem_.selectDepth(m, c);
    const InstanceBoxes* boxes = scene_.instanceBoxes_.get();
    const Box b = boxes && boxes->useAt(m, depth)
                      ? boxes->box(*boxWorker_, m, depth, c.frame, c.path)
                      : scene_.bounds_.select(g_, m, depth);
    return paddedBox(transformBox(up, b));
}

// The map from the world into the frame of the paint node being visited, for a material
// with a normal pattern: the T-nodes' inverses above it, composed.
Affine Tracer::paintMapHere(uint32_t material) const {
    Affine m = Affine::identity();
    if (!scene_.paintMapOf(material)) return m;
    for (const Affine* inv : inverses_) m = *inv * m;
    return m;
}

bool Tracer::firstOfSolid(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double& tmax,
                          Hit& hit) {
    const size_t base = spans_.size();
    const size_t count = spans(n, r, c, tmin, tmax);
    const bool found = boundaryHit(spans_, base, count, tmin, tmax, c.path, hit);
    spans_.resize(base);
    if (found) tmax = hit.t;
    return found;
}

bool Tracer::first(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double& tmax, Hit& hit,
                   const OperandBoxes::Entry* operands) {
    ++visits_;
    const Node& node = g_.nodes[n];
    switch (node.kind) {
        case NodeKind::Select:
        case NodeKind::Calc:
        case NodeKind::Transform:
        case NodeKind::Paint:
            return unary<true>(
                n, r, c, tmin, tmax,
                [&](NodeId below, const LocalRay& rr, const Ctx& cc,
                    const OperandBoxes::Entry* ops) {
                    return first(below, rr, cc, tmin, tmax, hit, ops);
                },
                [&](const UnrolledInstance& x, const Ctx& cc) {
                    if (anyHit_ && occluder_.missed(cc.path)) return false;
                    const bool found = x.first(r, tmin, tmax, hit, {cc.path, cc.material, cc.paint},
                                               anyHit_, expansion_->scratch());
                    if (found && anyHit_) occluder_.keep(inverses_, cc.path, cc.material);
                    return found;
                },
                [&](const Affine& inv, auto&& walkBelow) {
                    if (!walkBelow()) return false;
                    hit.normal = inv.transposedVector(hit.normal);
                    return true;
                });
        case NodeKind::Operator:
            if (node.op() != CsgOp::Union) return firstOfSolid(n, r, c, tmin, tmax, hit);
            return firstOfUnion(
                node.childCount, tmin, tmax, hit, anyHit_, order_,
                [&](uint32_t i, double& t0) {
                    double t1 = tmax;
                    const Box& b =
                        operands ? operands->box[i] : scene_.bounds_.node[g_.child(n, i)];
                    return !scene_.useBounds || clipToBox(b, r, t0, t1);
                },
                [&](uint32_t i, double& best, Hit& h) {
                    return first(g_.child(n, i), r, Semantics::operand(c, i), tmin, best, h);
                },
                scene_.unionLeads[n]);
        case NodeKind::Primitive:
            return firstOfPrimitive(n, r, c, tmin, tmax, hit);
    }
    return false;
}

bool Tracer::firstOfPrimitive(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double& tmax,
                              Hit& hit) {
    const PrimitiveKind kind = g_.primitives[g_.nodes[n].payload].kind;
    double args[9] = {};
    scene_.sem_.primitiveArgs(n, c, args);
    if (isTriangle(kind)) {
        Vec3 corners[3];
        triangleCorners(kind, args, corners);
        Boundary b;
        // (tmax widened by one step so that a tie can be seen)
        if (!intersectTriangle(corners[0], corners[1], corners[2], r.o, r.d, tmin,
                               std::nextafter(tmax, kInfinity), b) ||
            !nearer(b.t, c.path, tmax, hit))
            return false;
        hit = Hit{b.t, b.normal, c.material, true, c.path, c.paint};
        tmax = b.t;
        return true;
    }
    Span s[kMaxPrimitiveSpans];
    const int count = intersectSolid(kind, args, r.o, r.d, s);
    for (int k = 0; k < count; ++k) {
        const Boundary* b = s[k].in.t > tmin ? &s[k].in : (s[k].out.t > tmin ? &s[k].out : nullptr);
        if (!b) continue;
        if (!nearer(b->t, c.path, tmax, hit)) return false;
        hit = Hit{b->t, b->normal, c.material, true, c.path, c.paint};
        tmax = b->t;
        return true;
    }
    return false;
}

size_t Tracer::spans(NodeId n, const LocalRay& r, const Ctx& c, double tmin, double tmax) {
    ++visits_;
    const Node& node = g_.nodes[n];
    switch (node.kind) {
        case NodeKind::Select:
        case NodeKind::Calc:
        case NodeKind::Transform:
        case NodeKind::Paint:
            return unary<false>(
                n, r, c, tmin, tmax,
                [&](NodeId below, const LocalRay& rr, const Ctx& cc, const OperandBoxes::Entry*) {
                    return spans(below, rr, cc, tmin, tmax);
                },
                [&](const UnrolledInstance& x, const Ctx& cc) {
                    return x.spans(r, tmin, tmax, spans_, {cc.path, cc.material, cc.paint},
                                   expansion_->scratch());
                },
                [&](const Affine& inv, auto&& walkBelow) {
                    const size_t base = spans_.size();
                    const size_t count = walkBelow();
                    for (size_t k = base; k < base + count; ++k) {
                        spans_[k].in.normal = inv.transposedVector(spans_[k].in.normal);
                        spans_[k].out.normal = inv.transposedVector(spans_[k].out.normal);
                    }
                    return count;
                });
        case NodeKind::Operator:
            return combineOperands(
                node.op(), node.childCount, spans_, tmin, tmax,
                [&](uint32_t i, double lo, double hi) {
                    return !scene_.useBounds ||
                           clipToBox(scene_.bounds_.node[g_.child(n, i)], r, lo, hi);
                },
                [&](uint32_t i, double lo, double hi) {
                    return spans(g_.child(n, i), r, Semantics::operand(c, i), lo, hi);
                });
        case NodeKind::Primitive: {
            const Primitive& p = g_.primitives[node.payload];
            if (isTriangle(p.kind)) return 0;  // surfaces: never under ∩ or \ (the compiler checks)
            double args[9] = {};
            scene_.sem_.primitiveArgs(n, c, args);
            Span s[kMaxPrimitiveSpans];
            const int count = intersectSolid(p.kind, args, r.o, r.d, s);
            for (int k = 0; k < count; ++k) {
                s[k].in.material = s[k].out.material = c.material;
                s[k].in.paint = s[k].out.paint = c.paint;
                spans_.push_back(s[k]);
            }
            return static_cast<size_t>(count);
        }
    }
    return 0;
}

}  // namespace pcsg::tracer
