// `mpirun -np N pcsg render ...`: the render spread over N ranks (docs/distributed.md).
//
//  - Every rank compiles the scene. Rank 0 runs the command as one process would, but the
//    pixels come from every rank: rank 0 hands out units of work (work_plan.h) on demand,
//    two in flight per rank (one rendering, one waiting, so no rank waits for a message),
//    gathers the pixels and writes the image. Rank 0 renders too.
//  - Each rank renders its units on its own cores through oneTBB (--threads per rank),
//    with tracer::RegionRenderer, so each pixel is the one a single process computes.
//  - A rank's main thread does all the MPI calls and never blocks in MPI: it polls, and
//    sleeps a fraction of a millisecond when there is nothing to do, so the render
//    threads keep the cores.
//  - Errors: a run-time error of the scene, on any rank, reaches rank 0, which prints it
//    once; every rank then exits with its status. A rank that dies ends the whole job:
//    mpirun kills the others and names the rank (the image writers write a temporary
//    file and rename it, and only once every pixel is in, so no partial image is left).
#pragma once

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "expander.h"
#include "graph.h"
#include "mpi_session.h"
#include "render.h"
#include "work_plan.h"

namespace pcsg::tools {

// What one rank did, gathered by rank 0 at the end.
struct RankFigures {
    int rank = 0;
    std::string host;
    int units = 0;
    uint64_t pixels = 0, rays = 0, nodeVisits = 0;
    double busySeconds = 0;  // rendering (and counting) its units
    uint64_t peakRssBytes = 0;
};

// A frame whose every pixel has arrived at rank 0.
struct DistributedFrame {
    WorkFrame frame;
    std::vector<float> rgb;
    uint64_t rays = 0, nodeVisits = 0;
    double renderSeconds = 0;  // the sum of its units' render times, over the ranks
    double boundsSeconds = 0;  // on the rank of its first unit
    std::optional<ExpansionCount> count;
};

struct DistributedJob {
    std::string scene;  // for error messages
    tracer::RenderOptions render;
    uint64_t countVisits = 0;
    std::vector<WorkFrame> frames;  // a still: one
    int framesInSequence = 0;       // 0: a still
};

// Rank 0's side.
class DistributedRender {
  public:
    explicit DistributedRender(MpiSession& session);
    ~DistributedRender();

    // Renders the job on every rank; `onFrame` gets each frame as it completes (in frame
    // order when units are tiles, else as they come) and returns a status (non-zero
    // stops the render). Returns 0, or the status of the first error, printed once.
    // `g` is rank 0's compiled graph; the render sets its time per frame.
    int render(Graph& g, const DistributedJob& job,
               const std::function<int(DistributedFrame&)>& onFrame);

    // Ends every other rank with this status and gathers every rank's figures (rank 0's
    // included); later calls return the same figures.
    const std::vector<RankFigures>& finish(int status);
    bool finished() const { return finished_; }
    int ranks() const;

  private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    bool finished_ = false;
};

// A rank other than 0: compiles the scene (silently: rank 0 reports errors), renders the
// units it is given until rank 0 says stop, and returns the status rank 0 sends.
int runWorkerRank(MpiSession& session, const std::string& scene,
                  const tracer::RenderOptions& options, uint64_t countVisits);

// The per-rank figures as JSON, and as text lines.
nlohmann::json rankFiguresJson(const std::vector<RankFigures>& ranks);
std::string rankFiguresText(const std::vector<RankFigures>& ranks);

}  // namespace pcsg::tools
