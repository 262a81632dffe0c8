// The random system generator: see generator.h.
#include "generator.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "appearance.h"
#include "bounds.h"
#include "compiler.h"

namespace pcsg::fuzz {

uint64_t mix64(uint64_t x) {
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}

Rng::Rng(uint64_t seed) {
    for (int k = 0; k < 4; ++k) {
        seed += 0x9e3779b97f4a7c15ull;
        s_[k] = mix64(seed);
    }
}

uint64_t Rng::next() {
    const auto rotl = [](uint64_t x, int k) { return (x << k) | (x >> (64 - k)); };
    const uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
}

uint64_t systemSeed(uint64_t campaignSeed, uint64_t index) {
    return mix64(mix64(campaignSeed) ^ (index * 0xd1b54a32d192ed03ull));
}

std::string milli(int64_t t) {
    const char* sign = t < 0 ? "-" : "";
    const uint64_t a = t < 0 ? uint64_t(-t) : uint64_t(t);
    std::string frac = fmt::format("{:03d}", a % 1000);
    while (!frac.empty() && frac.back() == '0') frac.pop_back();
    return fmt::format("{}{}{}{}", sign, a / 1000, frac.empty() ? "" : ".", frac);
}

namespace {

struct Module {
    std::string name;
    bool notationB = false;
    bool triangles = false;  // may hold triangles: never an operand of ∩ or \ then
    int rules = 2;           // notation A: the base rule and 1 or 2 recursive ones
};

class Generator {
  public:
    explicit Generator(uint64_t seed) : rng_(seed), seed_(seed) {}
    std::string run();

  private:
    Rng rng_;
    uint64_t seed_;
    std::vector<Module> modules_;
    int materials_ = 0;
    bool definition_ = false;
    int current_ = 0;          // the module whose rules are being written
    int calls_ = 0;            // calls of other modules the current rule may still make
    int budget_ = 0;           // primitives the current rule may still get
    bool calledNext_ = false;  // a rule of the current module calls the next module

    // A number in thousandths from [lo, hi] (both in thousandths).
    std::string n(int64_t lo, int64_t hi) { return milli(rng_.range(lo, hi)); }
    std::string vec(int64_t lo, int64_t hi) {
        return fmt::format("<{}, {}, {}>", n(lo, hi), n(lo, hi), n(lo, hi));
    }

    std::string rotation();
    std::string placement();
    std::string primitive();
    std::string solidLeaf();
    std::string triangleLeaf();
    std::string call(int module);
    std::string leaf(bool solid);
    std::string wrap(std::string body);
    std::string csg(int level, bool solid);
    std::string recursiveBody();
    std::string baseBody();
    std::string moduleText(int m);
    std::string materialsText();
    std::string axiom(int& d);
    std::string frame(const std::string& body, bool ground, double& groundZ);
};

// One orientation-changing transformation, of any kind but move and scale.
std::string Generator::rotation() {
    switch (rng_.below(9)) {
        case 0:
            return fmt::format("rotx({}) ", n(-180000, 180000));
        case 1:
            return fmt::format("roty({}) ", n(-180000, 180000));
        case 2:
            return fmt::format("rotz({}) ", n(-180000, 180000));
        case 3:
            return fmt::format("rot({}, {}, {}, {}) ", n(100, 1000), n(-1000, 1000), n(-1000, 1000),
                               n(-180000, 180000));
        case 4:
            return fmt::format("zshear({}, {}) ", n(-400, 400), n(-400, 400));
        case 5: {
            static const char* flips[] = {"flipyz ", "flipxz ", "flipxy "};
            return flips[rng_.below(3)];
        }
        case 6: {
            // Diagonally dominant, so never singular.
            const std::string d1 = n(700, 1200), d2 = n(700, 1200), d3 = n(700, 1200);
            return fmt::format("matrix({}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}, {}) ", d1,
                               n(-250, 250), n(-250, 250), n(-250, 250), d2, n(-250, 250),
                               n(-250, 250), n(-250, 250), d3, n(-200, 200), n(-200, 200),
                               n(-200, 200));
        }
        case 7:
            return fmt::format("rotz(k + {} * rand()) ", n(10000, 90000));
        default:
            return fmt::format("roty({} + {} * rand({})) ", n(-60000, 60000), n(10000, 90000),
                               n(0, 99000));
    }
}

// Where a primitive goes: its own offset and size, so no two surfaces coincide.
std::string Generator::placement() {
    const char* moveWord = rng_.percent(20) ? "translate" : "move";
    std::string s =
        fmt::format("{}({}, {}, {}) ", moveWord, n(-600, 600), n(-600, 600), n(-600, 600));
    if (rng_.percent(60)) s += rotation();
    if (rng_.percent(50))
        s += fmt::format("scale({}, {}, {}) ", n(150, 700), n(150, 700),
                         rng_.percent(10) ? n(-700, -150) : n(150, 700));  // a mirror too
    else
        s += fmt::format("uscale({}) ", n(150, 650));
    return s;
}

std::string Generator::primitive() {
    switch (rng_.below(7)) {
        case 0:
            return "sphere";
        case 1:
            return "cube";
        case 2:
            return "cylinder";
        case 3:
            return "cone";
        case 4:
            return "tetrahedron";
        case 5:
            // Always r < R: POV-Ray 3.7 gives a spindle torus (r > R) the inner sheet of
            // its quartic as a surface, which shows inside CSG, where the native tracer
            // (rightly) sees none (docs/fuzz.md, "POV-Ray's spindle tori").
            return fmt::format("torus({}, {})", n(600, 1000), n(120, 400));
        default:
            return rng_.percent(50) ? "sphere" : fmt::format("torus(0.8, 0.2 + 0.15 * rand())");
    }
}

std::string Generator::solidLeaf() {
    --budget_;
    if (definition_ && rng_.percent(12)) return placement() + "D0";
    return placement() + primitive();
}

std::string Generator::triangleLeaf() {
    --budget_;
    switch (rng_.below(3)) {
        case 0:
            return placement() + "tri1";
        case 1:
            return placement() + "tri2";
        default: {
            std::string s = "triangle(";
            for (int k = 0; k < 9; ++k) s += (k ? ", " : "") + n(-800, 800);
            return s + ")";
        }
    }
}

// A call of module m, one level down (d - 1), placed by a random transformation.
std::string Generator::call(int m) {
    std::string t = fmt::format("move({}, {}, {}) ", n(-700, 700), n(-700, 700), n(-200, 900));
    if (rng_.percent(70)) t += rotation();
    t += rng_.percent(30) ? fmt::format("uscale({} + 0.1 * rand()) ", n(400, 600))
                          : fmt::format("uscale({}) ", n(450, 720));
    const Module& mod = modules_[size_t(m)];
    if (mod.notationB) return t + fmt::format("{}(d - 1, s * {})", mod.name, n(700, 950));
    if (rng_.percent(40))
        return t + fmt::format("{{d = d - 1; s = s * {}}} {}", n(700, 950), mod.name);
    return t + fmt::format("{{d = d - 1}} {}", mod.name);
}

// An operand without operators: a primitive, a triangle, or a call of a later module.
std::string Generator::leaf(bool solid) {
    const int later = int(modules_.size()) - current_ - 1;
    const int m = later > 0 ? current_ + 1 + int(rng_.below(uint64_t(later))) : 0;
    if (calls_ > 0 && later > 0 && rng_.percent(40) && (!solid || !modules_[size_t(m)].triangles)) {
        --calls_;
        return call(m);
    }
    if (!solid && modules_[size_t(current_)].triangles && rng_.percent(35)) return triangleLeaf();
    if (rng_.percent(3)) return "empty";  // which the exporter folds away
    return solidLeaf();
}

// Prefixes: a C-node, paint, a transformation.
std::string Generator::wrap(std::string body) {
    if (rng_.percent(15)) body = fmt::format("uscale({}) ({})", n(800, 1200), body);
    if (rng_.percent(25) && materials_ > 0)
        body = fmt::format("paint(m{}) ({})", rng_.below(uint64_t(materials_)), body);
    if (rng_.percent(15)) body = fmt::format("{{s = s * {}}} ({})", n(800, 1100), body);
    return body;
}

// A CSG expression of at most `level` nested operators; solid: no triangles anywhere.
std::string Generator::csg(int level, bool solid) {
    if (level <= 0 || budget_ <= 1 || rng_.percent(30)) return leaf(solid);
    const uint64_t op = rng_.below(4);
    if (op <= 1) {
        const int count = int(rng_.range(2, 3));
        std::string s;
        for (int k = 0; k < count; ++k) s += (k ? " ∪ " : "") + csg(level - 1, solid);
        return wrap(s);
    }
    // ∩ and \ cut a solid with a larger solid, a smaller one or a plane.
    const std::string a = csg(level - 1, true);
    std::string cutter;
    if (rng_.percent(25)) {
        cutter = fmt::format("move({}, {}, {}) {}plane", n(-300, 300), n(-300, 300), n(-300, 300),
                             rotation());
        --budget_;
    } else if (op == 2) {
        cutter = fmt::format("move({}, {}, {}) uscale({}) {}", n(-300, 300), n(-300, 300),
                             n(-300, 300), n(600, 1100), primitive());
        --budget_;
    } else {
        cutter = csg(level - 1, true);
    }
    if (op == 2) return wrap(fmt::format("({}) ∩ ({})", a, cutter));
    if (rng_.percent(30)) return wrap(fmt::format("({}) \\ ({}) \\ ({})", a, cutter, solidLeaf()));
    return wrap(fmt::format("({}) \\ ({})", a, cutter));
}

std::string Generator::recursiveBody() {
    const Module& self = modules_[size_t(current_)];
    budget_ = 5;
    calls_ = 1;
    std::string s = csg(2, !self.triangles);
    s += " ∪ " + call(current_);
    // Every module is reached: each calls the next one (a module with triangles comes
    // before every module without, so the call is allowed here).
    if (current_ + 1 < int(modules_.size()) && !calledNext_) {
        s += " ∪ " + call(current_ + 1);
        calledNext_ = true;
    }
    if (rng_.percent(45)) {
        std::string again = call(current_);
        if (!self.triangles && rng_.percent(30))
            again = fmt::format("({}) ∩ (uscale({}) sphere)", again, n(1200, 1800));
        s += " ∪ " + again;
    }
    return s;
}

std::string Generator::baseBody() {
    budget_ = 3;
    calls_ = 0;
    if (rng_.percent(5)) return "empty";
    return csg(1, !modules_[size_t(current_)].triangles);
}

std::string Generator::moduleText(int m) {
    current_ = m;
    calledNext_ = false;
    const Module& mod = modules_[size_t(m)];
    std::string s;
    if (mod.notationB) {
        const std::string head = fmt::format("{}(d, s)", mod.name);
        s += fmt::format("p1: {} : d <= 0 -> {}\n", head, baseBody());
        if (rng_.percent(50))
            s += fmt::format("p2: {} : s > {} -> {}\n", head, n(500, 800), recursiveBody());
        return s + fmt::format("p3: {} -> {}\n", head, recursiveBody());
    }
    if (mod.rules == 2)
        s += fmt::format("{} if(d > 0, 2, 1)\n", mod.name);
    else if (rng_.percent(50))
        s += fmt::format("{} if(d > 0, 1 + choose({}, {}), 1)\n", mod.name, n(100, 900),
                         n(100, 900));
    else
        s += fmt::format("{} if(d > 0, if(s > {}, 2, 3), 1)\n", mod.name, n(500, 800));
    s += fmt::format("1: {} -> {}\n", mod.name, baseBody());
    for (int r = 2; r <= mod.rules; ++r)
        s += fmt::format("{}: {} -> {}\n", r, mod.name, recursiveBody());
    return s;
}

std::string Generator::materialsText() {
    std::string s;
    if (rng_.percent(20))
        s += fmt::format("material default {{ color {}  diffuse {}  phong {} }}\n", vec(300, 1000),
                         n(300, 900), n(0, 600));
    for (int k = 0; k < materials_; ++k)
        s += fmt::format("material m{} {{ {} }}\n", k, materialBody(rng_));
    return s;
}

// The axiom without the ground: the start values of d, s and k, and module 0.
std::string Generator::axiom(int& d) {
    d = int(rng_.range(1, 3));
    const Module& first = modules_[0];
    if (first.notationB && rng_.percent(40))
        return fmt::format("w: {{k = {}}} {}({}, {})", n(0, 90000), first.name, d, n(600, 1000));
    current_ = 0;
    budget_ = 2;
    calls_ = 0;
    std::string top = first.notationB ? fmt::format("{}(d, s)", first.name) : first.name;
    if (rng_.percent(40)) top += " ∪ " + solidLeaf();
    return fmt::format("{{d = {}; s = {}; k = {}}} ({})", d, n(600, 1000), n(0, 90000), top);
}

std::string fixed(double v) {
    return milli(std::llround(v * 1000));
}
std::string fixedVec(const Vec3& v) {
    return fmt::format("<{}, {}, {}>", fixed(v.x), fixed(v.y), fixed(v.z));
}

// The camera, lights and background for the object of `body` (a whole system without
// them), from its hyper-bounding box; groundZ: a height below the object.
std::string Generator::frame(const std::string& body, bool ground, double& groundZ) {
    Diagnostics diags;
    const std::optional<Graph> g = compileSource("generated.pcsg", body, diags);
    Vec3 centre{0, 0, 0};
    double radius = 2;
    if (g) {
        const Box box = tracer::computeBounds(*g).node[g->axiom];
        if (box.isBounded()) {
            centre = (box.lo + box.hi) * 0.5;
            radius = std::clamp(length(box.hi - box.lo) * 0.5, 0.2, 50.0);
        }
    }
    groundZ = centre.z - radius * 1.02;
    const auto direction = [&](int64_t zlo, int64_t zhi) {
        Vec3 v{double(rng_.range(-1000, 1000)), double(rng_.range(-1000, 1000)),
               double(rng_.range(zlo, zhi))};
        if (std::abs(v.x) + std::abs(v.y) < 200) v.x += 500;  // never along the sky
        return v * (1.0 / std::sqrt(dot(v, v)));
    };
    // Angle 45 over a 4:3 image: the vertical half-angle's sine is 0.297, so a sphere of
    // the box's radius fits at 3.4 radii; hyper-bounding boxes are loose (they hold every
    // instance rand() could make), so a little less fills the image better.
    const Vec3 eye = centre + direction(ground ? 300 : -600, 900) * (radius * 2.9);
    std::string s = fmt::format("camera {{ location {}  look_at {}  sky <0, 0, 1>  angle 45 }}\n",
                                fixedVec(eye), fixedVec(centre));
    const int lights = int(rng_.range(1, 2));
    for (int k = 0; k < lights; ++k) {
        const std::string at = fixedVec(centre + direction(200, 1000) * (radius * 8));
        const std::string colour = vec(400, 1000);
        s += fmt::format("light {{ position {}  color {}{} }}\n", at, colour,
                         lightExtras(rng_, radius, fixedVec(centre)));
    }
    s += fmt::format("background {}\n", vec(0, 500));
    return s + sceneExtras(rng_, radius, groundZ);
}

std::string Generator::run() {
    const int count = int(rng_.range(2, 4));
    // Modules 0..withTriangles may hold triangles: they are never operands of an
    // intersection or difference, and modules call only later modules, so none without
    // triangles ever calls one with them.
    const int withTriangles = rng_.percent(40) ? -1 : int(rng_.range(0, count - 1));
    for (int m = 0; m < count; ++m) {
        Module mod;
        mod.notationB = rng_.percent(40);
        mod.name = fmt::format("{}{}", mod.notationB ? "Q" : "M", m);
        mod.triangles = m <= withTriangles;
        mod.rules = int(rng_.range(2, 3));
        modules_.push_back(mod);
    }
    materials_ = int(rng_.range(1, 3));
    const bool definition = rng_.percent(30);
    const std::string materials = materialsText();
    const std::string settings =
        fmt::format("settings {{ seed {}  max_depth 64 }}\n", rng_.below(100000));
    int d = 0;
    const std::string start = axiom(d);
    std::string rules;
    if (definition) {  // made before definition_ is set: it does not use itself
        current_ = 0;
        budget_ = 2;
        calls_ = 0;
        rules += "D0 = " + csg(1, true) + "\n";
        definition_ = true;
    }
    for (int m = 0; m < count; ++m) rules += moduleText(m);
    const bool ground = rng_.percent(50);
    double groundZ = 0;
    const std::string head = frame(materials + settings + start + "\n" + rules, ground, groundZ);
    std::string ax = start;
    if (ground) {
        const std::string plane = fmt::format("paint(m{}) move(0, 0, {}) plane",
                                              rng_.below(uint64_t(materials_)), fixed(groundZ));
        ax = start.starts_with("w:") ? "w: " + plane + " ∪ " + start.substr(3)
                                     : plane + " ∪ " + start;
    }
    return fmt::format("// pcsg fuzz: the system of seed {:#018x}\n", seed_) + head + materials +
           settings + ax + "\n" + rules;
}

}  // namespace

std::string generateSystem(uint64_t seed) {
    return Generator(seed).run();
}

}  // namespace pcsg::fuzz
