#include "work_plan.h"

#include <algorithm>
#include <stdexcept>

namespace pcsg::tools {

WorkPlan::WorkPlan(int width, int height, std::vector<WorkFrame> frames, int framesInSequence,
                   int ranks, int tile)
    : width_(width),
      height_(height),
      tile_(tile),
      tilesX_((width + tile - 1) / tile),
      tilesY_((height + tile - 1) / tile),
      ranks_(std::max(1, ranks)),
      factor_(std::min(kMaxGuidedFactor, 2 * ranks_)),
      framesInSequence_(framesInSequence),
      frames_(std::move(frames)),
      wholeFrames_(static_cast<int>(frames_.size()) >= ranks_),
      tilesLeft_(static_cast<int64_t>(tilesX_) * tilesY_ * static_cast<int64_t>(frames_.size())) {
    if (width <= 0 || height <= 0 || tile <= 0)
        throw std::invalid_argument("work plan: the image and tile sizes must be positive");
}

uint64_t WorkPlan::totalPixels() const {
    return framePixels() * frames_.size();
}

std::optional<WorkUnit> WorkPlan::next() {
    if (frameIndex_ >= static_cast<int>(frames_.size())) return std::nullopt;
    const int frameTiles = tilesX_ * tilesY_;
    const int row = tileInFrame_ / tilesX_, col = tileInFrame_ % tilesX_;
    const int64_t share = static_cast<int64_t>(factor_) * ranks_;
    int64_t take = std::max<int64_t>(1, (tilesLeft_ + share - 1) / share);
    if (wholeFrames_) take = frameTiles;
    WorkUnit u;
    u.id = nextId_++;
    u.frameIndex = frameIndex_;
    u.frame = frames_[frameIndex_].frame;
    u.clock = frames_[frameIndex_].clock;
    u.framesInSequence = framesInSequence_;
    u.count = tileInFrame_ == 0 ? 1 : 0;
    int taken;
    if (col == 0 && take >= tilesX_) {
        const int rows = static_cast<int>(std::min<int64_t>(take / tilesX_, tilesY_ - row));
        u.x0 = 0, u.x1 = width_;
        u.y0 = row * tile_, u.y1 = std::min(height_, (row + rows) * tile_);
        taken = rows * tilesX_;
    } else {
        const int n = static_cast<int>(std::min<int64_t>(take, tilesX_ - col));
        u.x0 = col * tile_, u.x1 = std::min(width_, (col + n) * tile_);
        u.y0 = row * tile_, u.y1 = std::min(height_, (row + 1) * tile_);
        taken = n;
    }
    tileInFrame_ += taken;
    tilesLeft_ -= taken;
    if (tileInFrame_ >= frameTiles) {
        tileInFrame_ = 0;
        ++frameIndex_;
    }
    return u;
}

}  // namespace pcsg::tools
