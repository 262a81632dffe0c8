// The builder's scene phase: camera, light, background, material and settings
// (docs/language.md section 7). See build_scene.h.
#include "build_scene.h"

#include <fmt/format.h>

#include <cmath>

#include "build_material.h"
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
    void skySphere(const Stmt& s) {
        if (once(skySeen_, s, "sky_sphere")) readSkySphere(ctx_, exprs_, s);
    }

  private:
    bool once(uint32_t& seen, const Stmt& s, const char* what);
    template <class F>
    void items(const Stmt& s, const char* what, const char* known, F set);
    std::optional<double> value(uint32_t e, uint8_t field);
    std::optional<Vec3> vectorValue(const DirectiveItem& item, uint8_t field);
    std::optional<Vec3> wantVector(const DirectiveItem& item, uint8_t field);
    std::optional<double> wantScalar(const DirectiveItem& item, uint8_t field);
    void checkCamera(const Stmt& s);
    // Where the values read next go, should they read the time (TimedValue).
    void target(DirectiveTarget t, uint32_t index = 0) {
        target_ = t;
        index_ = index;
    }

    BuildContext& ctx_;
    Graph& g_;
    const Ast& ast_;
    ExprCompiler& exprs_;
    uint32_t settingsSeen_ = kNoNode, cameraSeen_ = kNoNode, backgroundSeen_ = kNoNode,
             skySeen_ = kNoNode;
    DirectiveTarget target_ = DirectiveTarget::Camera;
    uint32_t index_ = 0;
    bool timed_ = false;  // the last value read reads the time
};

// kSetting as the field: a settings value, which must be a constant.
constexpr uint8_t kSetting = 255;

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

// A directive's value: a constant, or for other directives than settings one that reads
// the time, recorded as a TimedValue of the current target.
std::optional<double> DirectiveReader::value(uint32_t e, uint8_t field) {
    timed_ = false;
    if (field == kSetting) return exprs_.constant(e);
    const auto v = exprs_.directiveValue(e);
    if (!v) return std::nullopt;
    if (v->timed != kNone) {
        g_.timedValues.push_back(TimedValue{target_, index_, field, v->timed});
        timed_ = true;
    }
    return v->value;
}

std::optional<Vec3> DirectiveReader::vectorValue(const DirectiveItem& item, uint8_t field) {
    Vec3 v;
    bool ok = true;
    for (int i = 0; i < 3; ++i) {
        const auto c = value(item.e[i], static_cast<uint8_t>(field + i));
        if (c)
            v[i] = *c;
        else
            ok = false;
    }
    if (!ok) return std::nullopt;
    return v;
}

std::optional<Vec3> DirectiveReader::wantVector(const DirectiveItem& item, uint8_t field) {
    if (!item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a vector '<x, y, z>'", clip(ctx_.text(item.nameTok))));
        return std::nullopt;
    }
    return vectorValue(item, field);
}

std::optional<double> DirectiveReader::wantScalar(const DirectiveItem& item, uint8_t field) {
    if (item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a number, not a vector", clip(ctx_.text(item.nameTok))));
        return std::nullopt;
    }
    return value(item.e[0], field);
}

void DirectiveReader::settings(const Stmt& s) {
    if (!once(settingsSeen_, s, "settings")) return;
    Settings& st = g_.scene.settings;
    items(s, "settings", "seed, max_depth", [&](std::string_view n, const DirectiveItem& item) {
        if (n == "seed") {
            if (auto v = wantScalar(item, kSetting)) {
                if (*v < 0 || *v != std::floor(*v) || *v > 9007199254740992.0)
                    ctx_.error(
                        item.nameTok,
                        fmt::format("seed must be a whole number from 0 to 2^53, found {}", *v));
                else
                    st.seed = static_cast<uint64_t>(*v);
            }
        } else if (n == "max_depth") {
            if (auto v = wantScalar(item, kSetting)) {
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
    target(DirectiveTarget::Camera);
    bool ok = true;
    items(s, "camera", "location, look_at, sky, angle",
          [&](std::string_view n, const DirectiveItem& item) {
              std::optional<Vec3> v;
              if (n == "location") {
                  if ((v = wantVector(item, 0))) c.location = *v;
              } else if (n == "look_at") {
                  if ((v = wantVector(item, 3))) c.lookAt = *v;
              } else if (n == "sky") {
                  if ((v = wantVector(item, 6))) c.sky = *v;
              } else if (n == "angle") {
                  if (auto a = wantScalar(item, 9)) {
                      if (!timed_ && !(*a > 0 && *a < 180)) {
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

// A camera that can see: a viewing direction, and a sky that is not along it. (A camera
// that moves is checked at each frame's time, by setTime().)
void DirectiveReader::checkCamera(const Stmt& s) {
    for (const TimedValue& tv : g_.timedValues)
        if (tv.target == DirectiveTarget::Camera) return;
    const Camera& c = g_.scene.camera;
    const Vec3 dir = c.lookAt - c.location;
    if (length(dir) == 0)
        ctx_.error(s.tok, "the camera's location and look_at are the same point");
    else if (length(c.sky) == 0 || length(cross(dir, c.sky)) <= 1e-12 * length(dir) * length(c.sky))
        ctx_.error(s.tok, "the camera's sky vector is zero or parallel to its viewing direction");
}

void DirectiveReader::light(const Stmt& s) {
    Light l;
    target(DirectiveTarget::Light, static_cast<uint32_t>(g_.scene.lights.size()));
    items(s, "light", "position, color", [&](std::string_view n, const DirectiveItem& item) {
        if (n == "position") {
            if (auto v = wantVector(item, 0)) l.position = *v;
        } else if (n == "color" || n == "colour") {
            if (auto v = wantVector(item, 3)) l.color = *v;
        } else {
            return false;
        }
        return true;
    });
    g_.scene.lights.push_back(l);
}

void DirectiveReader::background(const Stmt& s) {
    if (!once(backgroundSeen_, s, "background")) return;
    target(DirectiveTarget::Background);
    if (auto v = vectorValue(ast_.items[s.first], 0)) g_.scene.background = *v;
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
            case Kw::SkySphere:
                reader.skySphere(s);
                break;
            case Kw::Material:
                if (auto it = names.materialOfName.find(s.nameTok);
                    it != names.materialOfName.end())  // else a duplicate, reported
                    readMaterial(ctx, exprs, s, it->second);
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
