#include "graph.h"

#include <fmt/format.h>

namespace pcsg {

NodeId Graph::addNode(NodeKind kind, uint32_t payload, const std::vector<NodeId>& children,
                      FileLoc loc) {
    Node n;
    n.kind = kind;
    n.payload = payload;
    n.firstChild = static_cast<uint32_t>(edges.size());
    n.childCount = static_cast<uint32_t>(children.size());
    n.loc = loc;
    edges.insert(edges.end(), children.begin(), children.end());
    nodes.push_back(n);
    return static_cast<NodeId>(nodes.size() - 1);
}

ExprId Graph::addConstant(double value, FileLoc loc) {
    Expr e;
    e.begin = static_cast<uint32_t>(code.size());
    code.push_back(Instr{Op::Const, 0, 0, value});
    e.end = static_cast<uint32_t>(code.size());
    e.maxStack = 1;
    e.constant = true;
    e.loc = loc;
    e.text = fmt::format("{}", value);
    exprs.push_back(std::move(e));
    return static_cast<ExprId>(exprs.size() - 1);
}

ExprId Graph::addLoad(Slot s, FileLoc loc) {
    Expr e;
    e.begin = static_cast<uint32_t>(code.size());
    code.push_back(Instr{Op::Load, 0, s, 0});
    e.end = static_cast<uint32_t>(code.size());
    e.maxStack = 1;
    e.loc = loc;
    e.text = s < slotNames.size() ? slotNames[s] : fmt::format("slot{}", s);
    exprs.push_back(std::move(e));
    return static_cast<ExprId>(exprs.size() - 1);
}

Slot Graph::slot(const std::string& name) {
    for (Slot s = 0; s < slotNames.size(); ++s)
        if (slotNames[s] == name) return s;
    slotNames.push_back(name);
    return static_cast<Slot>(slotNames.size() - 1);
}

namespace {
template <class T>
size_t vectorBytes(const std::vector<T>& v) {
    return v.size() * sizeof(T);
}
size_t stringBytes(const std::string& s) {
    // Short strings live inside the std::string object itself.
    return s.capacity() > 15 ? s.size() + 1 : 0;
}
}  // namespace

size_t Graph::graphBytes() const {
    size_t b = sizeof(Graph);
    b += vectorBytes(files) + vectorBytes(nodes) + vectorBytes(edges) + vectorBytes(modules) +
         vectorBytes(transforms) + vectorBytes(calcs) + vectorBytes(assignments) +
         vectorBytes(primitives) + vectorBytes(args) + vectorBytes(exprs) + vectorBytes(code) +
         vectorBytes(fastCode) + vectorBytes(slotNames) + vectorBytes(materials) +
         vectorBytes(scene.lights) + vectorBytes(timedValues);
    for (const auto& f : files) b += stringBytes(f);
    for (const auto& m : modules)
        b += stringBytes(m.name) + vectorBytes(m.conditions) + vectorBytes(m.formals);
    for (const auto& p : primitives) b += vectorBytes(p.values);
    for (const auto& e : exprs) b += stringBytes(e.text);
    for (const auto& s : slotNames) b += stringBytes(s);
    for (const auto& m : materials) b += stringBytes(m.name);
    return b;
}

bool Material::mayLetLightThrough() const {
    const auto through = [](const FilterColour& c) { return c.filter != 0 || c.transmit != 0; };
    if (filter != 0 || transmit != 0) return true;
    for (const FilterColour& c : pigment.listColours)
        if (through(c)) return true;
    for (const ColourMapEntry& e : pigment.colourMap)
        if (through(e.colour)) return true;
    return false;
}

std::string Graph::where(FileLoc loc) const {
    const std::string file = loc.file < files.size() ? files[loc.file] : std::string("<scene>");
    if (loc.line == 0) return file;
    return fmt::format("{}:{}:{}", file, loc.line, loc.column);
}

}  // namespace pcsg
