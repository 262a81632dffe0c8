// The POV-Ray 3.7 writer: see pov_writer.h for the mapping.
#include "pov_writer.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>
#include <string_view>

#include "pov_lights.h"
#include "pov_texture.h"
#include "primitive_table.h"

namespace pcsg {

namespace {

// ---------------------------------------------------------------------------------------
// Geometry of the primitives in world coordinates.

double rowNorm2(const Affine& m, int i) {
    return m.l[i][0] * m.l[i][0] + m.l[i][1] * m.l[i][1] + m.l[i][2] * m.l[i][2];
}
double rowNormXY(const Affine& m, int i) {
    return std::sqrt(m.l[i][0] * m.l[i][0] + m.l[i][1] * m.l[i][1]);
}

// The image of the disk of radius 1 about the z axis in the plane z = h.
Box diskBox(const Affine& m, double h) {
    const Vec3 c = m.point({0, 0, h});
    Box b;
    for (int i = 0; i < 3; ++i) {
        const double e = rowNormXY(m, i);
        b.lo[i] = c[i] - e;
        b.hi[i] = c[i] + e;
    }
    return b;
}

// A triangle primitive's corners in world space.
void worldCorners(const ExpandedTree& t, const TreePrimitive& p, Vec3 out[3]) {
    triangleCorners(p.kind,
                    p.kind == PrimitiveKind::Triangle ? t.args.data() + p.firstArg : nullptr, out);
    for (int k = 0; k < 3; ++k) out[k] = p.toWorld.point(out[k]);
}

// A box that holds the primitive (tight for everything but the plane, which is infinite).
Box worldBox(const ExpandedTree& t, const TreePrimitive& p) {
    const Affine& m = p.toWorld;
    Box b;
    switch (p.kind) {
        case PrimitiveKind::Sphere:
            for (int i = 0; i < 3; ++i) {
                const double e = std::sqrt(rowNorm2(m, i));
                b.lo[i] = m.t[i] - e;
                b.hi[i] = m.t[i] + e;
            }
            return b;
        case PrimitiveKind::Cube:
            return transformBox(m, Box{{-1, -1, -1}, {1, 1, 1}});
        case PrimitiveKind::Tetrahedron:
            for (const Vec3& v : kTetraVertices) b.extend(m.point(v));
            return b;
        case PrimitiveKind::Cylinder:
            return unite(diskBox(m, 0), diskBox(m, 1));
        case PrimitiveKind::Cone: {
            b = diskBox(m, 0);
            b.extend(m.point({0, 0, 1}));
            return b;
        }
        case PrimitiveKind::Torus: {
            // Inside the sum of the circle of radius R and the ball of radius r.
            const double R = std::fabs(t.args[p.firstArg]), r = std::fabs(t.args[p.firstArg + 1]);
            for (int i = 0; i < 3; ++i) {
                const double e = R * rowNormXY(m, i) + r * std::sqrt(rowNorm2(m, i));
                b.lo[i] = m.t[i] - e;
                b.hi[i] = m.t[i] + e;
            }
            return b;
        }
        case PrimitiveKind::Plane: {
            constexpr double inf = Box::inf;
            return transformBox(m, Box{{-inf, -inf, -inf}, {inf, inf, 0}});
        }
        case PrimitiveKind::Tri1:
        case PrimitiveKind::Tri2:
        case PrimitiveKind::Triangle: {
            Vec3 c[3];
            worldCorners(t, p, c);
            for (const Vec3& v : c) b.extend(v);
            return b;
        }
        case PrimitiveKind::Empty:
            return b;
    }
    return b;
}

// POV-Ray rejects a triangle whose cross product (P1-P2) x (P3-P2) has length 0 (with a
// warning). Slivers that thin are invisible: leave them out with some margin.
bool degenerate(const Vec3 c[3]) {
    const Vec3 a = c[0] - c[1], b = c[2] - c[1];
    const double n = length(cross(a, b));
    return !(n > 1e-14 * length(a) * length(b)) || !std::isfinite(n);
}

// The boxes of all nodes: children precede parents, so one forward pass.
std::vector<Box> nodeBoxes(const ExpandedTree& t) {
    std::vector<Box> boxes(t.nodes.size());
    for (uint32_t n = 0; n < t.nodes.size(); ++n) {
        const TreeNode& node = t.nodes[n];
        boxes[n] = node.primitive ? worldBox(t, t.primitiveOf(n))
                                  : csgBox(node.op, node.count,
                                           [&](uint32_t i) { return boxes[t.childrenOf(n)[i]]; });
    }
    return boxes;
}

// ---------------------------------------------------------------------------------------
// Text.

// Streams text through a buffer of bounded size.
class Out {
  public:
    explicit Out(std::ostream& os) : os_(os) {}
    ~Out() = default;

    template <class... Args>
    void put(fmt::format_string<Args...> f, Args&&... args) {
        fmt::format_to(fmt::appender(buf_), f, std::forward<Args>(args)...);
        if (buf_.size() > (1 << 16)) flush();
    }
    void raw(std::string_view s) {
        buf_.append(s.data(), s.data() + s.size());
        if (buf_.size() > (1 << 16)) flush();
    }
    void num(double v) {
        if (v == 0) v = 0;  // no "-0"
        fmt::format_to(fmt::appender(buf_), "{}", v);
    }
    void vec(const Vec3& v) {
        buf_.push_back('<');
        num(v.x);
        buf_.push_back(',');
        num(v.y);
        buf_.push_back(',');
        num(v.z);
        buf_.push_back('>');
    }
    void flush() {
        os_.write(buf_.data(), static_cast<std::streamsize>(buf_.size()));
        written_ += buf_.size();
        buf_.clear();
        if (!os_) throw std::runtime_error("could not write the POV-Ray file");
    }
    uint64_t written() const { return written_ + buf_.size(); }

  private:
    std::ostream& os_;
    fmt::memory_buffer buf_;
    uint64_t written_ = 0;
};

bool isIdentity(const Affine& m) {
    const Affine id = Affine::identity();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            if (m.l[i][j] != id.l[i][j]) return false;
    return m.t.x == 0 && m.t.y == 0 && m.t.z == 0;
}

// POV-Ray's matrix is p·M + t: the 3x3 part is L transposed, row by row.
void putMatrix(Out& o, const Affine& m) {
    o.put(" matrix<");
    for (int j = 0; j < 3; ++j)
        for (int i = 0; i < 3; ++i) {
            o.num(m.l[i][j]);
            o.put(",");
        }
    o.num(m.t.x);
    o.put(",");
    o.num(m.t.y);
    o.put(",");
    o.num(m.t.z);
    o.put(">");
}

// The bounding box written with a little margin: POV-Ray's box tests have tolerances,
// and a flat object (a triangle in a coordinate plane) would otherwise get a box of no
// thickness.
void putBound(Out& o, const Box& b) {
    double extent = 0;
    for (int i = 0; i < 3; ++i) extent = std::max(extent, b.hi[i] - b.lo[i]);
    const double pad = 1e-6 * extent + 1e-9;
    o.raw(" bounded_by{box{");
    o.vec(b.lo - Vec3(pad, pad, pad));
    o.raw(",");
    o.vec(b.hi + Vec3(pad, pad, pad));
    o.raw("}}");
}

bool boundable(const Box& b) {
    if (!b.isBounded()) return false;
    for (int i = 0; i < 3; ++i)
        if (!(std::fabs(b.lo[i]) < 1e300 && std::fabs(b.hi[i]) < 1e300)) return false;
    return true;
}

std::string commentSafe(const std::string& s) {
    std::string out;
    for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_') ? c : '_';
    return out;
}

bool anyLetsLightThrough(const Graph& g) {
    for (const Material& m : g.materials)
        if (m.mayLetLightThrough()) return true;
    return false;
}

// Whether materials are written as POV-Ray `material { texture interior }`: when any has
// an interior or may let light through; else as textures, as before interiors existed.
// Wrapped, every material has its interior (ior 1 where none was given), so that each
// `material { }` written, one per paint node instance of the tree, is an object with its
// own interior, as the tracer's interiors are (tracer/transparency.h): POV-Ray gives an
// object whose material has no interior its parent's, and the root's to all objects when
// no material has one.
bool materialWrapped(const Graph& g) {
    for (const Material& m : g.materials)
        if (m.interior || m.mayLetLightThrough()) return true;
    return false;
}

// The inside of a material's texture: its pigment and finish (the items of section 10 only
// where they differ from POV-Ray's defaults, so that a scene without them exports as before).
void putTexture(Out& o, const Material& m) {
    const auto item = [&](std::string_view name, double v) {
        o.put(" {} ", name);
        o.num(v);
    };
    o.raw(povPigment(m));
    o.put(" finish {{ ambient ");
    o.num(m.ambient);
    o.put(" diffuse ");
    o.num(m.diffuse);
    if (m.brilliance != 1) item("brilliance", m.brilliance);
    o.put(" phong ");
    o.num(m.phong);
    o.put(" phong_size ");
    o.num(m.phongSize);
    if (m.specular != 0) item("specular", m.specular);
    if (m.roughness != 0.05) item("roughness", m.roughness);
    if (m.metallic != 0) item("metallic", m.metallic);
    if (m.reflectionRange || m.fresnel || m.reflectMetallic != 0) {
        o.put(" reflection {{ ");
        o.num(m.minReflection());
        o.put(", ");
        o.num(m.reflection);
        if (m.fresnel) o.put(" fresnel on");
        if (m.reflectMetallic != 0) item("metallic", m.reflectMetallic);
        o.put(" }}");
    } else {
        o.put(" reflection ");
        o.num(m.reflection);
    }
    if (m.conserveEnergy) o.put(" conserve_energy");
    o.put(" }}");
    o.raw(povNormal(m));
}

// interior { ior fade_distance fade_power fade_color } with the items that differ from
// POV-Ray's defaults.
void putInterior(Out& o, const Material& m) {
    o.put(" interior {{ ior ");
    o.num(m.ior);
    if (m.fadeDistance != 0) {
        o.put(" fade_distance ");
        o.num(m.fadeDistance);
    }
    if (m.fadePower != 0) {
        o.put(" fade_power ");
        o.num(m.fadePower);
    }
    if (m.fadeColour != Vec3{0, 0, 0}) {
        o.put(" fade_color rgb ");
        o.vec(m.fadeColour);
    }
    o.put(" }}");
}

void putHeader(Out& o, const Graph& g, const ExpandedTree& t, const PovOptions& opt) {
    o.put("// POV-Ray 3.7 scene exported by pcsg export-pov{}{}\n",
          opt.title.empty() ? "" : " from ", opt.title);
    o.put("// expanded tree: {} primitives, {} nodes\n", t.primitives.size(), t.nodes.size());
    o.put("// render: povray +I<file> +W{} +H{} (the camera's aspect is {}:{})\n", opt.width,
          opt.height, opt.width, opt.height);
    o.put("#version 3.7;\n");
    o.put("global_settings {{ assumed_gamma 1.0 max_trace_level {}",
          g.scene.settings.maxTraceLevel);
    if (g.scene.settings.adcBailout != 1.0 / 255.0) {
        o.put(" adc_bailout ");
        o.num(g.scene.settings.adcBailout);
    }
    o.put(" }}\n\n");
    o.put("{}\n", povCamera(g.scene.camera, opt.width, opt.height));
    for (const Light& l : g.scene.lights) o.put("{}\n", povLight(l));
    if (g.scene.fog.enabled) o.put("{}\n", povFog(g.scene.fog));
    o.put("background {{ color rgb ");
    o.vec(g.scene.background);
    o.put(" }}\n");
    if (g.scene.skySphere)
        o.put("sky_sphere {{ {} }}\n", povPigment(g.scene.skyPigment, g.scene.skyColour));
    o.put("\n");

    // Materials: materials[0] is the default (white, POV-Ray's finish defaults).
    const size_t count = std::max<size_t>(g.materials.size(), 1);
    const bool wrapped = materialWrapped(g);
    for (size_t i = 0; i < count; ++i) {
        const Material m = i < g.materials.size() ? g.materials[i] : Material{};
        o.put("#declare M{} = {}", i, wrapped ? "material { texture { " : "texture { ");
        putTexture(o, m);
        o.put(" }}");
        if (wrapped) putInterior(o, m);
        if (wrapped) o.put(" }}");
        if (!m.name.empty()) o.put("  // {}", commentSafe(m.name));
        o.put("\n");
    }

    // The tetrahedron with vertices (1,1,1), (-1,-1,1), (1,-1,-1), (-1,1,-1): the face
    // opposite vertex v lies in the plane -v.p = 1, its inside is -v.p <= 1.
    bool tetra = false;
    for (const TreePrimitive& p : t.primitives)
        tetra = tetra || p.kind == PrimitiveKind::Tetrahedron;
    if (tetra) {
        const double s = 1 / std::sqrt(3.0);
        o.put("\n#declare PcsgTetrahedron = intersection {{\n");
        for (const Vec3& v : kTetraVertices) {
            o.put("  plane {{ ");
            o.vec(-v * s);
            o.put(", ");
            o.num(s);
            o.put(" }}\n");
        }
        o.put(
            "  bounded_by {{ box {{ <-1.000001,-1.000001,-1.000001>, <1.000001,1.000001,1.000001> "
            "}} }}\n}}\n");
    }
    o.put("\n");
}

// The rotation taking POV-Ray's torus (about y, in y = 0) to ours (about z, in z = 0):
// x -> x, y -> z, z -> -y.
Affine torusFrame() {
    Affine r;
    r.l[0][0] = 1, r.l[0][1] = 0, r.l[0][2] = 0;
    r.l[1][0] = 0, r.l[1][1] = 0, r.l[1][2] = -1;
    r.l[2][0] = 0, r.l[2][1] = 1, r.l[2][2] = 0;
    return r;
}

// One primitive on one line. Returns false when it was left out.
// ` texture{M<i>}` (or ` material{M<i>}`) for a node's own texture; nothing without one.
// A texture with a pattern carries its paint node's frame (`frame`: that frame to world):
// POV-Ray evaluates it there (section 10's pattern space).
void putTextureRef(Out& o, uint32_t texture, bool wrapped, const Affine* frame = nullptr) {
    if (texture == kNone) return;
    o.put(" {}{{M{}", wrapped ? "material" : "texture", texture);
    if (frame && !isIdentity(*frame)) putMatrix(o, *frame);
    o.put("}}");
}

bool putPrimitive(Out& o, const ExpandedTree& t, const TreePrimitive& p, uint32_t texture,
                  const std::string& indent, bool wrapped, const Affine* frame) {
    // A patterned texture in world space, after the object's matrix; a plain one before.
    const auto tex = [&] {
        if (!frame) putTextureRef(o, texture, wrapped);
    };
    const auto patterned = [&] {
        if (frame) putTextureRef(o, texture, wrapped, frame);
    };
    switch (p.kind) {
        case PrimitiveKind::Sphere:
        case PrimitiveKind::Cube:
        case PrimitiveKind::Cylinder:
        case PrimitiveKind::Cone:
        case PrimitiveKind::Tetrahedron:
            o.put("{}{}", indent, primitiveInfo(p.kind).pov);
            tex();
            putMatrix(o, p.toWorld);
            patterned();
            break;
        case PrimitiveKind::Plane: {
            // In world coordinates, without a matrix: POV-Ray 3.7 cuts CSG wrongly next
            // to a plane given a `matrix` (even a uniform scale, which `scale` does
            // right), so the exporter writes the plane's world normal and distance.
            // z <= 0 in object space is m.p <= m.t in world space, m the third row of
            // the inverse of L.
            const Affine inv = p.toWorld.inverse();
            const Vec3 m{inv.l[2][0], inv.l[2][1], inv.l[2][2]};
            const Vec3 n = m * (1.0 / length(m));
            o.put("{}plane{{", indent);
            o.vec(n);
            o.put(",");
            o.num(dot(n, p.toWorld.t));
            tex();
            patterned();
            break;
        }
        case PrimitiveKind::Torus:
            o.put("{}torus{{", indent);
            o.num(t.args[p.firstArg]);
            o.put(",");
            o.num(t.args[p.firstArg + 1]);
            tex();
            putMatrix(o, p.toWorld * torusFrame());
            patterned();
            break;
        case PrimitiveKind::Tri1:
        case PrimitiveKind::Tri2:
        case PrimitiveKind::Triangle: {
            Vec3 c[3];
            worldCorners(t, p, c);
            if (degenerate(c)) return false;
            o.put("{}triangle{{", indent);
            o.vec(c[0]);
            o.put(",");
            o.vec(c[1]);
            o.put(",");
            o.vec(c[2]);
            tex();
            patterned();
            break;
        }
        case PrimitiveKind::Empty:
            return false;
    }
    o.put("}}\n");
    return true;
}

// ---------------------------------------------------------------------------------------
// The tree, with an explicit stack. An item is a tree node, or a group: a run of a big
// union's operands (in `members`) written as a nested union.

struct Item {
    bool group = false;
    uint32_t node = 0;                              // a tree node
    size_t lo = 0, hi = 0;                          // a group: members[lo, hi)
    uint32_t next = 0;                              // children written so far
    std::vector<std::pair<size_t, size_t>> slices;  // a big group's sub-groups
    bool ownsMembers = false;  // this item pushed members[lo, hi) and pops them at the end
    Box box;
    bool cut = false;          // below an intersection or difference (a union there is a merge)
    uint32_t texture = kNone;  // a group that replaces a union: the union's own texture
    const Affine* textureFrame = nullptr;  // and its paint frame
};

class TreeWriter {
  public:
    static constexpr size_t kMaxNesting = 256;  // deeper unions are flattened and regrouped

    TreeWriter(Out& o, const ExpandedTree& t, const PovOptions& opt, PovWriteStats& stats,
               bool wrapped, bool merges)
        : o_(o),
          t_(t),
          opt_(opt),
          stats_(stats),
          boxes_(nodeBoxes(t)),
          maxChildren_(std::max<uint32_t>(opt.maxUnionChildren, 2)),
          wrapped_(wrapped),
          merges_(merges) {}

    void write(uint32_t root) {
        stack_.push_back(nodeItem(root));
        while (!stack_.empty()) step();
    }

  private:
    Item nodeItem(uint32_t n, bool cut = false) {
        Item it;
        it.node = n;
        it.cut = cut;
        return it;
    }

    // A union's keyword: `merge` below an intersection or difference, where the tracer's
    // span lists have no surfaces inside the union (POV-Ray's union keeps them, which
    // light passing through shows), when some material lets light through.
    const char* unionWord(bool cut) const { return merges_ && cut ? "merge" : "union"; }

    std::string indent() const {
        return std::string(std::min<size_t>(stack_.size() - 1, 40) * 1, ' ');
    }

    void step() {
        Item& it = stack_.back();
        if (it.group)
            stepGroup(it);
        else
            stepNode(it);
    }

    // One step on a tree node: a primitive's line, the regrouping of a big union, an
    // operation's opening line, its next child, or its closing bound.
    void stepNode(Item& it) {
        const TreeNode& node = t_.nodes[it.node];
        if (node.primitive) {
            writePrimitive(it.node);
            return;
        }
        const bool deep = stack_.size() > kMaxNesting;
        if (node.is(CsgOp::Union) && it.next == 0 && (node.count > maxChildren_ || deep)) {
            regroupUnion(it.node, deep);
            return;
        }
        if (it.next == 0) {
            o_.put("{}{} {{\n", indent(),
                   node.is(CsgOp::Union) ? unionWord(it.cut) : csgOpName(node.op));
        }
        if (it.next < node.count) {
            const uint32_t c = t_.childrenOf(it.node)[it.next++];
            const bool cut = it.cut || !node.is(CsgOp::Union);
            stack_.push_back(nodeItem(c, cut));
            return;
        }
        const Box& b = boxes_[it.node];
        const bool bound = !node.is(CsgOp::Union) || opt_.boundUnions;
        o_.put("{}", indent());
        putTextureRef(o_, node.texture, wrapped_, t_.textureFrameOf(it.node));
        if (bound && boundable(b)) putBound(o_, b);
        o_.put(" }}\n");
        stack_.pop_back();
    }

    // Writes the primitive of the top item, node n, and pops it.
    void writePrimitive(uint32_t n) {
        if (putPrimitive(o_, t_, t_.primitiveOf(n), t_.nodes[n].texture, indent(), wrapped_,
                         t_.textureFrameOf(n)))
            ++stats_.objects;
        else
            ++stats_.skipped;
        stack_.pop_back();
    }

    // Replaces the top item, union n, by a group item over a run of `members` holding its
    // operands. Deep in the tree (a long chain of unions from a linear recursion), the
    // union's whole union-subtree is flattened first: POV-Ray's parser crashes at about
    // 19,000 nested braces.
    void regroupUnion(uint32_t n, bool deep) {
        const size_t lo = members_.size();
        const bool cut = stack_.back().cut;
        if (deep)
            flattenUnion(n);
        else
            members_.insert(members_.end(), t_.childrenOf(n), t_.childrenOf(n) + t_.nodes[n].count);
        stack_.pop_back();
        Item g;
        g.group = true;
        g.cut = cut;
        g.lo = lo;
        g.hi = members_.size();
        g.ownsMembers = true;
        g.texture = t_.nodes[n].texture;
        g.textureFrame = t_.textureFrameOf(n);
        stack_.push_back(std::move(g));
    }

    // One step on a group of members[lo, hi): its opening line (or, for a single member,
    // the member itself), its next member or sub-group, or its closing bound.
    void stepGroup(Item& it) {
        const size_t n = it.hi - it.lo;
        if (it.next == 0) {
            if (n == 1 && it.texture == kNone) {
                const uint32_t only = members_[it.lo];
                const bool cut = it.cut;
                finishGroup();  // pops `it`
                stack_.push_back(nodeItem(only, cut));
                return;
            }
            for (size_t i = it.lo; i < it.hi; ++i) it.box.extend(boxes_[members_[i]]);
            if (n > maxChildren_) split(it);
            o_.put("{}{} {{\n", indent(), unionWord(it.cut));
            ++stats_.groups;
        }
        const size_t parts = it.slices.empty() ? n : it.slices.size();
        if (it.next < parts) {
            const uint32_t i = it.next++;
            const bool cut = it.cut;
            if (it.slices.empty()) {
                stack_.push_back(nodeItem(members_[it.lo + i], cut));
            } else {
                Item g;
                g.group = true;
                g.cut = cut;
                g.lo = it.slices[i].first;
                g.hi = it.slices[i].second;
                stack_.push_back(std::move(g));
            }
            return;
        }
        o_.put("{}", indent());
        putTextureRef(o_, it.texture, wrapped_, it.textureFrame);
        if (opt_.boundUnions && boundable(it.box)) putBound(o_, it.box);
        o_.put(" }}\n");
        finishGroup();
    }

    // Appends the operands of union n, looking through nested unions, to `members_`.
    void flattenUnion(uint32_t n) {
        std::vector<uint32_t> todo = {n};
        while (!todo.empty()) {
            const uint32_t u = todo.back();
            todo.pop_back();
            const uint32_t* c = t_.childrenOf(u);
            for (uint32_t i = 0; i < t_.nodes[u].count; ++i) {
                // A union with a texture of its own stays one member: flattened, its
                // primitives would lose the texture.
                if (t_.nodes[c[i]].is(CsgOp::Union) && t_.nodes[c[i]].texture == kNone)
                    todo.push_back(c[i]);
                else
                    members_.push_back(c[i]);
            }
        }
    }

    void finishGroup() {
        Item& it = stack_.back();
        if (it.ownsMembers) members_.resize(it.lo);
        stack_.pop_back();
    }

    // Sorts members[lo, hi) by box centre along the axis where the centres spread most,
    // and cuts them into at most maxChildren_ runs of equal size.
    void split(Item& it) {
        Box centres;
        for (size_t i = it.lo; i < it.hi; ++i) centres.extend(centreOf(members_[i]));
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (centres.hi[a] - centres.lo[a] > centres.hi[axis] - centres.lo[axis]) axis = a;
        std::stable_sort(
            members_.begin() + static_cast<std::ptrdiff_t>(it.lo),
            members_.begin() + static_cast<std::ptrdiff_t>(it.hi),
            [&](uint32_t a, uint32_t b) { return centreOf(a)[axis] < centreOf(b)[axis]; });
        const size_t n = it.hi - it.lo;
        const size_t parts = std::min<size_t>(maxChildren_, (n + maxChildren_ - 1) / maxChildren_);
        const size_t size = (n + parts - 1) / parts;
        for (size_t s = it.lo; s < it.hi; s += size)
            it.slices.push_back({s, std::min(it.hi, s + size)});
    }

    Vec3 centreOf(uint32_t n) const {
        const Box& b = boxes_[n];
        Vec3 c;
        for (int i = 0; i < 3; ++i) {
            // Unbounded operands (planes) sort by their finite side, or as 0.
            const double lo =
                std::isfinite(b.lo[i]) ? b.lo[i] : (std::isfinite(b.hi[i]) ? b.hi[i] : 0);
            const double hi = std::isfinite(b.hi[i]) ? b.hi[i] : lo;
            c[i] = b.isEmpty() ? 0 : 0.5 * (lo + hi);
        }
        return c;
    }

    Out& o_;
    const ExpandedTree& t_;
    const PovOptions& opt_;
    PovWriteStats& stats_;
    std::vector<Box> boxes_;
    uint32_t maxChildren_;
    bool wrapped_;  // materials are POV-Ray `material`s (materialWrapped)
    bool merges_;   // unions below an intersection or difference are merges (unionWord)
    std::vector<Item> stack_;
    std::vector<uint32_t> members_;
};

}  // namespace

std::string povCamera(const Camera& c, int width, int height) {
    const double aspect = static_cast<double>(width > 0 ? width : 4) / (height > 0 ? height : 3);
    return fmt::format(
        "camera {{\n  perspective\n  location <{},{},{}>\n  right -x*{}\n  up y\n  direction z\n"
        "  sky <{},{},{}>\n  look_at <{},{},{}>\n  angle {}\n}}",
        c.location.x, c.location.y, c.location.z, aspect, c.sky.x, c.sky.y, c.sky.z, c.lookAt.x,
        c.lookAt.y, c.lookAt.z, c.angle);
}

PovWriteStats writePov(const Graph& g, const ExpandedTree& tree, std::ostream& out,
                       const PovOptions& options) {
    PovWriteStats stats;
    Out o(out);
    putHeader(o, g, tree, options);
    if (!tree.empty()) {
        TreeWriter w(o, tree, options, stats, materialWrapped(g), anyLetsLightThrough(g));
        w.write(tree.root);
    } else {
        o.put("// the scene expands to nothing\n");
    }
    o.flush();
    out.flush();
    if (!out) throw std::runtime_error("could not write the POV-Ray file");
    stats.bytes = o.written();
    return stats;
}

}  // namespace pcsg
