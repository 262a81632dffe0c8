// How the distributed renderer (distributed_render.h) cuts a render into units of work,
// handed out by rank 0 one at a time as ranks ask for them (master/worker).
//
//  - Fewer frames than ranks (a still is one frame): each frame is cut into tiles of
//    kWorkTile x kWorkTile pixels, and a unit is a run of them: whole rows of tiles, or
//    part of one row. Guided self-scheduling: a unit takes ceil(R / (f P)) of the R tiles
//    not yet handed out (P ranks, f = min(16, 2 P)), at least one, within one row unless
//    it takes whole rows, and never more than its frame has left. So units start large
//    (few messages) and shrink to single tiles at the end (the ranks finish together).
//    f: the terrain's cost per row varies 30-fold, so with two units in flight per rank
//    the first units must be a small share of the work or one rank gets too much of the
//    costly rows; but each unit also recomputes the centres of a one-pixel border
//    (adaptive sampling), so a few ranks want few units. docs/distributed.md shows the
//    simulated trade-off.
//  - As many frames as ranks or more: a unit is a whole frame.
// Units are handed out in frame order; the first unit of a frame also counts that frame's
// expansion (the primitive equivalence, and the run-time errors no ray would find).
// tools/dev/mpi_schedule_sim.py simulates this schedule: keep the two in step.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

namespace pcsg::tools {

constexpr int kWorkTile = 32;
constexpr int kMaxGuidedFactor = 16;

struct WorkFrame {
    int frame = 1;     // its number in the sequence (1 for a still)
    double clock = 0;  // its time
};

// One unit, sent as bytes from rank 0 to a rank (the same executable on every rank).
struct WorkUnit {
    int32_t id = 0;
    int32_t frameIndex = 0;        // into the plan's frames
    int32_t frame = 1;             // WorkFrame::frame
    int32_t framesInSequence = 0;  // 0: a still (no frame in error messages)
    double clock = 0;
    int32_t x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // the pixels, [x0, x1) x [y0, y1)
    int32_t count = 0;                       // 1: the frame's first unit: count the expansion
    int32_t pad = 0;
    uint64_t pixels() const { return static_cast<uint64_t>(x1 - x0) * (y1 - y0); }
};

class WorkPlan {
  public:
    WorkPlan(int width, int height, std::vector<WorkFrame> frames, int framesInSequence, int ranks,
             int tile = kWorkTile);

    // The next unit, or nothing when all have been handed out.
    std::optional<WorkUnit> next();

    uint64_t totalPixels() const;
    const std::vector<WorkFrame>& frames() const { return frames_; }
    uint64_t framePixels() const { return static_cast<uint64_t>(width_) * height_; }

  private:
    int width_, height_, tile_, tilesX_, tilesY_, ranks_, factor_, framesInSequence_;
    std::vector<WorkFrame> frames_;
    bool wholeFrames_;
    int frameIndex_ = 0, tileInFrame_ = 0, nextId_ = 0;
    int64_t tilesLeft_;  // over every frame not yet handed out
};

}  // namespace pcsg::tools
