// The one semantics of a cyclic CSG graph: evaluating expressions, what an S-node
// selects, what a C-node assigns, what a T-node's matrix is, and the instance path
// behind rand(). The tracer and the expander both call these functions and nothing
// else to give a graph its meaning (docs/language.md sections 3, 4 and 6).
//
// A parameter frame is a plain array of Graph::slotCount() doubles owned by the
// caller (a stack buffer or a per-thread arena: no allocation per visit). A slot that
// has not been assigned on the current path holds the bit pattern kUnassigned.
#pragma once

#include <cstdint>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "graph.h"

namespace pcsg {

// A run-time error of docs/language.md: rule number out of range, no notation-B rule applies,
// a non-finite value in a selection or transformation, a zero scale factor, an
// unassigned parameter, max_depth exceeded. Thrown by the functions below; the tracer
// and the expander add the module path as the exception passes their S-node visits,
// report it once and exit with status 1.
class RuntimeError : public std::runtime_error {
  public:
    RuntimeError(FileLoc loc, std::string message);

    FileLoc loc;
    std::string message;                  // without location or module path
    std::vector<std::string> modulePath;  // outermost first, filled in while unwinding

    // Called by a traversal at each S-node the error passes on its way out.
    void enterModule(const std::string& name) { modulePath.insert(modulePath.begin(), name); }
    // "file:line:col: error: message\n  module path: A -> B -> C".
    std::string format(const Graph& g) const;
};

// The bit pattern of an unassigned slot (a NaN no arithmetic produces).
inline constexpr uint64_t kUnassignedBits = 0x7ff4dead0000beefULL;
double unassigned();
bool isUnassigned(double v);

// Fills a new frame: every slot unassigned. `frame` has g.slotCount() doubles.
void initFrame(const Graph& g, double* frame);

// --- instance paths (docs/language.md section 6) ---------------------------------------------
// The instance path is a 64-bit hash of the choices from the axiom down: which child of
// each operator and which rule of each S-node. Unary nodes leave it unchanged.
inline constexpr uint64_t kRootPath = 0x9e3779b97f4a7c15ULL;
uint64_t pathChild(uint64_t path, uint32_t childIndex);
uint64_t pathRule(uint64_t path, uint32_t ruleIndex);

// The random numbers of the language: both pure functions, uniform in [0,1).
double randOf(uint64_t seed, double x);                          // rand(x)
double randAt(uint64_t seed, uint64_t path, uint32_t callSite);  // rand()

// --- evaluation ------------------------------------------------------------------------
// Everything the functions below need besides the node: the frame, the instance path.
struct EvalState {
    const double* frame;
    uint64_t path;
};

// Evaluates an expression. Throws RuntimeError when it reads an unassigned slot.
// Non-finite results are returned as they are (only selections and transformations
// reject them).
double evalExpr(const Graph& g, ExprId e, EvalState s);

// The rule an S-node takes, as a 0-based child index. Throws RuntimeError when the
// number is out of range, non-finite, or no notation-B condition holds.
uint32_t selectRule(const Graph& g, NodeId selectNode, EvalState s);

// Applies a C-node: `out` (g.slotCount() doubles, may not alias `in`) becomes `in`
// with the C-node's assignments applied in order (or simultaneously for a call).
void applyCalc(const Graph& g, NodeId calcNode, EvalState in, double* out);

// A T-node's matrix for the given state: it maps points of the child's frame into the
// T-node's frame. Throws RuntimeError on a non-finite argument or a singular matrix.
// Constant transforms return their precomputed matrix.
Affine transformMatrix(const Graph& g, NodeId transformNode, EvalState s);

// transformMatrix() and the matrix's inverse (Affine::inverse()'s doubles, bit for bit). A
// terrain's terminating rules move() and zshear() a triangle per instance: their inverses
// are built directly, without the general inverse (inverseOf()).
void transformPair(const Graph& g, NodeId transformNode, EvalState s, Affine& forward,
                   Affine& inverse);

// forward.inverse() for the matrix `forward` = makeTransform(op, args): built directly for
// move() and zshear() of finite arguments, the same doubles as the general inverse.
Affine inverseOf(TransformOp op, const double* args, const Affine& forward);

// The matrix of one transformation from its evaluated arguments (shared with tests and
// the builder's constant folding). `args` has the count the operation takes.
Affine makeTransform(TransformOp op, const double* args);

// The precomputed matrix of a T-node whose arguments are the constants `args`, or nothing
// when they make a singular or non-finite transformation (rot about the zero axis, a zero
// scale factor): such a T-node stays unfolded, so that the run-time check reports it
// where it is used (docs/language.md section 5).
std::optional<Affine> constantTransform(TransformOp op, const double* args);

// A primitive's argument values (torus radii, triangle corners) for the given state.
// Throws RuntimeError on non-finite values.
void primitiveArgs(const Graph& g, NodeId primitiveNode, EvalState s, double* out);

// Called by a traversal on entering an S-node at the given depth (1 for the first
// S-node on the path). Throws the max_depth RuntimeError when depth exceeds
// g.scene.settings.maxDepth.
void checkDepth(const Graph& g, NodeId selectNode, uint32_t depth, EvalState s);

// sin and cos of an angle in degrees, exact at multiples of 90 so that rotz(90) maps +x
// exactly to +y. The tracer's interval bounds use the same functions: their soundness
// depends on it.
double sinDegrees(double a);
double cosDegrees(double a);

// "c = 3, x = 0.5" for the slots assigned in a frame: for error messages.
std::string describeFrame(const Graph& g, const double* frame);

}  // namespace pcsg
