// Frame sequences of `pcsg render --frames N` (docs/language.md section 11), numbered and
// named as POV-Ray numbers and names them (+KFI1 +KFF<N> +KI<a> +KF<b> [+KC]).
#pragma once

#include <optional>
#include <string>

namespace pcsg::tools {

struct FramePlan {
    int frames = 1;                     // N
    double clockFrom = 0, clockTo = 1;  // a, b
    bool cyclic = false;                // +KC: the step is (b-a)/N, so frame N+1 would be a again
    int first = 1, last = 1;            // --subset: the frames rendered, 1 <= first <= last <= N
};

// The clock of frame f (1-based) of the plan: a + (f-1)(b-a)/(N-1), or (b-a)/N steps when
// cyclic; a when N is 1 (computed as std::lerp, so the last frame of a non-cyclic plan is b
// exactly).
double frameClock(const FramePlan& plan, int frame);

// The file of frame f of N: the frame number, zero-padded to the width of N, before the
// extension ("out.png", 24 frames: "out01.png" ... "out24.png"; 3 frames: "out1.png").
std::string frameFileName(const std::string& output, int frame, int frames);

// Whether each frame of a sequence computes its own hyper-bounding boxes (tighter than
// the boxes of the whole clock range, which the sequence computes once): --frame-bounds
// on, off, or auto. Auto computes them while they took under 2% of the frame's render
// time, judged by the cheaper of the last two frames that computed their own (so that
// one slow measurement, a thread descheduled on a loaded machine, does not switch them
// off), and re-measures one frame in every kRetry while they are off (a growing scene's
// frames get dearer as it grows, and its boxes pay again). The pixels are the same
// either way: only the time depends on this choice.
class FrameBoundsChoice {
  public:
    enum class Mode { Auto, On, Off };
    static constexpr double kShare = 0.02;
    static constexpr int kRetry = 8;

    explicit FrameBoundsChoice(Mode mode) : mode_(mode) {}
    // Whether the next frame computes its own boxes.
    bool ownBoxes() const;
    // A frame was rendered: with its own boxes (which took boundsSeconds) or with the
    // range's; renderSeconds without the boxes.
    void frameDone(bool own, double boundsSeconds, double renderSeconds);

  private:
    Mode mode_;
    double share_[2] = {0, 0};  // the last two own frames' boxes / render time
    int sinceOwn_ = 0;          // frames rendered with the range's boxes since the last own
};

// "on", "off" or "auto" (the --frame-bounds values); nothing otherwise.
std::optional<FrameBoundsChoice::Mode> frameBoundsMode(const std::string& text);

// Makes every thread allocate from one malloc arena (glibc's M_ARENA_MAX; nothing
// elsewhere), before a sequence's first frame. The tracer threads of each frame allocate
// their tables (the step memo's 1.4 MB, the expansion cache) and free them at its end;
// in arenas of their own, what a frame's threads freed stays resident beside what the
// next frame's threads allocate in others: 19 to 27 MB for 3 frames of the growing tree
// at 640x480 on two threads, 17.9 MB with one arena, as much as one frame alone. The
// tracer allocates nothing per ray, so the threads do not contend for the one arena.
void useOneMallocArena();

// "A,B": two finite numbers, A <= B. Nothing, with `error` set, otherwise.
std::optional<std::pair<double, double>> parseClockRange(const std::string& text,
                                                         std::string& error);

// "F,L": whole numbers, 1 <= F <= L <= frames. Nothing, with `error` set, otherwise.
std::optional<std::pair<int, int>> parseSubset(const std::string& text, int frames,
                                               std::string& error);

}  // namespace pcsg::tools
