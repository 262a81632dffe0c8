// Setting the time of a frame: see scene_time.h.
#include "scene_time.h"

#include <fmt/format.h>

#include <cmath>

#include "eval.h"

namespace pcsg {

namespace {

double* vectorField(Vec3& v, uint8_t i) {
    return i == 0 ? &v.x : (i == 1 ? &v.y : &v.z);
}

// The number a timed value sets.
double* targetOf(Graph& g, const TimedValue& tv) {
    const uint8_t f = tv.field;
    switch (tv.target) {
        case DirectiveTarget::Camera: {
            Camera& c = g.scene.camera;
            if (f == 9) return &c.angle;
            return vectorField(f < 3 ? c.location : (f < 6 ? c.lookAt : c.sky), f % 3);
        }
        case DirectiveTarget::Light: {
            Light& l = g.scene.lights[tv.index];
            double* scalars[] = {&l.fadeDistance, &l.fadePower, &l.radius, &l.falloff,
                                 &l.tightness};
            if (f >= 9) return scalars[f - 9];
            return vectorField(f < 3 ? l.position : (f < 6 ? l.color : l.pointAt), f % 3);
        }
        case DirectiveTarget::Background:
            return vectorField(g.scene.background, f);
        case DirectiveTarget::Material: {
            Material& m = g.materials[tv.index];
            double* scalars[] = {&m.ambient,    &m.diffuse,       &m.phong,    &m.phongSize,
                                 &m.reflection, &m.brilliance,    &m.specular, &m.roughness,
                                 &m.metallic,   &m.reflectionMin, &m.ior,      &m.filter,
                                 &m.transmit};
            return f < 3 ? vectorField(m.color, f) : scalars[f - 3];
        }
    }
    return nullptr;
}

// The camera checks of the builder (build_scene.cpp), at this time.
void checkCamera(const Graph& g, FileLoc loc) {
    const Camera& c = g.scene.camera;
    const std::string when = describeTime(g.time);
    if (!(c.angle > 0 && c.angle < 180))
        throw RuntimeError(loc, fmt::format("the camera angle must be between 0 and 180 "
                                            "degrees, found {} at {}",
                                            c.angle, when));
    const Vec3 dir = c.lookAt - c.location;
    if (length(dir) == 0)
        throw RuntimeError(loc, fmt::format("the camera's location and look_at are the same "
                                            "point at {}",
                                            when));
    if (length(c.sky) == 0 || length(cross(dir, c.sky)) <= 1e-12 * length(dir) * length(c.sky))
        throw RuntimeError(loc, fmt::format("the camera's sky vector is zero or parallel to its "
                                            "viewing direction at {}",
                                            when));
}

}  // namespace

std::string describeTime(const Time& t) {
    return fmt::format("clock {}, frame {}", t.clock, t.frame);
}

void setTime(Graph& g, Time t) {
    g.time = t;
    FileLoc cameraLoc;
    bool camera = false;
    for (const TimedValue& tv : g.timedValues) {
        const Expr& e = g.exprs[tv.expr];
        const double v = evalExpr(g, tv.expr, EvalState{nullptr, kRootPath});
        if (!std::isfinite(v))
            throw RuntimeError(e.loc, fmt::format("the directive value '{}' is {} (not a finite "
                                                  "number) at {}",
                                                  e.text, v, describeTime(t)));
        *targetOf(g, tv) = v;
        if (tv.target == DirectiveTarget::Camera && !camera) {
            camera = true;
            cameraLoc = e.loc;
        }
    }
    if (camera) checkCamera(g, cameraLoc);
}

}  // namespace pcsg
