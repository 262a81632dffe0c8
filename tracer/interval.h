// Interval arithmetic over the expression code of the graph, for the bounds analysis
// (bounds.h): what values can an expression take when its slots range over intervals?
//
// An Interval is a set of doubles: the reals in [lo, hi] (either end may be infinite,
// meaning unbounded) plus NaN when `nan` is set. The empty set with no NaN ("bottom") is
// the result of an expression that cannot evaluate without a run-time error (it reads a
// slot that is never assigned on the paths considered); a traversal never gets past such
// an evaluation, so the analysis may drop those paths.
//
// Every operation is sound: the result contains every value the concrete operation of
// eval.cpp produces for operands in the given sets (rounding is monotone, so evaluating
// monotone pieces at the ends with the same double operations keeps the result sound).
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "graph.h"

namespace pcsg::tracer {

struct Interval {
    static constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo = kInf, hi = -kInf;  // default: no real values
    bool nan = false;

    static Interval point(double v);
    static Interval of(double lo, double hi) { return Interval{lo, hi, false}; }
    static Interval all() { return Interval{-kInf, kInf, true}; }
    static Interval bottom() { return Interval{}; }

    bool hasReals() const { return lo <= hi; }
    bool isBottom() const { return !hasReals() && !nan; }
    bool isPoint() const { return lo == hi && !nan; }
    bool contains(double v) const;
    bool operator==(const Interval&) const = default;
};

Interval join(const Interval& a, const Interval& b);

// One slot of an abstract frame: the values it may hold, and whether it may be unassigned.
struct AbstractSlot {
    Interval value;
    bool unassigned = true;
    bool operator==(const AbstractSlot&) const = default;
};
using AbstractFrame = std::vector<AbstractSlot>;

// Joins b into a; returns true when a changed.
bool joinInto(AbstractFrame& a, const AbstractFrame& b);

// Widening: bounds of `next` that moved beyond `prev` go to infinity. Returns next widened.
AbstractFrame widen(const AbstractFrame& prev, const AbstractFrame& next);

// `time`, in the functions below: the times `clock` and `frame` range over; nullptr: the
// graph's time alone (Graph::time).
//
// Evaluates an expression on intervals (bottom when every evaluation fails). The seed is
// the scene's, so that rand(x) of a known x is known.
Interval evalInterval(const Graph& g, ExprId e, const AbstractFrame& frame,
                      const TimeRange* time = nullptr);

// The same, path by path: one interval per way through the expression's `if`s and
// short-circuit operators (their union is evalInterval's result, up to the join).
std::vector<Interval> evalIntervalPaths(const Graph& g, ExprId e, const AbstractFrame& frame,
                                        const TimeRange* time = nullptr);

// A C-node on intervals: false when every evaluation fails (the child is unreachable).
bool applyCalcInterval(const Graph& g, NodeId calcNode, const AbstractFrame& in, AbstractFrame& out,
                       const TimeRange* time = nullptr);

// The rules (0-based) an S-node may select in the frame; empty when every selection fails.
// `mayFail`, when given, is set when the selection may be a run-time error for some values
// in the frame (a rule number out of range or not finite, no notation-B condition true).
std::vector<uint32_t> reachableRules(const Graph& g, NodeId selectNode, const AbstractFrame& frame,
                                     bool* mayFail = nullptr, const TimeRange* time = nullptr);

// An affine map whose entries are intervals: it stands for every matrix with entries in
// them. transformBox applies all of them to a box (zero times an unbounded side is zero:
// boxes hold finite points).
struct IntervalAffine {
    Interval l[3][3];
    Interval t[3];
    static IntervalAffine of(const Affine& m);
};

// The matrices a T-node may have in the frame (the NaN and non-finite parts of its
// arguments are run-time errors and are left out). Returns false when every evaluation
// fails.
bool transformInterval(const Graph& g, NodeId transformNode, const AbstractFrame& frame,
                       IntervalAffine& out, const TimeRange* time = nullptr);

// The arguments a primitive may have (torus R r, triangle corners); false when every
// evaluation fails. `out` gets one interval per argument.
bool primitiveArgsInterval(const Graph& g, NodeId primitiveNode, const AbstractFrame& frame,
                           Interval* out, const TimeRange* time = nullptr);

Box transformBox(const IntervalAffine& m, const Box& b);

}  // namespace pcsg::tracer
