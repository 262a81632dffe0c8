// The cyclic CSG graph: the one representation that the compiler produces and that the
// tracer and the expander read. See README.md ("How it works") and the seed paper, section 2.2.
//
// Everything is stored in flat arrays indexed by small integers, so that a graph is a
// handful of vectors (its size in bytes is graphBytes()) and the hot loops of the tracer
// switch over NodeKind without virtual calls.
//
//  - One S-node (NodeKind::Select) per module. Its children are the module's rules, in
//    rule order (rule k is child k-1). Module references in rule bodies are plain edges
//    to the S-node: the graph is cyclic and S-nodes are the only targets of back edges.
//  - T-nodes (Transform) have one child and a transformation whose arguments are
//    expressions over parameter slots.
//  - C-nodes (Calc) have one child and an ordered list of assignments.
//  - Paint nodes have one child and a material index.
//  - Operator nodes (∪ ∩ \, their CsgOp in the payload) are n-ary (chains of the same operator are
//    flattened by the builder: A ∪ B ∪ C is one Union with three children;
//    A \ B \ C is one Difference: the first child minus all the others).
//  - Primitive nodes are leaves.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "csg_op.h"
#include "fast_instr.h"
#include "geometry.h"
#include "texture.h"

namespace pcsg {

using NodeId = uint32_t;
using ExprId = uint32_t;
using Slot = uint32_t;
inline constexpr uint32_t kNone = UINT32_MAX;

// A position in a source file: file index into Graph::files, 1-based line and column
// (column counts bytes). line 0 means "no position".
struct FileLoc {
    uint32_t file = 0;
    uint32_t line = 0;
    uint32_t column = 0;
};

// ---------------------------------------------------------------------------------------
// Expressions: a flat stack code over parameter slots.

enum class Func : uint8_t {
    Sin,
    Cos,
    Tan,
    Asin,
    Acos,
    Atan,
    Atan2,
    Sqrt,
    Exp,
    Ln,
    Log10,
    Pow,
    Abs,
    Floor,
    Ceil,
    Min,
    Max,
    Mod,
    Clamp,
    Rand1,  // rand(x)
};

enum class Op : uint8_t {
    Const,  // push imm
    Load,   // push frame[a]; reading an unassigned slot is a run-time error
    Neg,
    Not,  // unary
    Add,
    Sub,
    Mul,
    Div,
    Mod,
    Pow,  // binary: pops b, then a, pushes a op b
    Lt,
    Le,
    Gt,
    Ge,
    Eq,
    Ne,          // comparisons give 1 or 0
    Jump,        // pc = a (absolute index into Graph::code)
    JumpIfZero,  // pops v; if v == 0, pc = a
    ToBool,      // replaces v by (v != 0)
    Call,        // a = Func, argc = number of arguments popped (min/max take 2 or more)
    Rand0,       // rand(): push uniform [0,1) from (seed, instance path, call site a)
    Choose,      // choose(w1..wn): argc = n, call site a; pushes a rule number 1..n
    Clock,       // push the graph's time: clock
    Frame,       // push the graph's time: frame
};

struct Instr {
    Op op;
    uint8_t argc = 0;
    uint32_t a = 0;
    double imm = 0;
};

struct Expr {
    uint32_t begin = 0, end = 0;  // [begin, end) in Graph::code
    uint32_t maxStack = 0;        // the largest stack depth the code reaches
    bool constant = false;        // reads no slot, no clock or frame, calls no rand()/choose()
    bool usesPath = false;        // calls rand() or choose(): depends on the instance path
    bool usesTime = false;        // reads clock or frame
    uint32_t fast = kNoFast;      // its fast form's first instruction in Graph::fastCode
    FileLoc loc;
    std::string text;  // the source text, for run-time error messages
};

// ---------------------------------------------------------------------------------------
// Nodes.

enum class NodeKind : uint8_t {
    Select,
    Transform,
    Calc,
    Paint,
    Operator,  // ∪ ∩ \: the CsgOp is the payload
    Primitive,
};

struct Node {
    NodeKind kind;
    uint32_t payload = kNone;  // index into the kind's table (modules, transforms, calcs,
                               // materials for Paint, primitives); the CsgOp of an Operator
    uint32_t firstChild = 0;   // children are Graph::edges[firstChild, firstChild+childCount)
    uint32_t childCount = 0;
    FileLoc loc;

    CsgOp op() const { return static_cast<CsgOp>(payload); }  // Operator nodes
    bool is(CsgOp o) const { return kind == NodeKind::Operator && op() == o; }
};

// One module: the data of its S-node.
struct Module {
    std::string name;
    NodeId node = kNone;  // its S-node
    FileLoc loc;
    // Notation A: `NAME expr`; the expression's value rounded to the nearest integer is
    // the rule number.
    ExprId select = kNone;
    // Notation B: the first rule in order whose condition is non-zero is taken; a rule
    // without condition has kNone here (always true). Empty for notation A.
    bool notationB = false;
    std::vector<ExprId> conditions;
    std::vector<Slot> formals;  // notation B formal parameters, e.g. S(c)
};

enum class TransformOp : uint8_t {
    Move,    // args dx dy dz (alias translate)
    Scale,   // fx fy fz
    UScale,  // f
    RotX,
    RotY,
    RotZ,    // a (degrees, right-handed)
    Rot,     // ax ay az a
    ZShear,  // a b: (x, y, z + a x + b y)
    FlipYZ,
    FlipXZ,
    FlipXY,  // no args: mirror in that coordinate plane (flipxz: y -> -y)
    Matrix,  // m11 m12 m13 m21 m22 m23 m31 m32 m33 tx ty tz: p·M + t as in POV-Ray
};

struct Transform {
    TransformOp op;
    uint32_t firstArg = 0, argCount = 0;  // Graph::args[firstArg, firstArg+argCount)
    bool constant = false;                // all arguments constant: `matrix` is valid
    Affine matrix;                        // precomputed when constant
    // All its arguments as one program in Graph::fastCode, argument i stored to out[i]: when
    // one of them is more than a lone constant or parameter (zshear(z2-z1, z3-z1)).
    uint32_t fast = kNoFast;
};

struct Assignment {
    Slot slot;
    ExprId value;
};

struct Calc {
    uint32_t first = 0, count = 0;  // Graph::assignments[first, first+count)
    // false: assignments run in order, each sees the ones before (a C-node `{...}`).
    // true: all values are computed from the incoming frame, then assigned together
    //       (a notation-B call S(e1, e2) on formals (c1, c2)).
    bool simultaneous = false;
    uint32_t fast = kNoFast;  // all assignments as one program in Graph::fastCode
};

enum class PrimitiveKind : uint8_t {
    Sphere,
    Cube,
    Cylinder,
    Cone,
    Tetrahedron,
    Torus,
    Plane,
    Empty,
    Tri1,
    Tri2,
    Triangle,
};

struct Primitive {
    PrimitiveKind kind;
    uint32_t firstArg = 0, argCount = 0;  // torus: R r; triangle: 9 coordinates
    bool constant = true;                 // all arguments constant
    std::vector<double> values;           // the argument values when constant
};

// ---------------------------------------------------------------------------------------
// Scene directives (docs/language.md section 7). Their values are constants, or read the
// time (section 11): such a value is a TimedValue, which setTime() (scene_time.h)
// evaluates into the Scene and the materials for each frame.

struct Camera {
    Vec3 location{0, -5, 2};
    Vec3 lookAt{0, 0, 0};
    Vec3 sky{0, 0, 1};
    double angle = 40;  // horizontal field of view, degrees
};

// A POV-Ray 3.7 light_source (docs/language.md sections 7 and 10; tracer/lights.h has the
// formulas). The numbered fields are those a TimedValue may set (scene_time.cpp).
struct Light {
    Vec3 position{10, -20, 30};  // fields 0-2
    Vec3 color{1, 1, 1};         // 3-5
    Vec3 pointAt{0, 0, 1};       // 6-8: a spotlight's axis points from position to here
    double fadeDistance = 0;     // 9: with fade_power > 0, 2 / (1 + (d / fade_distance)^p)
    double fadePower = 0;        // 10
    double radius = 30;          // 11: spotlight, degrees (full light inside)
    double falloff = 45;         // 12: spotlight, degrees (no light outside)
    double tightness = 0;        // 13: spotlight, cos^tightness
    bool spotlight = false;
    bool shadowless = false;  // POV-Ray's fill light: no shadows and no highlights
    // area_light <axis1>, <axis2>, size1, size2 (size1 * size2 > 1 makes it an area light)
    Vec3 axis1{0, 0, 0}, axis2{0, 0, 0};
    int size1 = 1, size2 = 1;
    int adaptive = 100;     // POV-Ray's default: subdivide to the full grid
    bool jitter = false;    // rendered with a fixed pseudo-random jitter; not reproducible in POV
    bool circular = false;  // the grid's square shells mapped to circles
    bool orient = false;    // the axes turned to face each lit point
    bool areaLight() const { return size1 * size2 > 1; }
};
inline constexpr uint8_t kLightFields = 14;

// fog { } (docs/language.md section 10): POV-Ray 3.7's constant (type 1) or ground fog
// (type 2, altitude along z).
struct Fog {
    bool enabled = false;
    int type = 1;
    double distance = 0;
    Vec3 color{0, 0, 0};
    double filter = 0, transmit = 0;
    double offset = 0, alt = 1;  // ground fog: density 1 below offset, 1/(1+h^2) above
};

// POV-Ray 3.7's pigment colour and classic finish, with POV-Ray's defaults.
// A material (docs/language.md sections 7 and 10): POV-Ray 3.7's texture items, with its
// defaults. The numbered fields are those a TimedValue may set (scene_time.cpp).
struct Material {
    std::string name;
    Vec3 color{1, 1, 1};           // fields 0-2: the pigment's colour
    double ambient = 0.1;          // 3
    double diffuse = 0.6;          // 4
    double phong = 0;              // 5
    double phongSize = 40;         // 6
    double reflection = 0;         // 7: reflection's maximum (`reflection r`: min and max)
    double brilliance = 1;         // 8
    double specular = 0;           // 9
    double roughness = 0.05;       // 10: as written; POV-Ray raises to 1 / roughness
    double metallic = 0;           // 11: highlights take the pigment's colour
    double reflectionMin = 0;      // 12: with reflectionRange, else reflection's value
    double ior = 1;                // 13: interior { ior }, read by fresnel reflection
    bool reflectionRange = false;  // `reflection { min, max }`
    bool fresnel = false;
    double reflectMetallic = 0;  // reflection { ... metallic }
    bool conserveEnergy = false;
    bool interior = false;  // an interior { } was given (the exporter writes it)
    double filter = 0;      // 14: the plain pigment colour's filter
    double transmit = 0;    // 15: and transmit
    // interior { fade_distance fade_power fade_color } (constants): POV-Ray's attenuation of
    // light travelling inside; fade_distance 0 is none.
    double fadeDistance = 0;
    double fadePower = 0;
    Vec3 fadeColour{0, 0, 0};
    Pigment pigment{};    // its pattern (PatternKind::Plain: color, filter, transmit)
    NormalSpec normal{};  // NormalKind::None: the surface's own normal

    double minReflection() const { return reflectionRange ? reflectionMin : reflection; }
    // Whether it may let light through: its plain colour or a colour of its pattern has a
    // filter or transmit.
    bool mayLetLightThrough() const;
};
inline constexpr uint8_t kMaterialFields = 16;

struct Settings {
    uint64_t seed = 0;
    uint32_t maxDepth = 256;
    // POV-Ray's global_settings: the deepest ray tree (the camera ray is level 1) and the
    // weight below which a ray is not traced.
    uint32_t maxTraceLevel = 5;
    double adcBailout = 1.0 / 255.0;
};

struct Scene {
    Camera camera;
    std::vector<Light> lights;  // the builder fills in the default light when none is given
    Vec3 background{0, 0, 0};
    Fog fog;
    // sky_sphere { pigment { ... } } (section 10): the pigment at a missed ray's direction
    // in scene coordinates, instead of the background.
    bool skySphere = false;
    Pigment skyPigment;      // a pattern, or PatternKind::Plain: skyColour
    FilterColour skyColour;  // the plain pigment's colour
    Settings settings;
};

// The time of the frame being rendered (docs/language.md section 11), read by the
// expressions `clock` and `frame`. A still image has clock 0 and frame 1.
struct Time {
    double clock = 0;
    int frame = 1;
};

// A range of times: what an analysis that must hold for several frames (the tracer's
// bounds of an animation) lets `clock` and `frame` be.
struct TimeRange {
    double clockLo = 0, clockHi = 0;
    int frameLo = 1, frameHi = 1;
    static TimeRange at(const Time& t) { return {t.clock, t.clock, t.frame, t.frame}; }
};

// A directive's value that reads `clock` or `frame`, and the number it sets:
//   Camera:     location x y z (fields 0-2), look_at (3-5), sky (6-8), angle (9)
//   Light:      lights[index]: position (0-2), color (3-5), point_at (6-8), fade_distance (9),
//               fade_power (10), radius (11), falloff (12), tightness (13)
//   Background: x y z (0-2)
//   Material:   materials[index]: color (0-2), ambient (3), diffuse (4), phong (5),
//               phong_size (6), reflection (7)
enum class DirectiveTarget : uint8_t { Camera, Light, Background, Material };
struct TimedValue {
    DirectiveTarget target;
    uint32_t index = 0;
    uint8_t field = 0;
    ExprId expr = kNone;
};

// ---------------------------------------------------------------------------------------

struct Graph {
    std::vector<std::string> files;  // source file names, for FileLoc::file

    std::vector<Node> nodes;
    std::vector<NodeId> edges;
    NodeId axiom = kNone;

    std::vector<Module> modules;
    std::vector<Transform> transforms;
    std::vector<Calc> calcs;
    std::vector<Assignment> assignments;
    std::vector<Primitive> primitives;
    std::vector<ExprId> args;  // arguments of transforms and primitives

    std::vector<Expr> exprs;
    std::vector<Instr> code;
    std::vector<FastInstr> fastCode;     // the fast form of `code` (fast_code.h), built last
    std::vector<std::string> slotNames;  // parameter names, by slot
    uint32_t randCallSites = 0;          // number of rand()/choose() call sites

    std::vector<Material> materials;  // materials[0] is the default material
    Scene scene;
    Time time;  // the current frame's time: set it (setTime) before rendering a frame
    std::vector<TimedValue> timedValues;  // directive values that read the time

    // --- construction helpers (used by the builder and by tests) ---
    NodeId addNode(NodeKind kind, uint32_t payload, const std::vector<NodeId>& children,
                   FileLoc loc = {});
    NodeId addOperator(CsgOp op, const std::vector<NodeId>& children, FileLoc loc = {}) {
        return addNode(NodeKind::Operator, static_cast<uint32_t>(op), children, loc);
    }
    ExprId addConstant(double value, FileLoc loc = {});
    ExprId addLoad(Slot slot, FileLoc loc = {});
    Slot slot(const std::string& name);  // finds or creates the slot for a name

    // --- queries ---
    const NodeId* childrenOf(NodeId n) const { return edges.data() + nodes[n].firstChild; }
    NodeId child(NodeId n, uint32_t i = 0) const { return edges[nodes[n].firstChild + i]; }
    size_t slotCount() const { return slotNames.size(); }
    // The bytes this graph occupies (its vectors' contents and strings): the
    // "graph bytes" figure of the statistics.
    size_t graphBytes() const;
    // "file:line:col" for a location.
    std::string where(FileLoc loc) const;
};

}  // namespace pcsg
