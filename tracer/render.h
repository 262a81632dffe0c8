// Rendering an image: pixels in tiles, in parallel on thread_pool.h's threads, anti-aliasing. The
// result is linear float RGB; tools/image/ writes it to a file.
//
//  - Rows: the render keeps a window of the rows in flight (pass 1 in bands of 16 rows, and
//    for adaptive sampling the two bands before, being decided and supersampled), not the
//    whole image, and hands each finished row to a RowSink (a 640-wide window is 0.5 MB,
//    the whole image's floats 3.7 MB). render() without a sink collects the rows into
//    RenderResult::rgb.
//  - Every pixel's colour depends only on the pixel (fixed sample positions, no shared
//    mutable state), so the image is the same byte for byte whatever the thread count.
//  - --aa N: N x N stratified samples at the centres of an N x N grid of sub-pixels,
//    averaged with equal weights.
//  - --adaptive T: POV-Ray's +A T (sampling method 1): one sample at each pixel centre;
//    a pixel whose colour differs from a 4-neighbour's by at least T (the sum of the
//    absolute differences of red, green and blue after the gamma 2.5 encoding POV-Ray's
//    Antialias_Gamma uses) gets POV-Ray's extra grid of depth x depth samples (depth 3,
//    no jitter), and its colour is (centre + grid samples) / (depth^2 + 1). The decision
//    is made after all centres are known, so it does not depend on the tiling.
//  - Threads: the walk recurses once per node visit, so the render runs on threads whose
//    stacks are sized from the scene (TraceScene::stackBytesNeeded): a thread of its own
//    with that stack calls the parallel loop, and the pool's threads get the same size
//    through ParallelLimits (thread_pool.h).
//  - A run-time error of the scene (RuntimeError) stops the render: the first error wins
//    (later ones from other threads are dropped), the remaining tiles are skipped, and
//    render() rethrows it. Nothing is written.
//  - Regions: RegionRenderer renders any rectangle of the image with the pixels render()
//    gives it (the distributed renderer's ranks render the tiles they are handed). With
//    adaptive sampling a pixel's pass 2 reads its 4-neighbours' centres, so a region takes
//    the pass-1 samples of a one-pixel border around itself too.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "bounds.h"
#include "graph.h"
#include "instance_boxes.h"
#include "unroll_cache.h"

namespace pcsg::tracer {

struct RenderOptions {
    int width = 640, height = 480;
    int aa = 1;             // N x N stratified samples per pixel (1: the centre only)
    double adaptive = 0;    // > 0: adaptive supersampling threshold (POV-Ray's +A)
    int adaptiveDepth = 3;  // POV-Ray's +R
    int threads = 0;        // 0: all cores
    bool useBounds = true;  // tests compare against rendering without culling
    // The times the hyper-bounding boxes are computed for; none: the graph's time alone.
    // (The image is the same either way: a wider range only culls less.)
    std::optional<TimeRange> boundsTime;
    // Boxes computed beforehand (a sequence's, once for its whole clock range), used
    // instead of computing them here; null: computed here, for boundsTime.
    std::shared_ptr<const Bounds> bounds;
    // Exact boxes of S-node instances where the static ones are loose (instance_boxes.h),
    // kept in a table of at most this many bytes.
    bool instanceBoxes = true;
    size_t instanceBoxBytes = 64u << 20;
    // A sequence's boxes that do not change with the time, kept from frame to frame
    // (SequenceInstanceBoxes, for this graph); null: this render's own table alone.
    std::shared_ptr<SequenceInstanceBoxes> sequenceBoxes;
    // Expanded instances (unrolled_instances.h), in one cache shared by the threads that
    // holds at most this many bytes; 0: none.
    size_t expansionBytes = 16u << 20;
    // Where that cache's budget starts (at most expansionBytes; the budget grows toward it
    // where a larger one saves expansions).
    size_t expansionStartBytes = UnrollCache::kStartBytes;
    // Called from worker threads with the fraction done (0..1); may be empty.
    std::function<void(double)> progress;
    // Called from worker threads after each tile of each pass (1, or 2 for adaptive
    // sampling) with the tile's pixel rectangle and the CPU seconds its thread spent on
    // it (a cost that other load on the machine does not inflate); may be empty.
    std::function<void(int pass, int x0, int y0, int x1, int y1, double seconds)> tileTime;
    // When set and true, the render stops at the next tile and throws RenderCancelled.
    const std::atomic<bool>* cancel = nullptr;
    // Called once, on a worker thread, when the instance boxes have been filled ahead of
    // the first rays (or were not to be), with what the fill counted on the way
    // (InstanceBoxes::prefill; null: nothing); may be empty.
    std::function<void(std::shared_ptr<const KnownCounts>)> prefilled;
};

struct RenderCancelled : std::runtime_error {
    RenderCancelled() : std::runtime_error("the render was cancelled") {}
};

// A rectangle of the image's pixels: [x0, x1) x [y0, y1).
struct Region {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
    size_t pixels() const { return static_cast<size_t>(width()) * height(); }
};

// Where a render's finished rows go: rows(y, rgb) once for each row y of the region, with
// the region's width x 3 linear RGB floats, which are gone when it returns. It is called
// on any of the render's threads, in no set order (different rows at the same time), and
// an exception it throws stops the render as a tile's would.
using RowSink = std::function<void(int y, std::span<const float> rgb)>;

struct RenderResult {
    int width = 0, height = 0;
    std::vector<float> rgb;  // linear RGB, row-major from the top-left (empty with a RowSink)
    uint64_t rays = 0;
    uint64_t nodeVisits = 0;
    double seconds = 0;              // the render proper
    double boundsSeconds = 0;        // computing the hyper-bounding boxes
    uint32_t infiniteBoxes = 0;      // nodes left with unbounded boxes
    InstanceBoxStats instanceBoxes;  // the instance-box cache at the end
    uint64_t expansions = 0;         // sub-graph instances expanded (all threads)
    size_t expansionBudget = 0;      // the bytes the expansion cache's budget grew to
    // The two-level structure (top_level.h), if it was built: its copies of shared
    // instances and those instances, or its cuts deferred to the walk, and its bytes.
    struct TopLevelFigures {
        bool built = false;
        size_t copies = 0, instances = 0, deferred = 0, bytes = 0;
    } topLevel;
};

// Renders the scene's graph. Throws RuntimeError (the first run-time error of the scene)
// or std::runtime_error (the stack cannot be made large enough).
RenderResult render(const Graph& g, const RenderOptions& options);
// The same, each row handed to `rows` as it is finished (the result has no pixels).
RenderResult render(const Graph& g, const RenderOptions& options, const RowSink& rows);

// The scene made ready once (hyper-bounding boxes, trace scene, camera) and rendered a
// region at a time, each region's pixels exactly those render() gives them. The graph
// and options must outlive it.
class RegionRenderer {
  public:
    RegionRenderer(const Graph& g, const RenderOptions& options);
    ~RegionRenderer();
    RegionRenderer(const RegionRenderer&) = delete;
    RegionRenderer& operator=(const RegionRenderer&) = delete;

    // The region's linear RGB, row-major. Throws as render() does; options.progress is
    // called with the fraction of this region done.
    std::vector<float> render(const Region& region);
    // The same, each row handed to `rows` as it is finished.
    void render(const Region& region, const RowSink& rows);

    // The figures so far (no pixels): rays, node visits and expansions of every region,
    // the bounds' time, and `seconds`, the set-up and every region's render.
    RenderResult figures() const;

  private:
    struct State;
    std::unique_ptr<State> state_;
};

}  // namespace pcsg::tracer
