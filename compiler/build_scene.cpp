// The builder's scene phase: camera, light, background, material and settings
// (docs/language.md section 7). See build_scene.h.
#include "build_scene.h"

#include <fmt/format.h>

#include <algorithm>
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
    void traceSetting(std::string_view n, const DirectiveItem& item, Settings& st);
    void camera(const Stmt& s);
    void light(const Stmt& s);
    void background(const Stmt& s);
    void fog(const Stmt& s);
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
    bool oneValue(const DirectiveItem& item);
    bool flag(const DirectiveItem& item);
    bool lightItem(Light& l, std::string_view n, const DirectiveItem& item);
    bool spotItem(Light& l, std::string_view n, const DirectiveItem& item);
    bool areaItem(Light& l, std::string_view n, const DirectiveItem& item);
    void areaLight(Light& l, const DirectiveItem& item);
    std::optional<double> wantNumber(const DirectiveItem& item, uint8_t field, double lo,
                                     const char* rule, double hi = 1e300);
    void checkLight(const Stmt& s, const Light& l, const std::vector<std::string_view>& given);
    bool fogItem(Fog& f, std::string_view n, const DirectiveItem& item);
    std::optional<double> constValue(uint32_t e, const char* what);
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
             fogSeen_ = kNoNode, skySeen_ = kNoNode;
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
    for (uint32_t i = 0; i < s.count; i += 1 + ast_.items[s.first + i].more) {
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

// Whether an item has exactly one value; reports a flag without one, or several.
bool DirectiveReader::oneValue(const DirectiveItem& item) {
    if (item.flag)
        ctx_.error(item.nameTok, fmt::format("'{}' needs a value", clip(ctx_.text(item.nameTok))));
    else if (item.more > 0)
        ctx_.error(item.nameTok, fmt::format("'{}' takes one value, found {}",
                                             clip(ctx_.text(item.nameTok)), item.more + 1));
    return !item.flag && item.more == 0;
}

// Whether a flag item (`spotlight`) stands alone; reports a value after it.
bool DirectiveReader::flag(const DirectiveItem& item) {
    if (!item.flag)
        ctx_.error(item.nameTok, fmt::format("'{}' takes no value", clip(ctx_.text(item.nameTok))));
    return item.flag;
}

std::optional<Vec3> DirectiveReader::wantVector(const DirectiveItem& item, uint8_t field) {
    if (!oneValue(item)) return std::nullopt;
    if (!item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a vector '<x, y, z>'", clip(ctx_.text(item.nameTok))));
        return std::nullopt;
    }
    return vectorValue(item, field);
}

std::optional<double> DirectiveReader::wantScalar(const DirectiveItem& item, uint8_t field) {
    if (!oneValue(item)) return std::nullopt;
    if (item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a number, not a vector", clip(ctx_.text(item.nameTok))));
        return std::nullopt;
    }
    return value(item.e[0], field);
}

constexpr const char* kSettingsTakes = "seed, max_depth, max_trace_level, adc_bailout";

void DirectiveReader::settings(const Stmt& s) {
    if (!once(settingsSeen_, s, "settings")) return;
    Settings& st = g_.scene.settings;
    items(s, "settings", kSettingsTakes, [&](std::string_view n, const DirectiveItem& item) {
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
        } else if (n == "max_trace_level" || n == "adc_bailout") {
            traceSetting(n, item, st);
        } else {
            return false;
        }
        return true;
    });
}

// POV-Ray's max_trace_level (a whole number from 1 to 256, its limit) and adc_bailout (a
// weight from 0 to 1).
void DirectiveReader::traceSetting(std::string_view n, const DirectiveItem& item, Settings& st) {
    const auto v = wantScalar(item, kSetting);
    if (!v) return;
    if (n == "max_trace_level") {
        if (*v < 1 || *v != std::floor(*v) || *v > 256)
            ctx_.error(
                item.nameTok,
                fmt::format("max_trace_level must be a whole number from 1 to 256, found {}", *v));
        else
            st.maxTraceLevel = static_cast<uint32_t>(*v);
    } else if (*v < 0 || *v > 1) {
        ctx_.error(item.nameTok, fmt::format("adc_bailout must be from 0 to 1, found {}", *v));
    } else {
        st.adcBailout = *v;
    }
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

// A number that must be at least `lo` (a value that reads the time is checked per frame
// by nothing: POV-Ray's formulas take any number there).
std::optional<double> DirectiveReader::wantNumber(const DirectiveItem& item, uint8_t field,
                                                  double lo, const char* rule, double hi) {
    const auto v = wantScalar(item, field);
    if (v && !timed_ && !(*v >= lo && *v <= hi)) {
        ctx_.error(item.nameTok, fmt::format("'{}' must be {}, found {}",
                                             clip(ctx_.text(item.nameTok)), rule, *v));
        return std::nullopt;
    }
    return v;
}

// A value that must be a constant, also where the directive's others may read the time.
std::optional<double> DirectiveReader::constValue(uint32_t e, const char* what) {
    const auto v = exprs_.directiveValue(e);
    if (!v) return std::nullopt;
    if (v->timed != kNone) {
        ctx_.error(ast_.exprs[e].from,
                   fmt::format("'{}' reads the time (clock, frame): {} are constants",
                               g_.exprs[v->timed].text, what));
        return std::nullopt;
    }
    return v->value;
}

// area_light <axis1>, <axis2>, size1, size2: two vectors, then two whole numbers >= 1.
void DirectiveReader::areaLight(Light& l, const DirectiveItem& item) {
    const DirectiveItem* v = &item;
    if (item.flag || item.more != 3 || !v[0].vector || !v[1].vector || v[2].vector || v[3].vector) {
        ctx_.error(item.nameTok,
                   "'area_light' takes <axis1>, <axis2>, size1, size2 (two "
                   "vectors and two whole numbers)");
        return;
    }
    Vec3 axes[2];
    for (int a = 0; a < 2; ++a)
        for (int i = 0; i < 3; ++i)
            if (auto c = constValue(v[a].e[i], "area_light's values")) axes[a][i] = *c;
    int sizes[2] = {1, 1};
    for (int a = 0; a < 2; ++a) {
        const auto n = constValue(v[2 + a].e[0], "area_light's values");
        if (!n) continue;
        if (!(*n >= 1 && *n <= 1000 && *n == std::floor(*n)))
            ctx_.error(item.nameTok, fmt::format("area_light's size{} must be a whole number "
                                                 "from 1 to 1000, found {}",
                                                 a + 1, *n));
        else
            sizes[a] = static_cast<int>(*n);
    }
    l.axis1 = axes[0];
    l.axis2 = axes[1];
    l.size1 = sizes[0];
    l.size2 = sizes[1];
}

bool DirectiveReader::spotItem(Light& l, std::string_view n, const DirectiveItem& item) {
    std::optional<double> v;
    if (n == "spotlight") {
        l.spotlight = flag(item);
    } else if (n == "point_at") {
        if (auto p = wantVector(item, 6)) l.pointAt = *p;
    } else if (n == "radius") {
        if ((v = wantNumber(item, 11, 0, "from 0 to 90 degrees", 90))) l.radius = *v;
    } else if (n == "falloff") {
        if ((v = wantNumber(item, 12, 0, "from 0 to 90 degrees", 90))) l.falloff = *v;
    } else if (n == "tightness") {
        if ((v = wantNumber(item, 13, 0, "0 or more"))) l.tightness = *v;
    } else {
        return false;
    }
    return true;
}

bool DirectiveReader::areaItem(Light& l, std::string_view n, const DirectiveItem& item) {
    if (n == "area_light") {
        areaLight(l, item);
    } else if (n == "adaptive") {
        if (oneValue(item) && !item.vector) {
            const auto a = constValue(item.e[0], "adaptive's values");
            if (a && !(*a >= 0 && *a <= 100 && *a == std::floor(*a)))
                ctx_.error(item.nameTok,
                           fmt::format("'adaptive' must be a whole number from 0 to 100, "
                                       "found {}",
                                       *a));
            else if (a)
                l.adaptive = static_cast<int>(*a);
        } else if (!item.flag && item.more == 0) {
            ctx_.error(item.nameTok, "'adaptive' takes a number, not a vector");
        }
    } else if (n == "jitter") {
        l.jitter = flag(item);
    } else if (n == "circular") {
        l.circular = flag(item);
    } else if (n == "orient") {
        l.orient = flag(item);
    } else {
        return false;
    }
    return true;
}

bool DirectiveReader::lightItem(Light& l, std::string_view n, const DirectiveItem& item) {
    std::optional<double> v;
    if (n == "position") {
        if (auto p = wantVector(item, 0)) l.position = *p;
    } else if (n == "color" || n == "colour") {
        if (auto c = wantVector(item, 3)) l.color = *c;
    } else if (n == "shadowless") {
        l.shadowless = flag(item);
    } else if (n == "fade_distance") {
        if ((v = wantNumber(item, 9, 0, "0 or more"))) l.fadeDistance = *v;
    } else if (n == "fade_power") {
        if ((v = wantNumber(item, 10, 0, "0 or more"))) l.fadePower = *v;
    } else {
        return spotItem(l, n, item) || areaItem(l, n, item);
    }
    return true;
}

constexpr const char* kLightItems =
    "position, color, shadowless, fade_distance, fade_power, spotlight, point_at, radius, "
    "falloff, tightness, area_light, adaptive, jitter, circular, orient";

void DirectiveReader::light(const Stmt& s) {
    Light l;
    target(DirectiveTarget::Light, static_cast<uint32_t>(g_.scene.lights.size()));
    std::vector<std::string_view> given;
    items(s, "light", kLightItems, [&](std::string_view n, const DirectiveItem& item) {
        given.push_back(n);
        return lightItem(l, n, item);
    });
    checkLight(s, l, given);
    g_.scene.lights.push_back(l);
}

// The items that need another: spotlight's, area_light's; and what POV-Ray cannot do.
void DirectiveReader::checkLight(const Stmt& s, const Light& l,
                                 const std::vector<std::string_view>& given) {
    const bool area = std::find(given.begin(), given.end(), "area_light") != given.end();
    for (std::string_view n : given) {
        if (!l.spotlight &&
            (n == "point_at" || n == "radius" || n == "falloff" || n == "tightness"))
            ctx_.error(s.tok, fmt::format("'{}' needs 'spotlight' in the same light", n));
        if (!area && (n == "adaptive" || n == "jitter" || n == "circular" || n == "orient"))
            ctx_.error(s.tok, fmt::format("'{}' needs 'area_light' in the same light", n));
    }
    if (l.spotlight && l.shadowless)
        ctx_.error(s.tok,
                   "a light cannot be both 'spotlight' and 'shadowless' (POV-Ray 3.7 "
                   "makes a shadowless light a fill light, which has no cone)");
    if (l.circular && (l.size1 <= 1 || l.size2 <= 1))
        ctx_.error(s.tok, "a 'circular' area_light needs sizes greater than 1");
}

void DirectiveReader::background(const Stmt& s) {
    if (!once(backgroundSeen_, s, "background")) return;
    target(DirectiveTarget::Background);
    if (auto v = vectorValue(ast_.items[s.first], 0)) g_.scene.background = *v;
}

// fog's values are constants (docs/language.md section 10).
bool DirectiveReader::fogItem(Fog& f, std::string_view n, const DirectiveItem& item) {
    const char* what = "fog's values";
    if (n == "color" || n == "colour") {
        if (!oneValue(item)) return true;
        if (!item.vector) {
            ctx_.error(item.nameTok, "the fog's 'color' takes a vector '<r, g, b>'");
            return true;
        }
        for (int i = 0; i < 3; ++i)
            if (auto c = constValue(item.e[i], what)) f.color[i] = *c;
        return true;
    }
    double* target = n == "distance"     ? &f.distance
                     : n == "filter"     ? &f.filter
                     : n == "transmit"   ? &f.transmit
                     : n == "fog_offset" ? &f.offset
                     : n == "fog_alt"    ? &f.alt
                                         : nullptr;
    double type = 0;
    if (n == "fog_type") target = &type;
    if (!target) return false;
    if (!oneValue(item)) return true;
    if (item.vector) {
        ctx_.error(item.nameTok,
                   fmt::format("'{}' takes a number, not a vector", clip(ctx_.text(item.nameTok))));
        return true;
    }
    const auto v = constValue(item.e[0], what);
    if (!v) return true;
    const bool unit = n == "filter" || n == "transmit";
    if (n == "fog_type" && !(*v == 1 || *v == 2))
        ctx_.error(item.nameTok, fmt::format("'fog_type' must be 1 (constant) or 2 (ground), "
                                             "found {}",
                                             *v));
    else if ((n == "distance" || n == "fog_alt") && !(*v > 0))
        ctx_.error(item.nameTok, fmt::format("'{}' must be greater than 0, found {}", n, *v));
    else if (unit && !(*v >= 0 && *v <= 1))
        ctx_.error(item.nameTok, fmt::format("'{}' must be from 0 to 1, found {}", n, *v));
    else if (n == "fog_type")
        f.type = static_cast<int>(*v);
    else
        *target = *v;
    return true;
}

void DirectiveReader::fog(const Stmt& s) {
    if (!once(fogSeen_, s, "fog")) return;
    Fog f;
    std::vector<std::string_view> given;
    items(s, "fog", "distance, color, filter, transmit, fog_type, fog_offset, fog_alt",
          [&](std::string_view n, const DirectiveItem& item) {
              given.push_back(n);
              return fogItem(f, n, item);
          });
    auto has = [&](std::string_view n) {
        return std::find(given.begin(), given.end(), n) != given.end();
    };
    if (!has("distance")) ctx_.error(s.tok, "a fog needs a 'distance'");
    if (f.type != 2)
        for (std::string_view n : {"fog_offset", "fog_alt"})
            if (has(n)) ctx_.error(s.tok, fmt::format("'{}' needs 'fog_type 2' (ground fog)", n));
    f.enabled = f.distance > 0;
    g_.scene.fog = f;
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
            case Kw::Fog:
                reader.fog(s);
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
