// pcsg bench --plot: the Sierpinski sweep and its SVG; see bench_plot.h.
#include "bench_plot.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>

#include "embree_run.h"
#include "renders.h"
#include "stats.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

constexpr const char* kNames[3] = {"pcsg", "POV-Ray", "Embree"};

uint64_t defaultMemoryLimit() {
    const long pages = sysconf(_SC_PHYS_PAGES), size = sysconf(_SC_PAGE_SIZE);
    return pages > 0 && size > 0 ? uint64_t(pages) * uint64_t(size) / 2 : (8ull << 30);
}

// One renderer at one order: its time and peak RSS, or nothing when it failed.
struct Measured {
    double seconds = 0;
    uint64_t rss = 0;
};
using Runner = std::function<std::optional<Measured>(const std::string& scene, int order)>;

std::optional<Measured> runNative(const ScalingOptions& o, const fs::path& work,
                                  const std::string& scene, int order) {
    std::vector<std::string> args = {"--adaptive", fmt::format("{}", o.adaptive)};
    if (o.threads > 0) args.insert(args.end(), {"--threads", std::to_string(o.threads)});
    const RenderRun r = renderNative(scene, (work / fmt::format("native_{}.png", order)).string(),
                                     o.width, o.height, args);
    if (!r.ok) return std::nullopt;
    return Measured{r.child.seconds, r.child.peakRssBytes};
}

std::optional<Measured> runPov(const ScalingOptions& o, const fs::path& work,
                               const std::string& scene, int order) {
    const fs::path pov = work / fmt::format("order_{}.pov", order);
    const RenderRun exported = exportPov(scene, pov.string(), o.width, o.height,
                                         {"--max-nodes", std::to_string(o.maxNodes)});
    if (!exported.ok) return std::nullopt;
    std::vector<std::string> args = {o.adaptive > 0 ? fmt::format("+A{}", o.adaptive) : "-A"};
    if (o.threads > 0) args.push_back("+WT" + std::to_string(o.threads));
    const RenderRun r =
        renderPovray(pov.string(), (work / fmt::format("povray_{}.png", order)).string(), o.width,
                     o.height, args);
    std::error_code ec;
    fs::remove(pov, ec);
    if (!r.ok) return std::nullopt;
    return Measured{r.child.seconds, r.child.peakRssBytes};
}

std::optional<Measured> runEmbreeAt(const ScalingOptions& o, const std::string& embree,
                                    const std::string& scene) {
    const auto e = runEmbree(embree, scene, o.width, o.height, o.threads, o.maxNodes);
    if (!e) return std::nullopt;
    return Measured{e->seconds, e->peakRss};
}

}  // namespace

std::string sierpinskiScene(int order) {
    return fmt::format(
        "// The Sierpinski tetrahedron of order {} (pcsg bench --plot).\n"
        "camera     {{ location <2.6, -5.2, 2.6>  look_at <0, 0, -0.15>  sky <0, 0, 1>  angle "
        "38 }}\n"
        "light      {{ position <6, -10, 14>  color <1, 1, 1> }}\n"
        "light      {{ position <-12, -4, 5>  color <0.25, 0.28, 0.4> }}\n"
        "background <0.03, 0.05, 0.16>\n"
        "material warm {{ color <0.95, 0.55, 0.22>  ambient 0.12  diffuse 0.75  phong 0.35  "
        "phong_size 40 }}\n\n"
        "paint(warm) {{c={}}} S\n\n"
        "S if(c > 0, 2, 1)\n"
        "1: S -> tetrahedron\n"
        "2: S -> {{c=c-1}} ( move(0.5,0.5,0.5) uscale(0.5) S ∪ move(-0.5,-0.5,0.5) uscale(0.5) S "
        "∪\n"
        "                  move(0.5,-0.5,-0.5) uscale(0.5) S ∪ move(-0.5,0.5,-0.5) uscale(0.5) S "
        ")\n",
        order, order);
}

std::vector<ScalingPoint> measureScaling(const ScalingOptions& o, const fs::path& work,
                                         std::ostream& log) {
    const uint64_t limit = o.memoryLimit ? o.memoryLimit : defaultMemoryLimit();
    const std::optional<std::string> embree = findEmbree();
    std::array<Runner, 3> runners = {
        [&](const std::string& s, int k) { return runNative(o, work, s, k); },
        [&](const std::string& s, int k) { return runPov(o, work, s, k); },
        [&](const std::string& s, int) { return runEmbreeAt(o, *embree, s); }};
    std::array<bool, 3> running = {true, inPath("povray"), embree.has_value()};
    std::array<uint64_t, 3> lastRss = {0, 0, 0};
    std::vector<ScalingPoint> points;
    for (int k = o.fromOrder; k <= o.toOrder; ++k) {
        const fs::path scene = work / fmt::format("sierpinski_{}.pcsg", k);
        std::ofstream(scene) << sierpinskiScene(k);
        ScalingPoint p;
        p.order = k;
        for (int r = 0; r < 3; ++r) {
            // The tree and the mesh grow fourfold per order: stop before the limit.
            if (r != kScalingNative && lastRss[r] * 4 > limit) running[r] = false;
            if (!running[r]) continue;
            log << fmt::format("bench --plot: order {}, {} ...\n", k, kNames[r]) << std::flush;
            const std::optional<Measured> m = runners[r](scene.string(), k);
            if (!m) {
                running[r] = false;
                continue;
            }
            p.seconds[r] = m->seconds;
            p.rss[r] = lastRss[r] = m->rss;
        }
        points.push_back(p);
    }
    return points;
}

}  // namespace pcsg::tools
