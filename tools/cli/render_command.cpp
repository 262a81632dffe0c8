// pcsg render SCENE -o OUT [--width W] [--height H] [--aa N] [--adaptive T] [--threads N]
//                          [--clock X [--frame F] | --frames N [--clock-range A,B] [--cyclic]
//                          [--subset F,L] [--fps R] [--keep-frames]] [--json]
// Ray traces the scene's cyclic graph directly (tracer/): the graph is never expanded.
// Prints the figures of the paper's Table 1 and more (tools/cli/stats.h).
//
// A PNG is written in this process through libpng (tools/image/png_writer.h), so that the
// whole command stays small: OpenImageIO's ~260 shared libraries would cost it ~130 MB.
// Its rows go into the file as the render finishes them (png_writer.h's PngRows): the
// image is never held whole, as floats (3.7 MB at 640x480) nor as bytes (0.9 MB).
// An EXR or TIFF file is written by the pcsg-image helper (tools/image/image_helper.h),
// run once the pixels exist, which gets them through a pipe. The peak RSS printed is the
// whole command's (this process's, or the helper's when that is larger), what
// /usr/bin/time -v reports; the helper's own is printed beside it.
//
// With --frames N the scene compiles once and each frame sets its time (frames.h) and is
// rendered and written exactly as a still at that time would be; a run-time error at frame
// k names the frame and the clock and keeps the frames written before it. A video (-o
// OUT.mp4, .webm, .gif) is such a sequence of PNG files encoded by ffmpeg (video.h).
//
// Under `mpirun -np N` (or srun) the same command renders on N ranks and writes the same
// image (distributed_render.h, docs/distributed.md): runRenderCommand() decides.
//
// Exit status: 0 the image was written; 1 the scene is at fault (a compile error or a
// run-time error of docs/language.md, reported once with its module path; no image is
// written); 2 something could not run (bad options, an unwritable output file, no
// pcsg-image for an EXR or TIFF file).
#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <mutex>
#include <thread>
#include <tuple>
#include <vector>

#include "commands.h"
#include "distributed_render.h"
#include "eval.h"
#include "expander.h"
#include "frames.h"
#include "image_format.h"
#include "image_helper.h"
#include "mpi_session.h"
#include "png_writer.h"
#include "render.h"
#include "scene_input.h"
#include "scene_time.h"
#include "stats.h"
#include "traversal.h"
#include "video.h"

namespace pcsg::tools {

namespace {

struct RenderCommandOptions {
    std::string scene;
    std::string output;
    int width = 640, height = 480;
    int aa = 1;
    double adaptive = 0;
    int threads = 0;
    bool json = false;
    bool noBounds = false;
    bool noInstanceBoxes = false;
    size_t boxCacheMb = 64;
    size_t expansionCacheMb = 16;
    uint64_t countVisits = 20'000'000;
    double clock = 0;  // --clock: the still's time
    int frame = 1;     // --frame: the still's frame number
    int frames = 0;    // --frames N: a sequence (0: a still)
    std::string clockRange, subset;
    bool cyclic = false;
    double fps = 24;                   // a video's frame rate
    bool keepFrames = false;           // a video's frames are kept next to it
    std::string frameBounds = "auto";  // --frame-bounds: auto, on or off
    std::string tileTimes;             // --tile-times FILE: each tile's CPU time, as CSV
    // Rank 0 of `mpirun -np N pcsg render` (N > 1): the ranks render the pixels.
    DistributedRender* distributed = nullptr;
};

// A progress bar on standard error, redrawn at most every 1%.
class ProgressBar {
  public:
    void update(double fraction) {
        const int percent = static_cast<int>(fraction * 100);
        if (percent <= shown_.load(std::memory_order_relaxed)) return;
        std::unique_lock<std::mutex> lock(mutex_, std::try_to_lock);
        if (!lock.owns_lock() || percent <= shown_) return;
        shown_ = percent;
        const int width = 40, filled = percent * width / 100;
        const double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
        std::fprintf(stderr, "\r  [%s%s] %3d%%  %.1f s", std::string(filled, '#').c_str(),
                     std::string(width - filled, '.').c_str(), percent, elapsed);
        std::fflush(stderr);
    }
    void finish() {
        if (shown_ >= 0) std::fprintf(stderr, "\r%70s\r", "");
    }

  private:
    std::mutex mutex_;
    std::atomic<int> shown_{-1};
    std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// What the render computed and wrote, printed as text or JSON by printRender().
struct RenderReport {
    Stats stats;
    ExpansionCount count;
    tracer::RenderResult result;  // its pixels released once written
    // A PNG, written as the render hands over its rows (opened before it; null for the
    // other formats, whose floats are result.rgb, and under MPI).
    std::unique_ptr<PngRows> png;
    size_t graphNodes = 0;
    double imageWriteSeconds = 0;            // writing the image file
    std::optional<ImageWriteResult> helper;  // pcsg-image, for EXR and TIFF
};

// Writes the pixels: a PNG here, an EXR or TIFF through pcsg-image. Returns the error
// message, empty on success.
std::string writeOutput(const RenderCommandOptions& o, const std::string& imageHelper,
                        RenderReport& report) {
    const auto start = std::chrono::steady_clock::now();
    const std::span<const float> rgb = report.result.rgb;
    if (imageFormatOf(o.output) == ImageFormat::png) {
        try {
            if (report.png)
                report.png->finish();
            else
                writePng(o.output, o.width, o.height, rgb);
        } catch (const std::runtime_error& e) {
            return e.what();
        }
    } else {
        report.helper = writeImageWithHelper(imageHelper, o.output, o.width, o.height, rgb);
        if (!report.helper->ok) return report.helper->error;
    }
    report.imageWriteSeconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return {};
}

tracer::RenderOptions tracerOptions(const RenderCommandOptions& o) {
    tracer::RenderOptions ro;
    ro.width = o.width;
    ro.height = o.height;
    ro.aa = o.aa;
    ro.adaptive = o.adaptive;
    ro.threads = o.threads;
    ro.useBounds = !o.noBounds;
    ro.instanceBoxes = !o.noInstanceBoxes;
    ro.instanceBoxBytes = o.boxCacheMb << 20;
    ro.expansionBytes = o.expansionCacheMb << 20;
    return ro;
}

// --tile-times FILE: every tile's CPU time, for the scaling model of
// docs/distributed.md (tools/dev/mpi_schedule_sim.py reads it).
class TileTimes {
  public:
    void add(int pass, int x0, int y0, int x1, int y1, double seconds) {
        std::lock_guard<std::mutex> lock(mutex_);
        rows_ += fmt::format("{},{},{},{},{},{:.9f}\n", pass, x0, y0, x1, y1, seconds);
    }
    bool write(const std::string& path) const {
        std::FILE* f = std::fopen(path.c_str(), "w");
        if (!f) return false;
        const std::string header = "pass,x0,y0,x1,y1,seconds\n";
        bool ok = std::fwrite(header.data(), 1, header.size(), f) == header.size() &&
                  std::fwrite(rows_.data(), 1, rows_.size(), f) == rows_.size();
        return std::fclose(f) == 0 && ok;
    }

  private:
    std::mutex mutex_;
    std::string rows_;
};

// Rank 0 of a distributed render: the still's pixels from every rank.
int distributedStill(Graph& g, const RenderCommandOptions& o, const tracer::RenderOptions& ro,
                     RenderReport& report) {
    DistributedJob job;
    job.scene = o.scene;
    job.render = ro;
    job.countVisits = o.countVisits;
    job.frames = {WorkFrame{o.frame, o.clock}};
    const auto start = std::chrono::steady_clock::now();
    tracer::RenderResult& r = report.result;
    const int status = o.distributed->render(g, job, [&](DistributedFrame& f) {
        r.width = o.width;
        r.height = o.height;
        r.rgb = std::move(f.rgb);
        r.rays = f.rays;
        r.nodeVisits = f.nodeVisits;
        r.boundsSeconds = f.boundsSeconds;
        if (f.count) report.count = *f.count;
        return 0;
    });
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return status;
}

// Counts the expansion and renders; returns the exit status (0, or 1 and 2 with the
// error printed).
// What a frame of a sequence adds to a render: a note for its errors, the sequence's
// boxes, and the sequence's progress bar with the share of it this frame covers.
struct FrameContext {
    std::string note;
    std::shared_ptr<const tracer::Bounds> bounds;
    std::shared_ptr<tracer::SequenceInstanceBoxes> instanceBoxes;
    std::shared_ptr<ProgressBar> bar;
    double base = 0, share = 1;
};

// What the render's instance-box fill counted (InstanceBoxes::prefill), handed to the
// count once the fill is done, or null once the render has ended without one.
class FillCounts {
  public:
    void set(std::shared_ptr<const KnownCounts> counts) {
        std::lock_guard<std::mutex> lock(mutex_);
        if (done_) return;
        counts_ = std::move(counts);
        done_ = true;
        ready_.notify_all();
    }
    std::shared_ptr<const KnownCounts> wait() {
        std::unique_lock<std::mutex> lock(mutex_);
        ready_.wait(lock, [this] { return done_; });
        return counts_;
    }

  private:
    std::mutex mutex_;
    std::condition_variable ready_;
    bool done_ = false;
    std::shared_ptr<const KnownCounts> counts_;
};

// Opens the PNG the render's rows go to (RenderReport::png): 2 with the error printed
// when it cannot be written.
int openPng(const RenderCommandOptions& o, RenderReport& report, const std::string& frameNote) {
    if (imageFormatOf(o.output) != ImageFormat::png) return 0;
    try {
        report.png = std::make_unique<PngRows>(o.output, o.width, o.height);
    } catch (const std::runtime_error& e) {
        std::cerr << "pcsg render: " << e.what() << frameNote << "\n";
        return 2;
    }
    return 0;
}

// The count (primitive equivalence, and the scene's run-time errors on every path) runs on
// a thread of its own beside the render. It waits for the render's instance-box fill,
// which unrolls the instances below a few dozen S-node instances (a terrain's 2 million
// triangles, which do not repeat and cannot be memoised) in parallel before the first
// rays and counts them on the way: the count takes those counts and walks only the
// levels above them, and what the fill could not count (a run-time error there, a part
// found stored) itself. What is reported stays the serial order's: an error of the count
// wins over the render's (the render is cancelled and its pixels dropped), then the
// render's own error; nothing is written unless both succeed.
void countBesideRender(const Graph& g, CountOptions co, tracer::RenderOptions ro,
                       RenderReport& report) {
    std::atomic<bool> cancel{false};
    if (ro.cancel) throw std::logic_error("countBesideRender: the render has its own cancel flag");
    ro.cancel = &cancel;
    auto fill = std::make_shared<FillCounts>();
    ro.prefilled = [fill](std::shared_ptr<const KnownCounts> counts) {
        fill->set(std::move(counts));
    };
    std::exception_ptr countError, renderError;
    std::thread counter([&] {
        try {
            const std::shared_ptr<const KnownCounts> known = fill->wait();
            co.known = known.get();
            report.count = countExpansion(g, co);
        } catch (...) {
            countError = std::current_exception();
            cancel = true;
        }
    });
    try {
        // A PNG gets the rows as they are finished (the image is never held whole: 3.7 MB
        // of floats at 640x480); the helper's formats get result.rgb.
        if (PngRows* png = report.png.get())
            report.result = tracer::render(
                g, ro, [png](int y, std::span<const float> rgb) { png->put(y, rgb); });
        else
            report.result = tracer::render(g, ro);
    } catch (...) {
        renderError = std::current_exception();
    }
    fill->set(nullptr);  // (the render ended before its fill: the count walks everything)
    counter.join();
    if (countError) std::rethrow_exception(countError);
    if (renderError) std::rethrow_exception(renderError);
}

int countAndRender(Graph& g, const RenderCommandOptions& o, RenderReport& report,
                   const FrameContext& frame = {}) {
    // Primitive equivalence: what the expanded tree would hold, counted without building
    // it. The count walks every path of the expansion (memoised), so it also finds the
    // scene's run-time errors on paths no ray visits.
    tracer::RenderOptions ro = tracerOptions(o);
    ro.bounds = frame.bounds;
    ro.sequenceBoxes = frame.instanceBoxes;
    const std::string& frameNote = frame.note;
    auto bar = frame.bar ? frame.bar : std::make_shared<ProgressBar>();
    const bool showProgress = isatty(STDERR_FILENO) != 0;
    if (showProgress)
        ro.progress = [bar, base = frame.base, share = frame.share](double f) {
            bar->update(base + share * f);
        };
    if (o.distributed) {
        const int status = distributedStill(g, o, ro, report);
        if (showProgress) bar->finish();
        return status;
    }
    if (const int status = openPng(o, report, frameNote)) return status;
    auto times = std::make_shared<TileTimes>();
    if (!o.tileTimes.empty())
        ro.tileTime = [times](int pass, int x0, int y0, int x1, int y1, double seconds) {
            times->add(pass, x0, y0, x1, y1, seconds);
        };
    try {
        CountOptions co;
        co.maxVisits = o.countVisits;
        countBesideRender(g, co, ro, report);
    } catch (const RuntimeError& e) {
        if (showProgress) bar->finish();
        std::cerr << e.format(g) << frameNote << "\n";
        return 1;
    } catch (const std::exception& e) {
        if (showProgress) bar->finish();
        std::cerr << "pcsg render: error: " << o.scene << ": " << e.what() << frameNote << "\n";
        return 2;
    }
    if (showProgress && !frame.bar) bar->finish();
    if (!o.tileTimes.empty() && !times->write(o.tileTimes)) {
        std::cerr << "pcsg render: cannot write '" << o.tileTimes << "'\n";
        return 2;
    }
    return 0;
}

void printJson(const RenderCommandOptions& o, const RenderReport& report) {
    const tracer::RenderResult& result = report.result;
    nlohmann::json j = report.stats.toJson();
    j["output"] = o.output;
    j["node_visits"] = result.nodeVisits;
    j["bounds_seconds"] = result.boundsSeconds;
    j["unbounded_nodes"] = result.infiniteBoxes;
    j["instance_boxes"] = {{"entries", result.instanceBoxes.entries},
                           {"bytes", result.instanceBoxes.bytes},
                           {"computed", result.instanceBoxes.computed},
                           {"full", result.instanceBoxes.full}};
    j["expanded_instances"] = result.expansions;
    j["expansion_budget_bytes"] = result.expansionBudget;  // reached (at most the maximum)
    const tracer::RenderResult::TopLevelFigures& top = result.topLevel;
    j["top_level"] = {{"built", top.built},
                      {"copies", top.copies},
                      {"instances", top.instances},
                      {"deferred_cuts", top.deferred},
                      {"bytes", top.bytes}};
    j["aa"] = o.aa;
    j["adaptive"] = o.adaptive;
    j["graph_nodes"] = report.graphNodes;
    // After the render: the part of the wall time spent on the image.
    j["image_write_seconds"] = report.imageWriteSeconds;
    if (report.helper) {
        j["image_writer_peak_rss_bytes"] = report.helper->peakRssBytes;
        j["image_writer_seconds"] = report.helper->seconds;  // its whole life
    }
    if (!report.count.complete)
        j["primitive_equivalence_note"] = "too large to count (rand/choose)";
    if (o.distributed) {
        j["ranks"] = o.distributed->ranks();
        j["per_rank"] = rankFiguresJson(o.distributed->finish(0));
    }
    std::cout << j.dump(2) << "\n";
}

// --- frame sequences (--frames N) ---

bool framePlan(const RenderCommandOptions& o, FramePlan& p) {
    p.frames = o.frames;
    p.cyclic = o.cyclic;
    p.first = 1;
    p.last = o.frames;
    std::string error;
    if (!o.clockRange.empty()) {
        const auto range = parseClockRange(o.clockRange, error);
        if (!range) {
            std::cerr << "pcsg render: error: " << error << "\n";
            return false;
        }
        std::tie(p.clockFrom, p.clockTo) = *range;
    }
    if (!o.subset.empty()) {
        const auto subset = parseSubset(o.subset, o.frames, error);
        if (!subset) {
            std::cerr << "pcsg render: error: " << error << "\n";
            return false;
        }
        std::tie(p.first, p.last) = *subset;
    }
    return true;
}

// What one frame of a sequence computed and wrote.
struct FrameFigures {
    int frame = 1;
    double clock = 0;
    std::string output;
    tracer::RenderResult result;  // its pixels released once written
    double imageWriteSeconds = 0;
    std::optional<uint64_t> primitives;
    bool ownBounds = true;  // the frame computed its own boxes (else the range's)
};

// The hyper-bounding boxes of a sequence (docs/language.md section 11): computed once
// for the clock range of the frames rendered, with `clock` and `frame` intervals. A frame
// computes its own, tighter boxes too (they cull more) when FrameBoundsChoice (frames.h)
// says so. The image is the same either way. And the exact boxes of the instances that
// do not change with the time (tracer::SequenceInstanceBoxes), kept from frame to frame.
class SequenceBounds {
  public:
    SequenceBounds(const Graph& g, const FramePlan& plan, const RenderCommandOptions& o)
        : choice_(frameBoundsMode(o.frameBounds).value_or(FrameBoundsChoice::Mode::Auto)) {
        if (!o.noInstanceBoxes)
            instances_ = std::make_shared<tracer::SequenceInstanceBoxes>(g, o.boxCacheMb << 20);
        const double a = frameClock(plan, plan.first), b = frameClock(plan, plan.last);
        tracer::BoundsOptions bo;
        bo.time = TimeRange{std::min(a, b), std::max(a, b), plan.first, plan.last};
        const auto start = std::chrono::steady_clock::now();
        try {
            range_ = std::make_shared<tracer::Bounds>(tracer::computeBounds(g, bo));
        } catch (const std::exception&) {
            range_.reset();  // then every frame computes its own, and meets the error
        }
        seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    // The boxes for the next frame: the range's, or null (the frame computes its own).
    std::shared_ptr<const tracer::Bounds> next() const {
        if (!range_ || choice_.ownBoxes()) return nullptr;
        return range_;
    }
    // What the last frame cost: its own boxes and its render.
    void update(const tracer::RenderResult& r, bool ownBounds) {
        choice_.frameDone(ownBounds, r.boundsSeconds, r.seconds);
    }
    double seconds() const { return seconds_; }
    const std::shared_ptr<tracer::SequenceInstanceBoxes>& instanceBoxes() const {
        return instances_;
    }

  private:
    FrameBoundsChoice choice_;
    std::shared_ptr<const tracer::Bounds> range_;
    std::shared_ptr<tracer::SequenceInstanceBoxes> instances_;
    double seconds_ = 0;
};

// The note a frame's errors end with.
std::string frameNote(const FramePlan& plan, int f, double clock) {
    return fmt::format("\n  at frame {} of {}, clock {}", f, plan.frames, clock);
}

// Sets frame f's time and renders it, as a still at that clock would be (report: its
// pixels and figures; writeFrame writes them).
int renderFrame(const RenderCommandOptions& o, const FramePlan& plan, int f, Graph& g,
                SequenceBounds& bounds, const std::shared_ptr<ProgressBar>& bar, FrameFigures& out,
                RenderReport& report) {
    out.frame = f;
    out.clock = frameClock(plan, f);
    out.output = frameFileName(o.output, f, plan.frames);
    const std::string note = frameNote(plan, f, out.clock);
    try {
        setTime(g, Time{out.clock, f});
    } catch (const RuntimeError& e) {
        std::cerr << e.format(g) << note << "\n";
        return 1;
    }
    RenderCommandOptions fo = o;
    fo.output = out.output;
    const int count = plan.last - plan.first + 1;
    const FrameContext context{
        note,       bounds.next(), bounds.instanceBoxes(), bar, double(f - plan.first) / count,
        1.0 / count};
    if (const int status = countAndRender(g, fo, report, context)) return status;
    out.ownBounds = context.bounds == nullptr;
    bounds.update(report.result, out.ownBounds);
    if (report.count.complete) out.primitives = report.count.primitives;
    return 0;
}

// Writes the rendered frame's file (a PNG's rows are in it already: it is ended and
// renamed) and prints its line. Releases the pixels: `= {}` would clear them but keep
// their memory, a whole image per frame held to the end of the sequence.
int writeFrame(const RenderCommandOptions& o, const FramePlan& plan, const std::string& imageHelper,
               RenderReport& report, FrameFigures& out) {
    RenderCommandOptions fo = o;
    fo.output = out.output;
    if (const std::string error = writeOutput(fo, imageHelper, report); !error.empty()) {
        std::cerr << "pcsg render: " << error << frameNote(plan, out.frame, out.clock) << "\n";
        return 2;
    }
    out.imageWriteSeconds = report.imageWriteSeconds;
    report.result.rgb = std::vector<float>();
    report.png.reset();
    out.result = std::move(report.result);
    if (!o.json)
        std::cout << fmt::format("frame {} of {} (clock {}): wrote {} in {:.3f} s, {} rays\n",
                                 out.frame, plan.frames, out.clock, out.output, out.result.seconds,
                                 out.result.rays)
                  << std::flush;
    return 0;
}

nlohmann::json frameJson(const FrameFigures& f) {
    nlohmann::json j = {{"frame", f.frame},
                        {"clock", f.clock},
                        {"output", f.output},
                        {"rays", f.result.rays},
                        {"seconds", f.result.seconds},
                        {"bounds_seconds", f.result.boundsSeconds},
                        {"bounds", f.ownBounds ? "frame" : "range"},
                        {"node_visits", f.result.nodeVisits},
                        // unrolled in this frame (not found in the table, nor in the
                        // sequence's, which keeps the boxes that do not change with the time)
                        {"instance_boxes_computed", f.result.instanceBoxes.computed},
                        {"expanded_instances", f.result.expansions},
                        {"expansion_budget_bytes", f.result.expansionBudget},
                        {"image_write_seconds", f.imageWriteSeconds}};
    if (f.primitives) j["primitive_equivalence"] = *f.primitives;
    return j;
}

// The figures of the whole sequence: per frame, and the totals.
void printFrames(const RenderCommandOptions& o, const FramePlan& plan, const Graph& g,
                 const CompiledScene& compiled, const std::vector<FrameFigures>& done,
                 double rangeBoundsSeconds) {
    Stats s;
    s.scene = o.scene;
    s.width = static_cast<uint32_t>(o.width);
    s.height = static_cast<uint32_t>(o.height);
    s.graphBytes = g.graphBytes();
    s.parseSeconds = compiled.seconds;
    uint64_t rays = 0;
    double seconds = 0, writeSeconds = 0;
    for (const FrameFigures& f : done) {
        rays += f.result.rays;
        seconds += f.result.seconds;
        writeSeconds += f.imageWriteSeconds;
    }
    s.rays = rays;
    s.seconds = seconds;
    s.raysPerSecond = seconds > 0 ? rays / seconds : 0.0;
    s.peakRssBytes = wholeCommandPeakRssBytes();
    if (o.json) {
        nlohmann::json j = s.toJson();
        j["frames"] = nlohmann::json::array();
        for (const FrameFigures& f : done) j["frames"].push_back(frameJson(f));
        j["totals"] = {{"frames", done.size()},
                       {"rays", rays},
                       {"seconds", seconds},
                       {"image_write_seconds", writeSeconds},
                       {"frames_in_sequence", plan.frames},
                       {"range_bounds_seconds", rangeBoundsSeconds},
                       {"cyclic", plan.cyclic}};
        j["graph_nodes"] = g.nodes.size();
        if (o.distributed) {
            j["ranks"] = o.distributed->ranks();
            j["per_rank"] = rankFiguresJson(o.distributed->finish(0));
        }
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::cout << fmt::format("{}: wrote {} frames ({} to {} of {}) in {:.3f} s\n", o.scene,
                             done.size(), plan.first, plan.last, plan.frames, seconds);
    s.print(std::cout);
    std::cout << fmt::format("{:<24}{:.3f} s\n", "image write time", writeSeconds);
    if (o.distributed) std::cout << rankFiguresText(o.distributed->finish(0));
}

// Rank 0 of a distributed render: writes frame df, which every pixel of has arrived.
int writeDistributedFrame(const RenderCommandOptions& o, const FramePlan& plan,
                          DistributedFrame& df, const std::string& imageHelper,
                          std::vector<FrameFigures>& done) {
    FrameFigures figures;
    figures.frame = df.frame.frame;
    figures.clock = df.frame.clock;
    RenderCommandOptions fo = o;
    fo.output = frameFileName(o.output, figures.frame, plan.frames);
    RenderReport report;
    report.result.rgb = std::move(df.rgb);
    if (const std::string error = writeOutput(fo, imageHelper, report); !error.empty()) {
        std::cerr << "pcsg render: " << error
                  << fmt::format("\n  at frame {} of {}, clock {}", figures.frame, plan.frames,
                                 figures.clock)
                  << "\n";
        return 2;
    }
    figures.output = fo.output;
    figures.result.rays = df.rays;
    figures.result.nodeVisits = df.nodeVisits;
    figures.result.seconds = df.renderSeconds;
    figures.result.boundsSeconds = df.boundsSeconds;
    figures.imageWriteSeconds = report.imageWriteSeconds;
    if (df.count && df.count->complete) figures.primitives = df.count->primitives;
    if (!o.json)
        std::cout << fmt::format(
                         "frame {} of {} (clock {}): wrote {}, {:.3f} s of rendering on "
                         "the ranks, {} rays\n",
                         figures.frame, plan.frames, figures.clock, figures.output,
                         figures.result.seconds, figures.result.rays)
                  << std::flush;
    done.push_back(std::move(figures));
    return 0;
}

// Rank 0 of a distributed render: the frames, as units of work over every rank.
int runFramesDistributed(const RenderCommandOptions& o, const FramePlan& plan,
                         CompiledScene& compiled, const std::string& imageHelper) {
    DistributedJob job;
    job.scene = o.scene;
    job.render = tracerOptions(o);
    job.countVisits = o.countVisits;
    job.framesInSequence = plan.frames;
    for (int f = plan.first; f <= plan.last; ++f) job.frames.push_back({f, frameClock(plan, f)});
    auto bar = std::make_shared<ProgressBar>();
    const bool showProgress = isatty(STDERR_FILENO) != 0;
    if (showProgress) job.render.progress = [bar](double f) { bar->update(f); };
    std::vector<FrameFigures> done;
    const int status = o.distributed->render(*compiled.graph, job, [&](DistributedFrame& df) {
        return writeDistributedFrame(o, plan, df, imageHelper, done);
    });
    if (showProgress) bar->finish();
    if (status != 0) return status;
    std::sort(done.begin(), done.end(),
              [](const FrameFigures& a, const FrameFigures& b) { return a.frame < b.frame; });
    printFrames(o, plan, *compiled.graph, compiled, done, 0.0);  // each rank bounds its frames
    return 0;
}

int runFrames(const RenderCommandOptions& o, const FramePlan& plan, CompiledScene& compiled,
              const std::string& imageHelper) {
    if (o.distributed) return runFramesDistributed(o, plan, compiled, imageHelper);
    Graph& g = *compiled.graph;
    std::vector<FrameFigures> done;
    useOneMallocArena();
    SequenceBounds bounds(g, plan, o);
    // One bar over the whole sequence, cleared while a frame's line is printed.
    auto bar = std::make_shared<ProgressBar>();
    const bool showProgress = isatty(STDERR_FILENO) != 0;
    for (int f = plan.first; f <= plan.last; ++f) {
        FrameFigures figures;
        RenderReport report;
        int status = renderFrame(o, plan, f, g, bounds, bar, figures, report);
        if (showProgress) bar->finish();
        if (status == 0) status = writeFrame(o, plan, imageHelper, report, figures);
        if (status) return status;
        done.push_back(std::move(figures));
    }
    printFrames(o, plan, g, compiled, done, bounds.seconds());
    return 0;
}

void printText(const RenderCommandOptions& o, const RenderReport& report) {
    const tracer::RenderResult& result = report.result;
    std::cout << fmt::format("{}: wrote {} ({}x{}) in {:.3f} s\n", o.scene, o.output, o.width,
                             o.height, result.seconds);
    report.stats.print(std::cout);
    if (!report.count.complete)
        std::cout << fmt::format("{:<24}{}\n", "primitive equivalence",
                                 "too large to count (the system uses rand() or choose())");
    std::cout << fmt::format("{:<24}{}\n", "graph nodes", report.graphNodes);
    std::cout << fmt::format("{:<24}{}\n", "node visits", result.nodeVisits);
    if (result.instanceBoxes.entries > 0)
        std::cout << fmt::format(
            "{:<24}{} instances, {}{}\n", "instance-box cache", result.instanceBoxes.entries,
            humanBytes(result.instanceBoxes.bytes), result.instanceBoxes.full ? " (full)" : "");
    if (const tracer::RenderResult::TopLevelFigures& top = result.topLevel; top.built)
        std::cout << fmt::format("{:<24}{}, {}\n", "top level",
                                 top.deferred > 0
                                     ? fmt::format("{} cuts deferred to the walk", top.deferred)
                                     : fmt::format("{} copies of {} instance{}", top.copies,
                                                   top.instances, top.instances == 1 ? "" : "s"),
                                 humanBytes(top.bytes));
    if (report.helper)
        std::cout << fmt::format("{:<24}{} ({}, {:.3f} s after the render)\n",
                                 "image writer peak RSS", humanBytes(report.helper->peakRssBytes),
                                 kImageHelperName, report.imageWriteSeconds);
    else
        std::cout << fmt::format("{:<24}{:.3f} s (libpng, {})\n", "image write time",
                                 report.imageWriteSeconds,
                                 report.png ? "rows written while rendering" : "in this process");
    if (o.distributed) std::cout << rankFiguresText(o.distributed->finish(0));
}

int runStill(const RenderCommandOptions& o, CompiledScene& compiled,
             const std::string& imageHelper);
int runRender(const RenderCommandOptions& o);
int runRenderCommand(RenderCommandOptions& o);

// A video (-o OUT.mp4, .webm, .gif): the frames rendered as PNG files, then encoded by
// ffmpeg; checked before anything is rendered.
int runVideo(const RenderCommandOptions& o) {
    if (o.frames == 0) {
        std::cerr << "pcsg render: error: a video (" << o.output << ") needs --frames N\n";
        return 2;
    }
    if (!inPath("ffmpeg")) {
        std::cerr << "pcsg render: cannot write '" << o.output
                  << "': ffmpeg is not installed (it encodes the frames): install it with "
                     "`apt-get install ffmpeg`\n";
        return 2;
    }
    FramePlan plan;
    if (!framePlan(o, plan)) return 2;
    VideoFrames frames;
    std::string error;
    if (!videoFramesFor(o.output, o.keepFrames, frames, error)) {
        std::cerr << "pcsg render: " << error << "\n";
        return 2;
    }
    RenderCommandOptions fo = o;
    fo.output = frames.pattern;
    int status = runRender(fo);
    if (status == 0) {
        error = encodeVideo(o.output, frames.pattern, plan.first, plan.last, plan.frames, o.fps);
        if (!error.empty()) {
            std::cerr << "pcsg render: " << error << "\n";
            status = 2;
        } else if (!o.json) {
            std::cout << fmt::format("{}: wrote {} ({} frames at {} fps{})\n", o.scene, o.output,
                                     plan.last - plan.first + 1, o.fps,
                                     o.keepFrames ? ", frames kept" : "");
        }
    }
    removeVideoFrames(frames);
    return status;
}

int runRender(const RenderCommandOptions& o) {
    if (isVideoOutput(o.output)) return runVideo(o);
    FramePlan plan;
    if (o.frames > 0 && !framePlan(o, plan)) return 2;
    // Before the render: without a writer, the render would be for nothing.
    std::string imageHelper;
    if (imageFormatOf(o.output) != ImageFormat::png) {
        const std::optional<std::string> found = findImageHelper();
        if (!found) {
            std::cerr << "pcsg render: cannot write '" << o.output
                      << "': " << missingImageHelperMessage() << "\n";
            return 2;
        }
        imageHelper = *found;
    }
    CompiledScene compiled = compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    if (o.frames > 0) return runFrames(o, plan, compiled, imageHelper);
    return runStill(o, compiled, imageHelper);
}

// One image at --clock (clock 0 without it), frame 1.
int runStill(const RenderCommandOptions& o, CompiledScene& compiled,
             const std::string& imageHelper) {
    Graph& g = *compiled.graph;
    if (!setSceneTime(g, Time{o.clock, o.frame}, std::cerr)) return 1;
    RenderReport report;
    if (const int status = countAndRender(g, o, report)) return status;
    if (const std::string error = writeOutput(o, imageHelper, report); !error.empty()) {
        std::cerr << "pcsg render: " << error << "\n";
        return 2;
    }
    report.result.rgb = std::vector<float>();  // written: the printing needs only the figures
    report.graphNodes = g.nodes.size();
    Stats& s = report.stats;
    s.scene = o.scene;
    s.width = static_cast<uint32_t>(o.width);
    s.height = static_cast<uint32_t>(o.height);
    s.graphBytes = g.graphBytes();
    s.parseSeconds = compiled.seconds;
    if (report.count.complete) s.primitiveEquivalence = report.count.primitives;
    s.rays = report.result.rays;
    s.seconds = report.result.seconds;
    s.raysPerSecond = s.seconds > 0 ? report.result.rays / *s.seconds : 0.0;
    s.peakRssBytes = wholeCommandPeakRssBytes();  // the helper's included
    if (o.json)
        printJson(o, report);
    else
        printText(o, report);
    return 0;
}

// Under mpirun or srun (docs/distributed.md): rank 0 runs the command as one process
// would, with the pixels rendered by every rank; the other ranks render what rank 0 hands
// them. Without a launcher: one process, no MPI.
int runRenderCommand(RenderCommandOptions& o) {
    if (!launchedAsRanks()) return runRender(o);
    std::string error;
    const std::unique_ptr<MpiSession> session = MpiSession::start(error);
    if (!session) {
        if (launcherRank() == 0) std::cerr << "pcsg render: error: " << error << "\n";
        return 2;
    }
    if (session->size() == 1) return runRender(o);
    if (session->rank() != 0)
        return runWorkerRank(*session, o.scene, tracerOptions(o), o.countVisits);
    DistributedRender distributed(*session);
    int status = 0;
    if (o.scene == "-" || !o.tileTimes.empty()) {
        std::cerr << "pcsg render: error: "
                  << (o.scene == "-" ? "a distributed render reads the scene from a file (every "
                                       "rank compiles it), not from standard input"
                                     : "--tile-times measures one process: run it without mpirun")
                  << "\n";
        status = 2;
    } else {
        o.distributed = &distributed;
        status = runRender(o);
        o.distributed = nullptr;
    }
    distributed.finish(status);
    return status;
}

// CLI11 validator: the output's extension names an image type pcsg writes.
const CLI::Validator kImageOutput(
    [](const std::string& path) -> std::string {
        if (imageFormatOf(path) || isVideoOutput(path)) return {};
        return fmt::format("cannot write '{}': unknown image type ({}; a video: .mp4, .webm, .gif)",
                           path, kImageTypesHint);
    },
    "IMAGE");

// --clock, or --frames and what goes with it (docs/language.md section 11).
void addTimeOptions(CLI::App* cmd, RenderCommandOptions& o) {
    auto* clock = addClockOption(cmd, o.clock);
    auto* frames =
        cmd->add_option("--frames", o.frames,
                        "Render N frames of an animation, named like POV-Ray's: the frame "
                        "number zero-padded to the width of N before the extension (OUT01.png "
                        "... OUT24.png); frame f has clock A + (f-1)(B-A)/(N-1)")
            ->check(CLI::Range(1, 1000000));
    clock->excludes(frames);
    addFrameOption(cmd, o.frame)->excludes(frames);
    cmd->add_option("--clock-range", o.clockRange,
                    "A,B: the clocks of the first and last frame (default 0,1)")
        ->needs(frames);
    cmd->add_flag("--cyclic", o.cyclic,
                  "A cyclic animation (POV-Ray's +KC): the clock steps by (B-A)/N, so the last "
                  "frame is not B")
        ->needs(frames);
    cmd->add_option("--subset", o.subset, "F,L: render only frames F to L of the N")->needs(frames);
    cmd->add_option("--fps", o.fps, "A video's frame rate (-o OUT.mp4, .webm or .gif)")
        ->capture_default_str()
        ->check(CLI::Range(0.1, 1000.0))
        ->needs(frames);
    cmd->add_flag("--keep-frames", o.keepFrames,
                  "Keep a video's frames, as PNG files next to it under POV-Ray's names")
        ->needs(frames);
    cmd->add_option("--frame-bounds", o.frameBounds,
                    "The sequence's bounding boxes hold for its whole clock range, computed "
                    "once; each frame computes its own tighter ones too: on, off, or auto "
                    "(while they take under 2% of the frame's render time, re-measured one frame "
                    "in 8 while off). The pixels are the same either way")
        ->capture_default_str()
        ->check(CLI::IsMember({"auto", "on", "off"}))
        ->needs(frames);
}

}  // namespace

void addRenderCommand(CLI::App& app, int& status) {
    auto o = std::make_shared<RenderCommandOptions>();
    auto* cmd = app.add_subcommand(
        "render",
        "Ray trace a scene's cyclic CSG graph directly, without expanding it, and write the "
        "image (.png 8-bit sRGB, .exr linear float, .tif 16-bit sRGB). Camera, lights and "
        "materials follow POV-Ray 3.7, so the image can be compared with POV-Ray's rendering "
        "of `pcsg export-pov`. Prints rays, rays per second, primitive equivalence (the "
        "primitives the expanded tree would hold), graph bytes, peak memory and time. A PNG is "
        "written in this process; an EXR or TIFF file by the pcsg-image helper (found beside "
        "pcsg, or in PATH), which gets the pixels through a pipe once they exist.\n"
        "Under `mpirun -np N pcsg render ...` (or srun) the render is spread over N ranks, "
        "each using --threads cores, and rank 0 writes the same image (docs/distributed.md).\n"
        "Exit status: 0 written, 1 the scene has an error (nothing written), 2 could not run.");
    cmd->add_option("scene", o->scene, "The .pcsg file (- reads standard input)")->required();
    cmd->add_option("-o,--output", o->output,
                    "The image to write: .png, .exr, .tif or .tiff; or a video with --frames: "
                    ".mp4, .webm or .gif (encoded by ffmpeg)")
        ->required()
        ->check(kImageOutput);
    cmd->add_option("--width", o->width, "Image width in pixels")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    cmd->add_option("--height", o->height, "Image height in pixels")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    auto* aa = cmd->add_option("--aa", o->aa,
                               "Anti-aliasing: N x N stratified samples per pixel (1: none)")
                   ->capture_default_str()
                   ->check(CLI::Range(1, 64));
    cmd->add_option("--adaptive", o->adaptive,
                    "Adaptive anti-aliasing like POV-Ray's +A T (e.g. 0.3): pixels that differ "
                    "from a neighbour by T or more get 9 more samples (0: off)")
        ->capture_default_str()
        ->check(CLI::Range(0.0, 3.0))
        ->excludes(aa);
    cmd->add_option("--threads", o->threads,
                    "Worker threads (0: all cores); the image is the "
                    "same whatever the count")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    addTimeOptions(cmd, *o);
    cmd->add_flag("--json", o->json, "Print the figures as JSON");
    cmd->add_flag("--no-bounds", o->noBounds,
                  "Do not cull with hyper-bounding boxes (slow; for checking that culling never "
                  "changes the image)");
    cmd->add_flag("--no-instance-boxes", o->noInstanceBoxes,
                  "Cull with the static hyper-bounding boxes alone, without the exact boxes of "
                  "sub-graph instances (for comparison; the image is the same)");
    cmd->add_option("--box-cache-mb", o->boxCacheMb,
                    "Memory limit of the instance-box cache in MB (the exact boxes of sub-graph "
                    "instances, filled lazily while rendering; with --frames, the boxes that do "
                    "not change with the time are kept for the whole sequence in a second "
                    "table with the same limit)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    cmd->add_option("--expansion-cache-mb", o->expansionCacheMb,
                    "Memory limit in MB of the cache of expanded sub-graph instances, shared "
                    "by all threads (small instances unrolled once and traced as flat arrays; "
                    "its budget starts at 2 MB and grows toward this limit where a larger "
                    "one saves expansions; 0: none; the image is the same)")
        ->capture_default_str()
        ->check(CLI::Range(0, 1 << 20));
    cmd->add_option("--count-visits", o->countVisits,
                    "Work limit of the primitive-equivalence count in graph-node visits")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    cmd->add_option("--tile-times", o->tileTimes,
                    "Write every tile's cost (its thread's CPU seconds) to FILE as CSV "
                    "(pass,x0,y0,x1,y1,seconds), "
                    "for tools/dev/mpi_schedule_sim.py (docs/distributed.md); one process only")
        ->group("");  // hidden: a measuring tool
    cmd->callback([o, &status] { status = runRenderCommand(*o); });
}

}  // namespace pcsg::tools
