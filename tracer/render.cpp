#include "render.h"

#include <fmt/format.h>
#include <pthread.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "adaptive_encode.h"
#include "bounds.h"
#include "camera.h"
#include "eval.h"
#include "shading.h"
#include "thread_pool.h"
#include "traversal.h"

namespace pcsg::tracer {

namespace {

constexpr int kTile = 16;

// Runs f on a new thread with the given stack size and waits for it; exceptions travel
// back to the caller.
template <class F>
void runWithStack(size_t stackBytes, F& f) {
    struct Ctx {
        F* f;
        std::exception_ptr error;
    } ctx{&f, nullptr};
    pthread_attr_t attr;
    pthread_attr_init(&attr);
    const long page = sysconf(_SC_PAGESIZE);
    stackBytes = (stackBytes + page - 1) / page * page;
    pthread_attr_setstacksize(&attr, stackBytes);
    pthread_t thread;
    auto body = [](void* p) -> void* {
        auto* c = static_cast<Ctx*>(p);
        try {
            (*c->f)();
        } catch (...) {
            c->error = std::current_exception();
        }
        return nullptr;
    };
    const int rc = pthread_create(&thread, &attr, body, &ctx);
    pthread_attr_destroy(&attr);
    if (rc != 0)
        throw std::runtime_error(
            fmt::format("cannot start a render thread with a {} MB stack", stackBytes >> 20));
    pthread_join(thread, nullptr);
    if (ctx.error) std::rethrow_exception(ctx.error);
}

// The calling thread's CPU time: a tile's cost, whatever else runs on the machine.
double threadCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + ts.tv_nsec * 1e-9;
}

struct Worker {
    explicit Worker(const TraceScene& s) : shader(s) {}
    Shader shader;
    // Adaptive sampling: the pass-1 colours of the tile being decided and of its border,
    // encoded by aaEncode through `encode` (`pass` names the pass they belong to).
    std::vector<double> encoded;
    AaEncodeMemo encode;
    Region tile{0, 0, 0, 0}, area{0, 0, 0, 0};
    uint64_t pass = 0;
    std::vector<float> row;  // a row being handed over, its supersampled colours in
};

// Each adaptive pass of a TileRender, numbered (workers outlive a render).
std::atomic<uint64_t> adaptivePasses{0};

// By slot of the pool (thread_pool.h): one thread at a time runs a slot.
using Workers = std::vector<std::unique_ptr<Worker>>;

// One render of a region of the image in tiles of kTile x kTile pixels on the pool's
// threads: pass 1 takes the stratified samples (or the pixel centres) of the region and,
// with adaptive sampling, of a one-pixel border around it (clipped to the image); pass 2
// supersamples where a pixel of the region differs from a 4-neighbour. The first error
// stops the rest. The pixels are the same whatever the region: each depends only on its
// own samples and its neighbours' centres.
class TileRender {
  public:
    TileRender(const TraceScene& scene, const PinholeCamera& camera, const RenderOptions& opt,
               Workers& workers, const Region& region, const RowSink& sink)
        : scene_(scene),
          camera_(camera),
          opt_(opt),
          workers_(workers),
          w_(opt.width),
          h_(opt.height),
          region_(region),
          halo_(opt.adaptive > 0 ? Region{std::max(0, region.x0 - 1), std::max(0, region.y0 - 1),
                                          std::min(w_, region.x1 + 1), std::min(h_, region.y1 + 1)}
                                 : region),
          totalWork_(opt.adaptive > 0 ? bandCount() * (tilesAcross(halo_) + tilesAcross(region_))
                                      : tileCount(halo_)),
          near_(opt.adaptive),
          sink_(sink),
          windowRows_(std::min(halo_.height(), kWindowRows)) {
        rgb_.assign(static_cast<size_t>(windowRows_) * halo_.width() * 3, 0.0f);
        sampled_ = std::make_unique<std::atomic<int>[]>(tilesAcross(halo_));
        if (opt.adaptive <= 0) return;
        const size_t width = region_.width();
        const size_t rows = std::min(region_.height(), kDecidedRows);
        differs_.assign(rows * width, 0);
        super_.assign(rows * width * 3, 0.0f);
    }

    // Runs both passes on the calling thread's pool, handing the region's rows to the sink;
    // rethrows the first error.
    // `first` runs on the pool before the first tile.
    void run(size_t stackBytes, const std::function<void()>& first) {
        const ParallelLimits limits(opt_.threads, stackBytes);
        if (workers_.size() < static_cast<size_t>(parallelSlots()))
            workers_.resize(parallelSlots());
        first();
        renderInBands();
        if (firstError_) std::rethrow_exception(firstError_);
        if (stop_) throw RenderCancelled();
    }

  private:
    // The hand-over of finished rows to the sink: not a pass of its own for tileTime and
    // progress (passes 1 and 2 are the samples; pass 2 decides its pixels too).
    static constexpr int kEmit = 3;
    // The rows of the image kept at once (the window): those of the band in pass 1 with
    // the border rows above and below it, and the rows decided in the step before, which
    // are being handed over. (34 are in use at most: the last band's border row below is
    // written in the step that hands over the row 33 above it.)
    static constexpr int kWindowRows = 2 * kTile + 2;
    // The rows of differs_ and super_: those decided in two steps (the last has a row more).
    static constexpr int kDecidedRows = 2 * kTile + 2;

    struct Job {
        int pass;
        Region tile;
    };

    static int tileCount(const Region& r) {
        return ((r.width() + kTile - 1) / kTile) * ((r.height() + kTile - 1) / kTile);
    }

    static int tilesAcross(const Region& r) { return (r.width() + kTile - 1) / kTile; }
    int bandCount() const { return (region_.height() + kTile - 1) / kTile; }

    // The region in bands of kTile rows, each band's rows handed to the sink in the step
    // after its pass 1, so that the image is kept as a window of kWindowRows rows (0.26 MB
    // at 640 wide, where the whole image's floats were 3.7 MB). Step k runs, on the pool,
    // pass 1 of band k (with the image's border row above band 0 and below the last) beside
    // the hand-over of the rows finished in step k-1.
    //
    // Adaptive sampling (POV-Ray's +A, method 1) decides and supersamples, in step k, the
    // rows whose neighbours' centres are then all in: band k shifted up a row
    // (decidedRows(k)), a tile as soon as pass 1 has passed the tiles beside it, so that
    // its rays find the expansions pass 1's rays made a moment before still in the cache
    // (a terrain's patches: two whole-image passes had rebuilt nearly every patch, and
    // pass 2 two bands behind pass 1 still 60% of them). The supersampled colours go to
    // super_, not over the centres the next rows' decisions read; the hand-over takes
    // them from there. Each pixel depends only on its own samples and its neighbours'
    // centres, so the image is the one two whole passes give.
    void renderInBands() {
        const int bands = bandCount();
        const bool adaptive = opt_.adaptive > 0;
        for (int k = 0; k <= bands && !stop_; ++k) {
            std::vector<Job> jobs;
            if (k < bands) addBandJobs(jobs, k, adaptive);
            if (k >= 1) addRows(jobs, adaptive ? decidedRows(k - 1) : bandRows(k - 1, false));
            const uint64_t pass = ++adaptivePasses;  // (a worker's encoded tile: this step's)
            runJobs(jobs, [&](Worker& wk, int jobPass, int y, int x0, int x1) {
                if (jobPass == 1) return sampleRow(wk, y, x0, x1);
                if (jobPass == 2) return superRow(wk, pass, y, x0, x1);
                emitRow(wk, y, x0, x1, adaptive);
            });
        }
    }

    // Band k's pass-1 tiles, column by column, and with adaptive sampling the tiles of
    // decidedRows(k) (pass 2), each after the column that follows the last it waits for.
    void addBandJobs(std::vector<Job>& jobs, int k, bool adaptive) {
        const Region area = bandRows(k, true);
        const int columns = tilesAcross(area);
        sampleRowsOfTiles_ = (area.height() + kTile - 1) / kTile;
        for (int c = 0; c < columns; ++c) sampled_[c].store(0, std::memory_order_relaxed);
        const Region rows = decidedRows(k);
        int next = 0;  // the next tile of `rows` to add
        for (int c = 0; c <= columns; ++c) {
            for (int y0 = area.y0; c < columns && y0 < area.y1; y0 += kTile) {
                const int x0 = area.x0 + c * kTile;
                jobs.push_back({1, Region{x0, y0, std::min(area.x1, x0 + kTile),
                                          std::min(area.y1, y0 + kTile)}});
            }
            for (; adaptive && next < tilesAcross(rows); ++next) {
                const Region t = superTile(rows, next);
                if (c < columns && sampledColumns(t).second >= c) break;
                jobs.push_back({2, t});
            }
        }
    }

    // Tile i of the decided rows (all of them: a row or two more than kTile at most).
    static Region superTile(const Region& rows, int i) {
        const int x0 = rows.x0 + i * kTile;
        return Region{x0, rows.y0, std::min(rows.x1, x0 + kTile), rows.y1};
    }

    // The first and last column of pass-1 tiles whose centres the decisions of tile t read.
    std::pair<int, int> sampledColumns(const Region& t) const {
        const int last = tilesAcross(halo_) - 1;
        return {std::max(0, (t.x0 - 1 - halo_.x0) / kTile),
                std::min(last, (std::min(t.x1, halo_.x1 - 1) - halo_.x0) / kTile)};
    }

    // Waits until pass 1 has finished the columns of tiles that pass-2 tile t reads (they
    // were handed out before it: a thread that waits here never waits for itself).
    void awaitSampled(const Region& t) {
        const auto [c0, c1] = sampledColumns(t);
        for (int c = c0; c <= c1; ++c)
            while (sampled_[c].load(std::memory_order_acquire) < sampleRowsOfTiles_ && !stop_)
                std::this_thread::yield();
    }

    // The rows decided in step k: band k shifted up a row (their neighbours below are then
    // in band k), from the region's first row and to its last.
    Region decidedRows(int k) const {
        const Region band = bandRows(k, false);
        return Region{band.x0, std::max(region_.y0, band.y0 - 1), band.x1,
                      band.y1 == region_.y1 ? band.y1 : band.y1 - 1};
    }

    // Band b's rows of the region (with the image's border rows of pass 1 when `halo`).
    Region bandRows(int b, bool halo) const {
        Region r{region_.x0, region_.y0 + b * kTile, region_.x1,
                 std::min(region_.y1, region_.y0 + (b + 1) * kTile)};
        if (!halo) return r;
        r.x0 = halo_.x0, r.x1 = halo_.x1;
        if (b == 0) r.y0 = halo_.y0;
        if (r.y1 == region_.y1) r.y1 = halo_.y1;
        return r;
    }

    // Pass 2 over pixels [x0, x1) of decided row y: each pixel's decision, and where it
    // differs, its supersampled colour into super_.
    void superRow(Worker& wk, uint64_t pass, int y, int x0, int x1) {
        for (int x = x0; x < x1; ++x) {
            const bool differs = differsFromNeighbour(wk, pass, x, y);
            differs_[decidedIndex(x, y)] = differs;
            if (differs) supersamplePixel(wk, x, y, super_.data() + decidedIndex(x, y) * 3);
        }
    }

    // Hands over pixels [x0, x1) of row y: the centres, or with adaptive sampling the
    // supersampled colours where they differ (in the worker's row).
    void emitRow(Worker& wk, int y, int x0, int x1, bool adaptive) {
        const float* p = pixelAt(x0, y);
        const size_t n = static_cast<size_t>(x1 - x0) * 3;
        if (!adaptive) return sink_(y, {p, n});
        wk.row.assign(p, p + n);
        for (int x = x0; x < x1; ++x)
            if (differs_[decidedIndex(x, y)])
                std::copy_n(super_.data() + decidedIndex(x, y) * 3, 3, &wk.row[(x - x0) * 3]);
        sink_(y, {wk.row.data(), n});
    }

    // The hand-over of each of the area's rows, a job each.
    static void addRows(std::vector<Job>& jobs, const Region& area) {
        for (int y = area.y0; y < area.y1; ++y)
            jobs.push_back({kEmit, Region{area.x0, y, area.x1, y + 1}});
    }

    // Runs row(worker, pass, y, x0, x1) over each job's tile, in parallel.
    template <class Row>
    void runJobs(const std::vector<Job>& jobs, Row&& row) {
        parallelFor(jobs.size(), [&](size_t j, int slot) {
            const int pass = jobs[j].pass;
            const Region& t = jobs[j].tile;
            auto rowOfPass = [&](Worker& wk, int y, int x0, int x1) { row(wk, pass, y, x0, x1); };
            if (pass == 2) awaitSampled(t);
            runTile(slot, pass, t, rowOfPass);
            if (pass == 1)
                sampled_[(t.x0 - halo_.x0) / kTile].fetch_add(1, std::memory_order_release);
        });
    }

    // One tile; false when the render stops (an error here or elsewhere).
    template <class Row>
    bool runTile(int slot, int pass, const Region& t, Row& row) {
        if (stop_.load(std::memory_order_relaxed)) return false;
        if (opt_.cancel && opt_.cancel->load(std::memory_order_relaxed)) {
            stop_ = true;
            return false;
        }
        auto& wp = workers_[slot];
        if (!wp) wp = std::make_unique<Worker>(scene_);
        const double start = opt_.tileTime ? threadCpuSeconds() : 0.0;
        try {
            for (int y = t.y0; y < t.y1; ++y) row(*wp, y, t.x0, t.x1);
        } catch (...) {
            std::lock_guard<std::mutex> lock(errorMutex_);
            if (!firstError_) firstError_ = std::current_exception();
            stop_ = true;
            return false;
        }
        if (pass == kEmit) return true;
        if (opt_.tileTime) opt_.tileTime(pass, t.x0, t.y0, t.x1, t.y1, threadCpuSeconds() - start);
        const int d = ++done_;
        if (opt_.progress) opt_.progress(static_cast<double>(d) / totalWork_);
        return true;
    }

    // Pixel (x, y)'s index in differs_ (and its colour's in super_), which hold the rows
    // decided in two steps.
    size_t decidedIndex(int x, int y) const {
        return static_cast<size_t>((y - region_.y0) % kDecidedRows) * region_.width() +
               (x - region_.x0);
    }

    // Pixel (x, y) of the image in the window: row y of halo_ is row y mod windowRows_.
    float* pixelAt(int x, int y) {
        return rgb_.data() + (static_cast<size_t>((y - halo_.y0) % windowRows_) * halo_.width() +
                              (x - halo_.x0)) *
                                 3;
    }
    const float* pixelAt(int x, int y) const {
        return const_cast<TileRender*>(this)->pixelAt(x, y);
    }

    void store(int x, int y, const Vec3& c) {
        float* p = pixelAt(x, y);
        p[0] = static_cast<float>(c.x), p[1] = static_cast<float>(c.y),
        p[2] = static_cast<float>(c.z);
    }

    // Pass 1 over pixels [x0, x1) of row y: aa x aa stratified samples (the centre when aa
    // is 1). The camera rays of a pixel, or with aa 1 of the row's pixels, are made before
    // any is shaded: each waits on a chain of divisions and a square root, which one ray at
    // a time left exposed (13% of the time of frame 1 of the growing tree), and a batch
    // overlaps. The same rays, shaded and summed in the same order.
    void sampleRow(Worker& wk, int y, int x0, int x1) {
        const int aa = std::max(1, opt_.aa);
        if (aa == 1) {
            Ray rays[kTile];
            for (int x = x0; x < x1; x += kTile) {
                const int n = std::min(x1 - x, kTile);
                for (int k = 0; k < n; ++k) rays[k] = camera_.ray(x + k + 0.5, y + 0.5);
                for (int k = 0; k < n; ++k) {
                    Vec3 sum{0, 0, 0};
                    sum += wk.shader.shade(rays[k]);
                    store(x + k, y, sum / 1.0);
                }
            }
            return;
        }
        for (int x = x0; x < x1; ++x) {
            const Vec3 sum = shadeSamples(wk, aa * aa, Vec3{0, 0, 0}, [&](int s) {
                const int i = s % aa, j = s / aa;
                return camera_.ray(x + (i + 0.5) / aa, y + (j + 0.5) / aa);
            });
            store(x, y, sum / static_cast<double>(aa * aa));
        }
    }

    // `sum` plus the colours of samples 0 .. n-1, the rays rayOf(s) made kTile at a time
    // before they are shaded, in order.
    template <class RayOf>
    Vec3 shadeSamples(Worker& wk, int n, Vec3 sum, RayOf rayOf) {
        Ray rays[kTile];
        for (int first = 0; first < n; first += kTile) {
            const int batch = std::min(n - first, kTile);
            for (int k = 0; k < batch; ++k) rays[k] = rayOf(first + k);
            for (int k = 0; k < batch; ++k) sum += wk.shader.shade(rays[k]);
        }
        return sum;
    }

    // The pass-1 colours encoded by aaEncode (each pixel is compared with up to four
    // neighbours): once per pixel of the tile of (x, y) and its border, kept by the worker
    // while it decides that tile's pixels (a few KB, not a copy of the image).
    const double* encodedTile(Worker& wk, uint64_t pass, int x, int y) const {
        const Region& t = wk.tile;
        if (wk.pass != pass || x < t.x0 || x >= t.x1 || y < t.y0 || y >= t.y1) {
            const int x0 = region_.x0 + (x - region_.x0) / kTile * kTile;
            const int y0 = region_.y0 + (y - region_.y0) / kTile * kTile;
            wk.pass = pass;
            wk.tile = Region{x0, y0, x0 + kTile, y0 + kTile};
            wk.area =
                Region{std::max(halo_.x0, x0 - 1), std::max(halo_.y0, y0 - 1),
                       std::min(halo_.x1, x0 + kTile + 1), std::min(halo_.y1, y0 + kTile + 1)};
            wk.encoded.resize(wk.area.pixels() * 3);
            double* e = wk.encoded.data();
            for (int v = wk.area.y0; v < wk.area.y1; ++v) {
                const float* c = pixelAt(wk.area.x0, v);
                for (int k = 0; k < wk.area.width() * 3; ++k) *e++ = wk.encode(c[k]);
            }
        }
        return wk.encoded.data();
    }

    // Adaptive sampling (POV-Ray's +A, method 1): whether pixel (x, y)'s centre differs
    // from a 4-neighbour's by the threshold or more. Reads pass 1's centres; encodes them
    // only where a neighbour is not near (NearColours), which most pixels are not.
    bool differsFromNeighbour(Worker& wk, uint64_t pass, int x, int y) const {
        const int r = (y - halo_.y0) % windowRows_;  // (one division for the three rows)
        const ptrdiff_t row = static_cast<ptrdiff_t>(halo_.width()) * 3;
        const float* p = rgb_.data() + r * row + (x - halo_.x0) * 3;
        const float* up = r > 0 ? p - row : p + (windowRows_ - 1) * row;
        const float* down = r + 1 < windowRows_ ? p + row : p - (windowRows_ - 1) * row;
        // (a neighbour outside the image is the pixel itself, which is near)
        if (near_(p, x > 0 ? p - 3 : p) && near_(p, x + 1 < w_ ? p + 3 : p) &&
            near_(p, y > 0 ? up : p) && near_(p, y + 1 < h_ ? down : p))
            return false;
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        const double* encoded = encodedTile(wk, pass, x, y);
        auto at = [&](int px, int py) {  // (the neighbours of the tile's pixels are in area)
            return encoded +
                   (static_cast<size_t>(py - wk.area.y0) * wk.area.width() + (px - wk.area.x0)) * 3;
        };
        for (int k = 0; k < 4; ++k) {
            if (nx[k] < 0 || nx[k] >= w_ || ny[k] < 0 || ny[k] >= h_) continue;
            if (colourDistance(at(x, y), at(nx[k], ny[k])) >= opt_.adaptive) return true;
        }
        return false;
    }

    // Pass 2 of adaptive sampling, where a pixel differs: depth x depth more samples,
    // averaged with its centre, into `out` (the image's pixel is written once the
    // neighbours' decisions have read its centre).
    void supersamplePixel(Worker& wk, int x, int y, float* out) {
        const float* c = pixelAt(x, y);
        const int depth = std::max(1, opt_.adaptiveDepth);
        const double step = 1.0 / depth, range = 0.5 - step * 0.5;
        // (the rays made first, as sampleRow's)
        const Vec3 sum = shadeSamples(wk, depth * depth, Vec3{c[0], c[1], c[2]}, [&](int s) {
            const int i = s % depth, j = s / depth;
            return camera_.ray(x + 0.5 - range + i * step, y + 0.5 - range + j * step);
        });
        const Vec3 c2 = sum / static_cast<double>(depth * depth + 1);
        out[0] = static_cast<float>(c2.x), out[1] = static_cast<float>(c2.y),
        out[2] = static_cast<float>(c2.z);
    }

    const TraceScene& scene_;
    const PinholeCamera& camera_;
    const RenderOptions& opt_;
    Workers& workers_;
    const int w_, h_;
    const Region region_, halo_;
    const int totalWork_;
    const NearColours near_;  // neighbours that cannot differ at the threshold
    const RowSink& sink_;
    const int windowRows_;
    std::vector<float> rgb_;        // the window: windowRows_ rows of halo_'s pixels
    std::vector<uint8_t> differs_;  // adaptive sampling: the decisions (decidedIndex)
    std::vector<float> super_;      // and the supersampled colours where they differ
    // Step k's pass-1 tiles finished, by column, and how many rows of tiles a column has.
    std::unique_ptr<std::atomic<int>[]> sampled_;
    int sampleRowsOfTiles_ = 0;
    std::mutex errorMutex_;
    std::exception_ptr firstError_;
    std::atomic<bool> stop_{false};
    std::atomic<int> done_{0};
};

}  // namespace

struct RegionRenderer::State {
    State(const Graph& g, const RenderOptions& o, Bounds bounds, const InstanceBoxOptions& boxes)
        : opt(o),
          scene(g, std::move(bounds), o.instanceBoxes, boxes),
          camera(g.scene.camera, o.width, o.height) {}
    const RenderOptions& opt;
    TraceScene scene;
    const PinholeCamera camera;
    Workers workers;
    RenderResult figures;  // no pixels
    std::once_flag prefilled;
    // The instance boxes filled ahead of the first region's rays (InstanceBoxes::prefill).
    void prefill() {
        std::call_once(prefilled, [this] {
            const InstanceBoxes* boxes = scene.instanceBoxes();
            std::shared_ptr<const KnownCounts> counts;
            if (boxes && scene.useBounds) counts = boxes->prefill(scene.graph().axiom, opt.cancel);
            if (opt.prefilled) opt.prefilled(std::move(counts));
        });
    }
};

namespace {

Bounds boundsFor(const Graph& g, const RenderOptions& opt, RenderResult& figures) {
    const auto t0 = std::chrono::steady_clock::now();
    BoundsOptions boundsOptions;
    boundsOptions.time = opt.boundsTime;
    Bounds bounds = opt.bounds ? *opt.bounds : computeBounds(g, boundsOptions);
    figures.infiniteBoxes = bounds.infiniteNodes;
    figures.boundsSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return bounds;
}

InstanceBoxOptions boxOptionsFor(const RenderOptions& opt) {
    InstanceBoxOptions boxOptions;
    boxOptions.maxBytes = opt.instanceBoxBytes;
    boxOptions.sequence = opt.sequenceBoxes;
    return boxOptions;
}

}  // namespace

RegionRenderer::RegionRenderer(const Graph& g, const RenderOptions& opt) {
    if (opt.width <= 0 || opt.height <= 0)
        throw std::invalid_argument("image size must be positive");
    RenderResult figures;
    figures.width = opt.width;
    figures.height = opt.height;
    Bounds bounds = boundsFor(g, opt, figures);
    const auto t1 = std::chrono::steady_clock::now();
    state_ = std::make_unique<State>(g, opt, std::move(bounds), boxOptionsFor(opt));
    state_->scene.useBounds = opt.useBounds;
    state_->scene.expansionBytes = opt.expansionBytes;
    state_->scene.expansionStartBytes = opt.expansionStartBytes;
    figures.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
    state_->figures = figures;
}

RegionRenderer::~RegionRenderer() = default;

void RegionRenderer::render(const Region& region, const RowSink& rows) {
    State& s = *state_;
    if (region.x0 < 0 || region.y0 < 0 || region.x1 > s.opt.width || region.y1 > s.opt.height ||
        region.width() <= 0 || region.height() <= 0)
        throw std::invalid_argument("the region is not a non-empty part of the image");
    const auto t0 = std::chrono::steady_clock::now();
    const size_t stack = s.scene.stackBytesNeeded();
    // The walk recurses once per node visit: the calling thread gets a stack as large as
    // the scene needs, and so do the pool's threads.
    auto work = [&] {
        TileRender(s.scene, s.camera, s.opt, s.workers, region, rows).run(stack, [&] {
            s.prefill();
        });
    };
    runWithStack(stack, work);
    s.figures.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

std::vector<float> RegionRenderer::render(const Region& region) {
    std::vector<float> rgb;
    if (region.width() > 0 && region.height() > 0) rgb.resize(region.pixels() * 3);
    const size_t row = static_cast<size_t>(std::max(region.width(), 0)) * 3;
    render(region, [&](int y, std::span<const float> pixels) {
        std::copy(pixels.begin(), pixels.end(), rgb.data() + (y - region.y0) * row);
    });
    return rgb;
}

RenderResult RegionRenderer::figures() const {
    const State& s = *state_;
    RenderResult r = s.figures;
    for (const auto& wp : s.workers)
        if (wp) {
            r.rays += wp->shader.rays();
            r.nodeVisits += wp->shader.nodeVisits();
            r.expansions += wp->shader.tracer().expansions();
        }
    if (s.scene.instanceBoxes()) r.instanceBoxes = s.scene.instanceBoxes()->stats();
    r.expansionBudget = s.scene.expansionBudget();
    if (const TopLevel* t = s.scene.topLevel())
        r.topLevel = {true, t->copies(), t->instances(), t->deferred(), t->bytes()};
    return r;
}

RenderResult render(const Graph& g, const RenderOptions& opt) {
    RegionRenderer renderer(g, opt);
    std::vector<float> rgb = renderer.render(Region{0, 0, opt.width, opt.height});
    RenderResult result = renderer.figures();
    result.rgb = std::move(rgb);
    return result;
}

RenderResult render(const Graph& g, const RenderOptions& opt, const RowSink& rows) {
    RegionRenderer renderer(g, opt);
    renderer.render(Region{0, 0, opt.width, opt.height}, rows);
    return renderer.figures();
}

}  // namespace pcsg::tracer
