#include "distributed_render.h"

#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <map>
#include <sstream>
#include <thread>

#include "eval.h"
#include "scene_input.h"
#include "scene_time.h"
#include "stats.h"

namespace pcsg::tools {

namespace {

enum Tag : int { kAssign = 1, kResult = 2, kStop = 3, kFinal = 4 };

// How long an idle rank's main thread sleeps between polls: short beside a unit's
// render, and the two units in flight per rank hide it.
constexpr auto kPollSleep = std::chrono::microseconds(300);
constexpr int kUnitsInFlight = 2;

// A finished unit: its pixels, or the error that stopped it.
struct UnitResult {
    WorkUnit unit;
    int status = 0;     // 0, 1 a run-time error of the scene, 2 could not run
    std::string error;  // printed as it is
    std::vector<float> rgb;
    uint64_t rays = 0, nodeVisits = 0;
    double seconds = 0, boundsSeconds = 0;
    std::optional<ExpansionCount> count;
};

struct ResultHeader {
    WorkUnit unit;
    int32_t status, counted, countComplete, pad;
    uint64_t primitives, rays, nodeVisits, errorBytes, rgbFloats;
    double seconds, boundsSeconds;
};

std::vector<std::byte> encodeResult(const UnitResult& r) {
    ResultHeader h{r.unit,
                   r.status,
                   r.count ? 1 : 0,
                   r.count && r.count->complete ? 1 : 0,
                   0,
                   r.count ? r.count->primitives : 0,
                   r.rays,
                   r.nodeVisits,
                   r.error.size(),
                   r.rgb.size(),
                   r.seconds,
                   r.boundsSeconds};
    std::vector<std::byte> out;
    out.reserve(sizeof h + r.error.size() + r.rgb.size() * sizeof(float));
    appendBytes(out, h);
    const auto* e = reinterpret_cast<const std::byte*>(r.error.data());
    out.insert(out.end(), e, e + r.error.size());
    const auto* p = reinterpret_cast<const std::byte*>(r.rgb.data());
    out.insert(out.end(), p, p + r.rgb.size() * sizeof(float));
    return out;
}

UnitResult decodeResult(const std::vector<std::byte>& bytes) {
    ResultHeader h;
    if (bytes.size() < sizeof h) throw std::runtime_error("a short result message");
    std::memcpy(&h, bytes.data(), sizeof h);
    if (bytes.size() != sizeof h + h.errorBytes + h.rgbFloats * sizeof(float))
        throw std::runtime_error("a result message of the wrong size");
    UnitResult r;
    r.unit = h.unit;
    r.status = h.status;
    const char* text = reinterpret_cast<const char*>(bytes.data() + sizeof h);
    r.error.assign(text, h.errorBytes);
    r.rgb.resize(h.rgbFloats);
    std::memcpy(r.rgb.data(), text + h.errorBytes, h.rgbFloats * sizeof(float));
    r.rays = h.rays, r.nodeVisits = h.nodeVisits;
    r.seconds = h.seconds, r.boundsSeconds = h.boundsSeconds;
    if (h.counted) {
        r.count = ExpansionCount{};
        r.count->primitives = h.primitives;
        r.count->complete = h.countComplete != 0;
    }
    return r;
}

struct FinalHeader {
    int32_t rank, units;
    uint64_t pixels, rays, nodeVisits, peakRssBytes;
    double busySeconds;
};

std::vector<std::byte> encodeFinal(const RankFigures& f) {
    const FinalHeader h{f.rank,       f.units,        f.pixels,     f.rays,
                        f.nodeVisits, f.peakRssBytes, f.busySeconds};
    std::vector<std::byte> out;
    appendBytes(out, h);
    const auto* p = reinterpret_cast<const std::byte*>(f.host.data());
    out.insert(out.end(), p, p + f.host.size());
    return out;
}

RankFigures decodeFinal(const std::vector<std::byte>& bytes) {
    FinalHeader h;
    if (bytes.size() < sizeof h) throw std::runtime_error("a short final message");
    std::memcpy(&h, bytes.data(), sizeof h);
    RankFigures f{h.rank, "",           h.units,       h.pixels,
                  h.rays, h.nodeVisits, h.busySeconds, h.peakRssBytes};
    f.host.assign(reinterpret_cast<const char*>(bytes.data() + sizeof h), bytes.size() - sizeof h);
    return f;
}

template <class T>
T decodePod(const std::vector<std::byte>& bytes) {
    T value{};
    if (bytes.size() != sizeof value) throw std::runtime_error("a message of the wrong size");
    std::memcpy(&value, bytes.data(), sizeof value);
    return value;
}

// Renders the units given to one rank, one at a time on a thread of its own (which runs
// oneTBB's parallel loops), while the rank's main thread talks to the others.
class RankWorker {
  public:
    // `g`: the rank's compiled graph (nothing when it did not compile: every unit then
    // fails with `compileError`).
    RankWorker(Graph* g, std::string scene, const tracer::RenderOptions& options,
               uint64_t countVisits, std::string compileError = {})
        : g_(g),
          scene_(std::move(scene)),
          compileError_(std::move(compileError)),
          countVisits_(countVisits),
          options_(options) {
        options_.progress = {};
        options_.cancel = &cancel_;
    }
    ~RankWorker() { cancel(); }

    void enqueue(const WorkUnit& u) {
        queue_.push_back(u);
        startNext();
    }

    // A finished unit, if there is one; the next one starts.
    bool poll(UnitResult& out) {
        if (!thread_.joinable() || !done_.load(std::memory_order_acquire)) return false;
        thread_.join();
        out = std::move(current_);
        startNext();
        return true;
    }

    // Stops the running unit at its next tile and drops the others.
    void cancel() {
        queue_.clear();
        cancel_ = true;
        if (thread_.joinable()) thread_.join();
    }

    RankFigures figures(int rank, const std::string& host) const {
        RankFigures f = figures_;
        f.rank = rank;
        f.host = host;
        f.peakRssBytes = wholeCommandPeakRssBytes();
        return f;
    }

  private:
    void startNext() {
        if (thread_.joinable() || queue_.empty()) return;
        const WorkUnit u = queue_.front();
        queue_.pop_front();
        done_ = false;
        thread_ = std::thread([this, u] {
            current_ = run(u);
            done_.store(true, std::memory_order_release);
        });
    }

    UnitResult run(const WorkUnit& u);
    void renderUnit(const WorkUnit& u, UnitResult& r);

    Graph* g_;
    std::string scene_, compileError_;
    uint64_t countVisits_;
    tracer::RenderOptions options_;
    std::atomic<bool> cancel_{false}, done_{false};
    std::deque<WorkUnit> queue_;
    std::thread thread_;
    UnitResult current_;
    int frameIndex_ = -1;  // the frame the renderer is set up for
    std::unique_ptr<tracer::RegionRenderer> renderer_;
    RankFigures figures_;
};

void RankWorker::renderUnit(const WorkUnit& u, UnitResult& r) {
    if (u.frameIndex != frameIndex_ || !renderer_) {
        renderer_.reset();
        frameIndex_ = -1;
        setTime(*g_, Time{u.clock, u.frame});
        renderer_ = std::make_unique<tracer::RegionRenderer>(*g_, options_);
        frameIndex_ = u.frameIndex;
        r.boundsSeconds = renderer_->figures().boundsSeconds;
    }
    if (u.count) {
        CountOptions co;
        co.maxVisits = countVisits_;
        r.count = countExpansion(*g_, co);
    }
    const tracer::RenderResult before = renderer_->figures();
    r.rgb = renderer_->render(tracer::Region{u.x0, u.y0, u.x1, u.y1});
    const tracer::RenderResult after = renderer_->figures();
    r.rays = after.rays - before.rays;
    r.nodeVisits = after.nodeVisits - before.nodeVisits;
}

UnitResult RankWorker::run(const WorkUnit& u) {
    const auto start = std::chrono::steady_clock::now();
    UnitResult r;
    r.unit = u;
    const std::string note =
        u.framesInSequence > 0
            ? fmt::format("\n  at frame {} of {}, clock {}", u.frame, u.framesInSequence, u.clock)
            : std::string();
    try {
        if (!g_) {
            r.status = 1;
            r.error = compileError_;
        } else {
            renderUnit(u, r);
        }
    } catch (const RuntimeError& e) {
        r.status = 1;
        r.error = e.format(*g_) + note;
    } catch (const tracer::RenderCancelled&) {
        r.status = 2;
    } catch (const std::exception& e) {
        r.status = 2;
        r.error = "pcsg render: error: " + scene_ + ": " + e.what() + note;
    }
    r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    figures_.units += 1;
    figures_.pixels += r.status == 0 ? u.pixels() : 0;
    figures_.rays += r.rays;
    figures_.nodeVisits += r.nodeVisits;
    figures_.busySeconds += r.seconds;
    return r;
}

// A frame being gathered on rank 0.
struct FrameState {
    DistributedFrame frame;
    uint64_t pixelsLeft = 0;
};

}  // namespace

// --- rank 0 ---

struct DistributedRender::Impl {
    explicit Impl(MpiSession& s) : session(s) {}

    bool handle(int rank, UnitResult& r, const std::function<int(DistributedFrame&)>& onFrame);
    void assign(const WorkUnit& u, int rank);
    bool pollOnce(const std::function<int(DistributedFrame&)>& onFrame);

    MpiSession& session;
    const DistributedJob* job = nullptr;
    std::unique_ptr<RankWorker> local;
    std::unique_ptr<WorkPlan> plan;
    std::map<int, WorkUnit> outstanding;  // by id
    std::vector<int> inFlight;            // per rank
    std::map<int, FrameState> frames;     // by frame index, while gathered
    int status = 0;
    uint64_t pixelsDone = 0;
    std::vector<RankFigures> figures;
};

DistributedRender::DistributedRender(MpiSession& session)
    : impl_(std::make_unique<Impl>(session)) {}

DistributedRender::~DistributedRender() = default;

int DistributedRender::ranks() const {
    return impl_->session.size();
}

void DistributedRender::Impl::assign(const WorkUnit& u, int rank) {
    outstanding[u.id] = u;
    ++inFlight[rank];
    if (rank == 0) {
        local->enqueue(u);
        return;
    }
    std::vector<std::byte> bytes;
    appendBytes(bytes, u);
    session.send(rank, kAssign, std::move(bytes));
}

// Places a finished unit's pixels; false once the render must stop (an error).
bool DistributedRender::Impl::handle(int rank, UnitResult& r,
                                     const std::function<int(DistributedFrame&)>& onFrame) {
    --inFlight[rank];
    outstanding.erase(r.unit.id);
    if (r.status != 0) {
        if (status == 0 && !r.error.empty()) std::cerr << r.error << "\n";
        if (status == 0) status = r.status;
        return false;
    }
    const WorkUnit& u = r.unit;
    FrameState& f = frames[u.frameIndex];
    if (f.frame.rgb.empty()) {
        f.frame.frame = plan->frames()[u.frameIndex];
        f.pixelsLeft = plan->framePixels();
        if (u.pixels() == plan->framePixels())
            f.frame.rgb = std::move(r.rgb);
        else
            f.frame.rgb.assign(plan->framePixels() * 3, 0.0f);
    }
    if (!r.rgb.empty()) {
        const size_t row = static_cast<size_t>(u.x1 - u.x0) * 3;
        for (int y = u.y0; y < u.y1; ++y)
            std::copy_n(
                r.rgb.data() + (y - u.y0) * row, row,
                f.frame.rgb.data() + (static_cast<size_t>(y) * job->render.width + u.x0) * 3);
    }
    f.frame.rays += r.rays;
    f.frame.nodeVisits += r.nodeVisits;
    f.frame.renderSeconds += r.seconds;
    f.frame.boundsSeconds = std::max(f.frame.boundsSeconds, r.boundsSeconds);
    if (r.count) f.frame.count = r.count;
    f.pixelsLeft -= u.pixels();
    pixelsDone += u.pixels();
    if (job->render.progress)
        job->render.progress(static_cast<double>(pixelsDone) / plan->totalPixels());
    if (f.pixelsLeft > 0) return true;
    DistributedFrame done = std::move(f.frame);
    frames.erase(u.frameIndex);
    status = onFrame(done);
    return status == 0;
}

// Hands out units and takes in results once; false when the render is over.
bool DistributedRender::Impl::pollOnce(const std::function<int(DistributedFrame&)>& onFrame) {
    bool busy = false;
    for (int rank = 0; rank < session.size(); ++rank)
        while (inFlight[rank] < kUnitsInFlight) {
            const auto u = plan->next();
            if (!u) break;
            assign(*u, rank);
            busy = true;
        }
    UnitResult r;
    while (local->poll(r)) {
        busy = true;
        if (!handle(0, r, onFrame)) return false;
    }
    MpiMessage m;
    while (session.receive(m)) {
        busy = true;
        if (m.tag != kResult) continue;
        r = decodeResult(m.bytes);
        if (!handle(m.source, r, onFrame)) return false;
    }
    if (outstanding.empty()) return false;
    if (!busy) std::this_thread::sleep_for(kPollSleep);
    return true;
}

int DistributedRender::render(Graph& g, const DistributedJob& job,
                              const std::function<int(DistributedFrame&)>& onFrame) {
    Impl& s = *impl_;
    s.job = &job;
    s.local = std::make_unique<RankWorker>(&g, job.scene, job.render, job.countVisits);
    s.plan = std::make_unique<WorkPlan>(job.render.width, job.render.height, job.frames,
                                        job.framesInSequence, s.session.size());
    s.inFlight.assign(s.session.size(), 0);
    s.status = 0;
    s.pixelsDone = 0;
    try {
        while (s.pollOnce(onFrame)) {
        }
    } catch (const std::exception& e) {
        std::cerr << "pcsg render: error: " << e.what() << "\n";
        s.status = 2;
    }
    s.local->cancel();
    return s.status;
}

const std::vector<RankFigures>& DistributedRender::finish(int status) {
    Impl& s = *impl_;
    if (finished_) return s.figures;
    finished_ = true;
    const int32_t st = status;
    for (int rank = 1; rank < s.session.size(); ++rank) {
        std::vector<std::byte> bytes;
        appendBytes(bytes, st);
        s.session.send(rank, kStop, std::move(bytes));
    }
    s.figures.assign(s.session.size(), RankFigures{});
    if (s.local) s.local->cancel();
    s.figures[0] = s.local ? s.local->figures(0, s.session.host()) : RankFigures{};
    s.figures[0].rank = 0;
    s.figures[0].host = s.session.host();
    s.figures[0].peakRssBytes = wholeCommandPeakRssBytes();
    int waiting = s.session.size() - 1;
    MpiMessage m;
    while (waiting > 0) {
        if (!s.session.receive(m)) {
            std::this_thread::sleep_for(kPollSleep);
            continue;
        }
        if (m.tag != kFinal) continue;  // a result that came too late
        RankFigures f = decodeFinal(m.bytes);
        if (f.rank > 0 && f.rank < s.session.size()) s.figures[f.rank] = std::move(f);
        --waiting;
    }
    return s.figures;
}

// --- the other ranks ---

namespace {

// The test suite's way of killing a rank mid-render (tests/mpi_render.sh): the rank
// named by PCSG_MPI_TEST_ABORT_RANK aborts when its second unit arrives.
void abortIfTestSaysSo(int rank, int unitsReceived) {
    const char* v = std::getenv("PCSG_MPI_TEST_ABORT_RANK");
    if (v && std::atoi(v) == rank && unitsReceived == 2) std::abort();
}

}  // namespace

int runWorkerRank(MpiSession& session, const std::string& scene,
                  const tracer::RenderOptions& options, uint64_t countVisits) {
    std::ostringstream diagnostics;
    CompiledScene compiled;
    if (scene == "-")  // standard input goes to rank 0 alone, which reports it
        diagnostics << "standard input is read by rank 0 alone\n";
    else
        compiled = compileScene(scene, diagnostics);
    const std::string compileError =
        fmt::format("pcsg render: error: rank {} ({}) cannot compile {}:\n{}", session.rank(),
                    session.host(), scene, diagnostics.str());
    Graph* g = compiled.graph ? &*compiled.graph : nullptr;
    RankWorker worker(g, scene, options, countVisits, compileError);
    int received = 0;
    MpiMessage m;
    for (;;) {
        bool busy = false;
        while (session.receive(m)) {
            busy = true;
            if (m.tag == kAssign) {
                abortIfTestSaysSo(session.rank(), ++received);
                worker.enqueue(decodePod<WorkUnit>(m.bytes));
            } else if (m.tag == kStop) {
                worker.cancel();
                session.send(0, kFinal,
                             encodeFinal(worker.figures(session.rank(), session.host())));
                return decodePod<int32_t>(m.bytes);
            }
        }
        UnitResult r;
        while (worker.poll(r)) {
            busy = true;
            if (r.status == 2 && r.error.empty()) continue;  // cancelled
            session.send(0, kResult, encodeResult(r));
        }
        if (!busy) std::this_thread::sleep_for(kPollSleep);
    }
}

nlohmann::json rankFiguresJson(const std::vector<RankFigures>& ranks) {
    nlohmann::json list = nlohmann::json::array();
    for (const RankFigures& f : ranks)
        list.push_back({{"rank", f.rank},
                        {"host", f.host},
                        {"units", f.units},
                        {"pixels", f.pixels},
                        {"rays", f.rays},
                        {"node_visits", f.nodeVisits},
                        {"busy_seconds", f.busySeconds},
                        {"peak_rss_bytes", f.peakRssBytes}});
    return list;
}

std::string rankFiguresText(const std::vector<RankFigures>& ranks) {
    std::string out;
    uint64_t rss = 0;
    for (const RankFigures& f : ranks) {
        rss += f.peakRssBytes;
        out += fmt::format(
            "  rank {:<3} {:<16} {:>5} units {:>10} pixels {:>8.3f} s busy  peak RSS {}\n", f.rank,
            f.host, f.units, f.pixels, f.busySeconds, humanBytes(f.peakRssBytes));
    }
    return fmt::format("{:<24}{} (peak RSS of all ranks together: {})\n", "ranks", ranks.size(),
                       humanBytes(rss)) +
           out;
}

}  // namespace pcsg::tools
