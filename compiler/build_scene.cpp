// The builder's scene phase: camera, light, background, material and settings
// (docs/language.md section 7). See build_scene.h.
#include "build_scene.h"

#include <fmt/format.h>

#include <cmath>

#include "builder.h"

namespace pcsg {

namespace {

class DirectiveReader {
  public:
    DirectiveReader(BuildContext& ctx, ExprCompiler& exprs)
        : ctx_(ctx), g_(ctx.g), ast_(ctx.ast), exprs_(exprs) {}

    void settings(const Stmt& s);
    void camera(const Stmt& s);
    void light(const Stmt& s);
    void background(const Stmt& s);
    void material(const Stmt& s, const Names& names);

  private:
    bool once(uint32_t& seen, const Stmt& s, const char* what);
    template <class F>
    void items(const Stmt& s, const char* what, const char* known, F set);
    std::optional<Vec3> vectorValue(const DirectiveItem& item);
    std::optional<Vec3> wantVector(const DirectiveItem& item);
    std::optional<double> wantScalar(const DirectiveItem& item);
    void checkCamera(const Stmt& s);

    BuildContext& ctx_;
    Graph& g_;
    const Ast& ast_;
    ExprCompiler& exprs_;
    uint32_t settingsSeen_ = kNoNode, cameraSeen_ = kNoNode, backgroundSeen_ = kNoNode;
};

// Whether this is the first directive of a kind that is given once; reports a second.
bool DirectiveReader::once(uint32_t& seen, const Stmt& s, const char* what) {
    if (seen != kNoNode) {
        ctx_.error(s.tok, fmt::format("a second {} directive (the first is at line {})", what,
                                      ctx_.line(seen)));
        return false;
    }
    seen = s.tok;
    return true;
}

// Reads a directive's items through `set(name, item)`, which returns false for an
// unknown name.
template <class F>
void DirectiveReader::items(const Stmt& s, const char* what, const char* known, F set) {
    for (uint32_t i = 0; i < s.count; ++i) {
        const DirectiveItem& item = ast_.items[s.first + i];
        if (!set(ctx_.text(item.nameTok), item))
            ctx_.error(item.nameTok, fmt::format("unknown {} setting '{}' ({} takes {})", what,
                                                 clip(ctx_.text(item.nameTok)), what, known));
    }
}

std::optional<Vec3> DirectiveReader::vectorValue(const DirectiveItem& item) {
    Vec3 v;
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
        const auto c = exprs_.constant(item.e[i]);
        if (c)
            v[i] = *c;
        else
            ok = false;
    }
    if (!ok) return std::nullopt;
    return v;
}

std::optional<Vec3> DirectiveReader::wantVector(const DirectiveItem& item) {
    if (!item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a vector '<x, y, z>'", clip(ctx_.text(item.nameTok))));
        return std::nullopt;
    }
    return vectorValue(item);
}

std::optional<double> DirectiveReader::wantScalar(const DirectiveItem& item) {
    if (item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a number, not a vector", clip(ctx_.text(item.nameTok))));
        return std::nullopt;
    }
    return exprs_.constant(item.e[0]);
}

void DirectiveReader::settings(const Stmt& s) {
    if (!once(settingsSeen_, s, "settings")) return;
    Settings& st = g_.scene.settings;
    items(s, "settings", "seed, max_depth", [&](std::string_view n, const DirectiveItem& item) {
        if (n == "seed") {
            if (auto v = wantScalar(item)) {
                if (*v < 0 || *v != std::floor(*v) || *v > 9007199254740992.0)
                    ctx_.error(
                        item.nameTok,
                        fmt::format("seed must be a whole number from 0 to 2^53, found {}", *v));
                else
                    st.seed = static_cast<uint64_t>(*v);
            }
        } else if (n == "max_depth") {
            if (auto v = wantScalar(item)) {
                if (*v < 1 || *v != std::floor(*v) || *v > kMaxMaxDepth)
                    ctx_.error(
                        item.nameTok,
                        fmt::format("max_depth must be a whole number from 1 to {}, found {}",
                                    kMaxMaxDepth, *v));
                else
                    st.maxDepth = static_cast<uint32_t>(*v);
            }
        } else {
            return false;
        }
        return true;
    });
}

void DirectiveReader::camera(const Stmt& s) {
    if (!once(cameraSeen_, s, "camera")) return;
    Camera& c = g_.scene.camera;
    bool ok = true;
    items(s, "camera", "location, look_at, sky, angle",
          [&](std::string_view n, const DirectiveItem& item) {
              std::optional<Vec3> v;
              if (n == "location") {
                  if ((v = wantVector(item))) c.location = *v;
              } else if (n == "look_at") {
                  if ((v = wantVector(item))) c.lookAt = *v;
              } else if (n == "sky") {
                  if ((v = wantVector(item))) c.sky = *v;
              } else if (n == "angle") {
                  if (auto a = wantScalar(item)) {
                      if (!(*a > 0 && *a < 180)) {
                          ctx_.error(item.nameTok,
                                     fmt::format("the camera angle must be between 0 and 180 "
                                                 "degrees, found {}",
                                                 *a));
                          ok = false;
                      } else {
                          c.angle = *a;
                      }
                  }
              } else {
                  return false;
              }
              return true;
          });
    if (ok) checkCamera(s);
}

// A camera that can see: a viewing direction, and a sky that is not along it.
void DirectiveReader::checkCamera(const Stmt& s) {
    const Camera& c = g_.scene.camera;
    const Vec3 dir = c.lookAt - c.location;
    if (length(dir) == 0)
        ctx_.error(s.tok, "the camera's location and look_at are the same point");
    else if (length(c.sky) == 0 || length(cross(dir, c.sky)) <= 1e-12 * length(dir) * length(c.sky))
        ctx_.error(s.tok, "the camera's sky vector is zero or parallel to its viewing direction");
}

void DirectiveReader::light(const Stmt& s) {
    Light l;
    items(s, "light", "position, color", [&](std::string_view n, const DirectiveItem& item) {
        if (n == "position") {
            if (auto v = wantVector(item)) l.position = *v;
        } else if (n == "color" || n == "colour") {
            if (auto v = wantVector(item)) l.color = *v;
        } else {
            return false;
        }
        return true;
    });
    g_.scene.lights.push_back(l);
}

void DirectiveReader::background(const Stmt& s) {
    if (!once(backgroundSeen_, s, "background")) return;
    if (auto v = vectorValue(ast_.items[s.first])) g_.scene.background = *v;
}

void DirectiveReader::material(const Stmt& s, const Names& names) {
    auto it = names.materialOfName.find(s.nameTok);
    if (it == names.materialOfName.end()) return;  // a duplicate, reported
    Material& m = g_.materials[it->second];
    items(s, "material", "color, ambient, diffuse, phong, phong_size, reflection",
          [&](std::string_view n, const DirectiveItem& item) {
              if (n == "color" || n == "colour") {
                  if (auto v = wantVector(item)) m.color = *v;
                  return true;
              }
              double* target = n == "ambient"      ? &m.ambient
                               : n == "diffuse"    ? &m.diffuse
                               : n == "phong"      ? &m.phong
                               : n == "phong_size" ? &m.phongSize
                               : n == "reflection" ? &m.reflection
                                                   : nullptr;
              if (!target) return false;
              if (auto v = wantScalar(item)) *target = *v;
              return true;
          });
}

}  // namespace

void readSettings(BuildContext& ctx, ExprCompiler& exprs) {
    DirectiveReader reader(ctx, exprs);
    for (const Stmt& s : ctx.ast.stmts)
        if (s.kind == StmtKind::Directive && s.directive == Kw::Settings) reader.settings(s);
}

void readDirectives(BuildContext& ctx, const Names& names, ExprCompiler& exprs) {
    DirectiveReader reader(ctx, exprs);
    for (const Stmt& s : ctx.ast.stmts) {
        if (s.kind != StmtKind::Directive) continue;
        switch (s.directive) {
            case Kw::Camera:
                reader.camera(s);
                break;
            case Kw::Light:
                reader.light(s);
                break;
            case Kw::Background:
                reader.background(s);
                break;
            case Kw::Material:
                reader.material(s, names);
                break;
            default:
                break;
        }
    }
}

void addDefaultLight(BuildContext& ctx) {
    if (ctx.g.scene.lights.empty()) ctx.g.scene.lights.push_back(Light{});
}

}  // namespace pcsg
