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

}  // namespace

RenderResult render(const Graph& g, const RenderOptions& opt) {
    using Clock = std::chrono::steady_clock;
    if (opt.width <= 0 || opt.height <= 0)
        throw std::invalid_argument("image size must be positive");
    RenderResult result;
    result.width = opt.width;
    result.height = opt.height;
    const auto t0 = Clock::now();
    Bounds bounds = computeBounds(g);
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

    const int w = opt.width, h = opt.height;
    result.rgb.assign(static_cast<size_t>(w) * h * 3, 0.0f);
    float* img = result.rgb.data();
    const int tilesX = (w + kTile - 1) / kTile, tilesY = (h + kTile - 1) / kTile;
    const int tiles = tilesX * tilesY;
    const int aa = std::max(1, opt.aa);
    const bool adaptive = opt.adaptive > 0;

    std::mutex errorMutex;
    std::exception_ptr firstError;
    std::atomic<bool> stop{false};
    std::atomic<int> done{0};
    const int totalWork = adaptive ? 2 * tiles : tiles;

    // Pass 2 of adaptive sampling: supersample where a pixel differs from a 4-neighbour.
    auto supersample = [&](auto& forTiles) {
        const std::vector<float> centres = result.rgb;
        const int depth = std::max(1, opt.adaptiveDepth);
        const double step = 1.0 / depth, range = 0.5 - step * 0.5;
        forTiles([&](Worker& wk, int x0, int y0, int x1, int y1) {
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    const float* c = centres.data() + (static_cast<size_t>(y) * w + x) * 3;
                    bool differs = false;
                    const int nx[4] = {x - 1, x + 1, x, x}, ny[4] = {y, y, y - 1, y + 1};
                    for (int k = 0; k < 4 && !differs; ++k) {
                        if (nx[k] < 0 || nx[k] >= w || ny[k] < 0 || ny[k] >= h) continue;
                        const float* o =
                            centres.data() + (static_cast<size_t>(ny[k]) * w + nx[k]) * 3;
                        differs = colourDistance(c, o) >= opt.adaptive;
                    }
                    if (!differs) continue;
                    Vec3 sum{c[0], c[1], c[2]};
                    for (int j = 0; j < depth; ++j)
                        for (int i = 0; i < depth; ++i)
                            sum += wk.shader.shade(
                                camera.ray(x + 0.5 - range + i * step, y + 0.5 - range + j * step));
                    sum = sum / static_cast<double>(depth * depth + 1);
                    float* p = img + (static_cast<size_t>(y) * w + x) * 3;
                    p[0] = static_cast<float>(sum.x), p[1] = static_cast<float>(sum.y),
                    p[2] = static_cast<float>(sum.z);
                }
        });
    };

    auto work = [&] {
        std::unique_ptr<tbb::global_control> limit;
        if (opt.threads > 0)
            limit = std::make_unique<tbb::global_control>(
                tbb::global_control::max_allowed_parallelism, static_cast<size_t>(opt.threads));
        tbb::global_control stackSize(tbb::global_control::thread_stack_size, stack);
        tbb::enumerable_thread_specific<std::unique_ptr<Worker>> workers;

        auto forTiles = [&](auto&& body) {
            tbb::parallel_for(
                tbb::blocked_range<int>(0, tiles, 1),
                [&](const tbb::blocked_range<int>& range) {
                    for (int tile = range.begin(); tile != range.end(); ++tile) {
                        if (stop.load(std::memory_order_relaxed)) return;
                        auto& wp = workers.local();
                        if (!wp) wp = std::make_unique<Worker>(scene);
                        const int x0 = (tile % tilesX) * kTile, y0 = (tile / tilesX) * kTile;
                        const int x1 = std::min(w, x0 + kTile), y1 = std::min(h, y0 + kTile);
                        try {
                            body(*wp, x0, y0, x1, y1);
                        } catch (...) {
                            std::lock_guard<std::mutex> lock(errorMutex);
                            if (!firstError) firstError = std::current_exception();
                            stop = true;
                            return;
                        }
                        const int d = ++done;
                        if (opt.progress) opt.progress(static_cast<double>(d) / totalWork);
                    }
                },
                tbb::simple_partitioner());
        };

        // Pass 1: the stratified samples (or the centres, for adaptive sampling).
        forTiles([&](Worker& wk, int x0, int y0, int x1, int y1) {
            for (int y = y0; y < y1; ++y)
                for (int x = x0; x < x1; ++x) {
                    Vec3 sum{0, 0, 0};
                    for (int j = 0; j < aa; ++j)
                        for (int i = 0; i < aa; ++i)
                            sum +=
                                wk.shader.shade(camera.ray(x + (i + 0.5) / aa, y + (j + 0.5) / aa));
                    sum = sum / static_cast<double>(aa * aa);
                    float* p = img + (static_cast<size_t>(y) * w + x) * 3;
                    p[0] = static_cast<float>(sum.x), p[1] = static_cast<float>(sum.y),
                    p[2] = static_cast<float>(sum.z);
                }
        });
        if (adaptive && !stop) supersample(forTiles);

        for (auto& wp : workers)
            if (wp) {
                result.rays += wp->shader.rays();
                result.nodeVisits += wp->shader.nodeVisits();
                result.expansions += wp->shader.tracer().expansions();
            }
    };
    runWithStack(stack, work);
    if (firstError) std::rethrow_exception(firstError);
    if (scene.instanceBoxes()) result.instanceBoxes = scene.instanceBoxes()->stats();
    result.seconds = std::chrono::duration<double>(Clock::now() - t1).count();
    return result;
}

}  // namespace pcsg::tracer
