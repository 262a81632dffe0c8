#include "render.h"

#include <fmt/format.h>
#include <pthread.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <thread>

#include "bounds.h"
#include "camera.h"
#include "eval.h"
#include "shading.h"
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

double aaEncode(double c) {
    return c > 0 ? std::pow(c, 1.0 / 2.5) : 0.0;
}

double colourDistance(const float* a, const float* b) {
    double d = 0;
    for (int k = 0; k < 3; ++k) d += std::fabs(aaEncode(a[k]) - aaEncode(b[k]));
    return d;
}

struct Worker {
    explicit Worker(const TraceScene& s) : shader(s) {}
    Shader shader;
};

// One render of the image in tiles of kTile x kTile pixels on oneTBB's threads: pass 1
// takes the stratified samples (or the pixel centres), pass 2 of adaptive sampling
// supersamples where a pixel differs from a 4-neighbour. The first error stops the rest.
class TileRender {
  public:
    TileRender(const TraceScene& scene, const PinholeCamera& camera, const RenderOptions& opt,
               RenderResult& result)
        : scene_(scene),
          camera_(camera),
          opt_(opt),
          result_(result),
          w_(opt.width),
          h_(opt.height),
          tilesX_((w_ + kTile - 1) / kTile),
          tiles_(tilesX_ * ((h_ + kTile - 1) / kTile)),
          totalWork_(opt.adaptive > 0 ? 2 * tiles_ : tiles_) {
        result_.rgb.assign(static_cast<size_t>(w_) * h_ * 3, 0.0f);
    }

    // Runs both passes on the calling thread's pool; rethrows the first error.
    void run(size_t stackBytes) {
        std::unique_ptr<tbb::global_control> limit;
        if (opt_.threads > 0)
            limit = std::make_unique<tbb::global_control>(
                tbb::global_control::max_allowed_parallelism, static_cast<size_t>(opt_.threads));
        tbb::global_control stackSize(tbb::global_control::thread_stack_size, stackBytes);
        forTiles([&](Worker& wk, int x, int y) { samplePixel(wk, x, y); });
        if (opt_.adaptive > 0 && !stop_) {
            const std::vector<float> centres = result_.rgb;
            forTiles([&](Worker& wk, int x, int y) { supersamplePixel(wk, centres, x, y); });
        }
        for (auto& wp : workers_)
            if (wp) {
                result_.rays += wp->shader.rays();
                result_.nodeVisits += wp->shader.nodeVisits();
                result_.expansions += wp->shader.tracer().expansions();
            }
        if (firstError_) std::rethrow_exception(firstError_);
    }

  private:
    // Runs pixel(worker, x, y) over every pixel, tile by tile in parallel.
    template <class Pixel>
    void forTiles(Pixel&& pixel) {
        tbb::parallel_for(
            tbb::blocked_range<int>(0, tiles_, 1),
            [&](const tbb::blocked_range<int>& range) {
                for (int tile = range.begin(); tile != range.end(); ++tile)
                    if (!runTile(tile, pixel)) return;
            },
            tbb::simple_partitioner());
    }

    // One tile; false when the render stops (an error here or elsewhere).
    template <class Pixel>
    bool runTile(int tile, Pixel& pixel) {
        if (stop_.load(std::memory_order_relaxed)) return false;
        auto& wp = workers_.local();
        if (!wp) wp = std::make_unique<Worker>(scene_);
        const int x0 = (tile % tilesX_) * kTile, y0 = (tile / tilesX_) * kTile;
        const int x1 = std::min(w_, x0 + kTile), y1 = std::min(h_, y0 + kTile);
        try {
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) pixel(*wp, x, y);
        } catch (...) {
            std::lock_guard<std::mutex> lock(errorMutex_);
            if (!firstError_) firstError_ = std::current_exception();
            stop_ = true;
            return false;
        }
        const int d = ++done_;
        if (opt_.progress) opt_.progress(static_cast<double>(d) / totalWork_);
        return true;
    }

    float* pixelAt(std::vector<float>& rgb, int x, int y) const {
        return rgb.data() + (static_cast<size_t>(y) * w_ + x) * 3;
    }

    void store(int x, int y, const Vec3& c) {
        float* p = pixelAt(result_.rgb, x, y);
        p[0] = static_cast<float>(c.x), p[1] = static_cast<float>(c.y),
        p[2] = static_cast<float>(c.z);
    }

    // Pass 1: aa x aa stratified samples (the centre when aa is 1).
    void samplePixel(Worker& wk, int x, int y) {
        const int aa = std::max(1, opt_.aa);
        Vec3 sum{0, 0, 0};
        for (int j = 0; j < aa; ++j)
            for (int i = 0; i < aa; ++i)
                sum += wk.shader.shade(camera_.ray(x + (i + 0.5) / aa, y + (j + 0.5) / aa));
        store(x, y, sum / static_cast<double>(aa * aa));
    }

    // Pass 2 of adaptive sampling (POV-Ray's +A, method 1): a pixel whose centre differs
    // from a 4-neighbour's by the threshold or more gets depth x depth more samples.
    void supersamplePixel(Worker& wk, const std::vector<float>& centres, int x, int y) {
        const float* c = centres.data() + (static_cast<size_t>(y) * w_ + x) * 3;
        bool differs = false;
        const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4 && !differs; ++k) {
            if (nx[k] < 0 || nx[k] >= w_ || ny[k] < 0 || ny[k] >= h_) continue;
            const float* o = centres.data() + (static_cast<size_t>(ny[k]) * w_ + nx[k]) * 3;
            differs = colourDistance(c, o) >= opt_.adaptive;
        }
        if (!differs) return;
        const int depth = std::max(1, opt_.adaptiveDepth);
        const double step = 1.0 / depth, range = 0.5 - step * 0.5;
        Vec3 sum{c[0], c[1], c[2]};
        for (int j = 0; j < depth; ++j)
            for (int i = 0; i < depth; ++i)
                sum += wk.shader.shade(
                    camera_.ray(x + 0.5 - range + i * step, y + 0.5 - range + j * step));
        store(x, y, sum / static_cast<double>(depth * depth + 1));
    }

    const TraceScene& scene_;
    const PinholeCamera& camera_;
    const RenderOptions& opt_;
    RenderResult& result_;
    const int w_, h_, tilesX_, tiles_, totalWork_;
    tbb::enumerable_thread_specific<std::unique_ptr<Worker>> workers_;
    std::mutex errorMutex_;
    std::exception_ptr firstError_;
    std::atomic<bool> stop_{false};
    std::atomic<int> done_{0};
};

}  // namespace

RenderResult render(const Graph& g, const RenderOptions& opt) {
    using Clock = std::chrono::steady_clock;
    if (opt.width <= 0 || opt.height <= 0)
        throw std::invalid_argument("image size must be positive");
    RenderResult result;
    result.width = opt.width;
    result.height = opt.height;
    const auto t0 = Clock::now();
    BoundsOptions boundsOptions;
    boundsOptions.time = opt.boundsTime;
    Bounds bounds = opt.bounds ? *opt.bounds : computeBounds(g, boundsOptions);
    result.infiniteBoxes = bounds.infiniteNodes;
    const auto t1 = Clock::now();
    result.boundsSeconds = std::chrono::duration<double>(t1 - t0).count();
    InstanceBoxOptions boxOptions;
    boxOptions.maxBytes = opt.instanceBoxBytes;
    TraceScene scene(g, std::move(bounds), opt.instanceBoxes, boxOptions);
    scene.useBounds = opt.useBounds;
    scene.expansionBytesPerThread = opt.expansionBytesPerThread;
    const PinholeCamera camera(g.scene.camera, opt.width, opt.height);
    const size_t stack = scene.stackBytesNeeded();
    // The walk recurses once per node visit: the calling thread gets a stack as large as
    // the scene needs, and so do the pool's threads.
    auto work = [&] { TileRender(scene, camera, opt, result).run(stack); };
    runWithStack(stack, work);
    if (scene.instanceBoxes()) result.instanceBoxes = scene.instanceBoxes()->stats();
    result.seconds = std::chrono::duration<double>(Clock::now() - t1).count();
    return result;
}

}  // namespace pcsg::tracer
