// pcsg-embree: the yardstick of `pcsg bench`. A good BVH ray tracer on the expanded mesh
// is the limit for pcsg's performance, so this program expands a triangle-only scene with
// the project's own expander (povexport/expander.h), builds one Embree 3 scene of it at
// Embree's highest build quality for static scenes, and traces the rays pcsg traces: one
// camera ray per pixel centre (tracer/camera.h, the scene's camera) and one shadow ray per
// hit toward each light, on a fixed number of threads (oneTBB over bands of rows). It
// traces packets of 8: Embree's rtcIntersect8 on blocks of 4 x 2 pixels and rtcOccluded8
// for their shadow rays. Here they trace Sierpinski order 8 and the terrain 6-22% faster
// than rtcIntersect1 and rtcOccluded1 one ray at a time (--single). The rays are traced
// --passes times (5) and the trace time is the median pass's: one pass of 640 x 480 takes
// Embree 15-40 ms, in which oneTBB's threads starting up and the BVH's first touches
// weigh. It prints the triangles, the build and trace times, the rays of a pass, rays per
// second and its own peak RSS; `--json` prints them as JSON.
//
// Exit status: 0 done; 1 the scene did not compile or expand; 2 a bad command line, or a
// scene with a primitive that is not a triangle (a tetrahedron counts as its 4 faces) or
// with an intersection or difference (Embree traces surfaces, not CSG).
#include <embree3/rtcore.h>
#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <cmath>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "camera.h"
#include "expander.h"
#include "primitive_table.h"
#include "scene_input.h"
#include "yardstick.h"

namespace pcsg::embree_bench {
namespace {

using yardstick::Clock;
using yardstick::secondsSince;

struct Options : yardstick::TraceOptions {
    uint64_t maxNodes = 10'000'000;
    bool single = false;  // one ray at a time instead of packets of 8
};

struct Figures {
    uint64_t triangles = 0;
    double expandSeconds = 0, buildSeconds = 0;
    yardstick::Passes passes;
    uint64_t hits = 0;  // of a pass's camera rays
    uint64_t peakRssBytes = 0;
};

// Why the expanded tree cannot be traced as one triangle mesh, or nothing: every operator
// must be a union, and every primitive a triangle or a tetrahedron (its 4 faces).
std::string unsupportedIn(const ExpandedTree& tree) {
    for (const TreeNode& n : tree.nodes)
        if (!n.primitive && n.op != CsgOp::Union)
            return "the scene has an intersection or difference (CSG), which a triangle mesh "
                   "cannot express";
    for (const TreePrimitive& p : tree.primitives)
        if (p.kind != PrimitiveKind::Tetrahedron && !isTriangle(p.kind))
            return fmt::format(
                "the scene has a {} primitive; pcsg-embree traces only triangles "
                "(triangle, tri1, tri2) and tetrahedra",
                primitiveInfo(p.kind).name);
    return {};
}

// The mesh's size: 4 vertices and 4 faces per tetrahedron, 3 and 1 per triangle.
void meshSize(const ExpandedTree& tree, size_t& vertices, size_t& triangles) {
    vertices = triangles = 0;
    for (const TreePrimitive& p : tree.primitives) {
        const bool tetra = p.kind == PrimitiveKind::Tetrahedron;
        vertices += tetra ? 4 : 3;
        triangles += tetra ? 4 : 1;
    }
}

// Writes the world-space mesh of the tree into Embree's vertex and index buffers.
void fillMesh(const ExpandedTree& tree, float* v, uint32_t* i) {
    uint32_t base = 0;
    auto vertex = [&v](const Affine& toWorld, const Vec3& p) {
        const Vec3 w = toWorld.point(p);
        *v++ = float(w.x), *v++ = float(w.y), *v++ = float(w.z);
    };
    for (const TreePrimitive& p : tree.primitives) {
        if (p.kind == PrimitiveKind::Tetrahedron) {
            for (const Vec3& c : kTetraVertices) vertex(p.toWorld, c);
            // Face k is opposite vertex k.
            for (const uint32_t f : {1u, 2u, 3u, 0u, 2u, 3u, 0u, 1u, 3u, 0u, 1u, 2u})
                *i++ = base + f;
            base += 4;
        } else {
            Vec3 c[3];
            triangleCorners(p.kind, p.firstArg == kNone ? nullptr : &tree.args[p.firstArg], c);
            for (const Vec3& corner : c) vertex(p.toWorld, corner);
            *i++ = base, *i++ = base + 1, *i++ = base + 2;
            base += 3;
        }
    }
}

// Builds the Embree scene of the tree's mesh at Embree's best quality for a static scene:
// a high-quality (spatial split) BVH, no dynamic, compact or robust flags, as Embree's
// documentation recommends for the fastest traversal. The mesh goes straight into
// Embree's buffers, and the tree is released before the BVH is built.
RTCScene buildScene(RTCDevice device, ExpandedTree tree, uint64_t& triangles) {
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_HIGH);
    size_t nv = 0, nt = 0;
    meshSize(tree, nv, nt);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), nv));
    auto* i = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), nt));
    fillMesh(tree, v, i);
    tree = ExpandedTree{};
    triangles = nt;
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene);
    return scene;
}

RTCRayHit cameraRay(const tracer::PinholeCamera& camera, int px, int py) {
    const tracer::Ray r = camera.ray(px + 0.5, py + 0.5);
    RTCRayHit rh{};
    rh.ray.org_x = float(r.origin.x), rh.ray.org_y = float(r.origin.y);
    rh.ray.org_z = float(r.origin.z);
    rh.ray.dir_x = float(r.dir.x), rh.ray.dir_y = float(r.dir.y), rh.ray.dir_z = float(r.dir.z);
    rh.ray.tnear = 0;
    rh.ray.tfar = INFINITY;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

// The shadow ray from the hit at t along the ray (o, d) toward the light: its direction
// reaches the light at t = 1, and it starts a little off the surface.
struct ShadowRay {
    float org[3], dir[3], tnear;
};

ShadowRay shadowRayFrom(const float o[3], const float d[3], float t, const Light& light) {
    ShadowRay s;
    for (int a = 0; a < 3; ++a) s.org[a] = o[a] + t * d[a];
    s.dir[0] = float(light.position.x) - s.org[0];
    s.dir[1] = float(light.position.y) - s.org[1];
    s.dir[2] = float(light.position.z) - s.org[2];
    const float length = std::sqrt(s.dir[0] * s.dir[0] + s.dir[1] * s.dir[1] + s.dir[2] * s.dir[2]);
    s.tnear = length > 0 ? 1e-4f / length : 0;
    return s;
}

// One shadow ray from the hit toward the light: true when something is in the way.
bool shadowed(RTCScene scene, const RTCRayHit& rh, const Light& light) {
    const float o[3] = {rh.ray.org_x, rh.ray.org_y, rh.ray.org_z};
    const float d[3] = {rh.ray.dir_x, rh.ray.dir_y, rh.ray.dir_z};
    const ShadowRay s = shadowRayFrom(o, d, rh.ray.tfar, light);
    RTCRay ray{};
    ray.org_x = s.org[0], ray.org_y = s.org[1], ray.org_z = s.org[2];
    ray.dir_x = s.dir[0], ray.dir_y = s.dir[1], ray.dir_z = s.dir[2];
    ray.tnear = s.tnear;
    ray.tfar = 1;
    ray.mask = ~0u;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    rtcOccluded1(scene, &context, &ray);
    return ray.tfar < 0;  // Embree sets tfar to -inf when occluded
}

// Traces every pixel's camera ray and, for a hit, a shadow ray toward each light, one ray
// at a time (--single).
void trace(RTCScene scene, const Scene& s, const Options& o, Figures& f) {
    const tracer::PinholeCamera camera(s.camera, o.width, o.height);
    std::atomic<uint64_t> rays{0}, hits{0}, lit{0};
    tbb::parallel_for(tbb::blocked_range<int>(0, o.height), [&](const tbb::blocked_range<int>& r) {
        uint64_t localRays = 0, localHits = 0, localLit = 0;
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        for (int py = r.begin(); py < r.end(); ++py)
            for (int px = 0; px < o.width; ++px) {
                RTCRayHit rh = cameraRay(camera, px, py);
                rtcIntersect1(scene, &context, &rh);
                ++localRays;
                if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) continue;
                ++localHits;
                for (const Light& light : s.lights) {
                    ++localRays;
                    if (!shadowed(scene, rh, light)) ++localLit;
                }
            }
        rays += localRays, hits += localHits, lit += localLit;
    });
    f.passes.rays = rays, f.hits = hits;
}

// Packets of 8 (the default): the camera rays of a 4 x 2 block of pixels in one
// rtcIntersect8 (coherent), and the shadow rays of its hits toward each light in one
// rtcOccluded8. The same rays as trace(); Embree's packet path for coherent rays.
struct alignas(32) Lanes {
    int valid[8];
};

void cameraPacket(const tracer::PinholeCamera& camera, int x0, int y0, const Options& o,
                  RTCRayHit8& rh, Lanes& lanes) {
    for (int k = 0; k < 8; ++k) {
        const int px = x0 + k % 4, py = y0 + k / 4;
        lanes.valid[k] = px < o.width && py < o.height ? -1 : 0;
        const RTCRay r = cameraRay(camera, px, py).ray;
        rh.ray.org_x[k] = r.org_x, rh.ray.org_y[k] = r.org_y, rh.ray.org_z[k] = r.org_z;
        rh.ray.dir_x[k] = r.dir_x, rh.ray.dir_y[k] = r.dir_y, rh.ray.dir_z[k] = r.dir_z;
        rh.ray.tnear[k] = r.tnear, rh.ray.tfar[k] = r.tfar, rh.ray.time[k] = 0;
        rh.ray.mask[k] = r.mask, rh.ray.id[k] = 0, rh.ray.flags[k] = 0;
        rh.hit.geomID[k] = RTC_INVALID_GEOMETRY_ID;
    }
}

// The shadow rays of the packet's hits toward the light (shadowRayFrom, as shadowed()
// makes each one); returns the lanes traced.
int shadowPacket(RTCScene scene, RTCIntersectContext& context, const RTCRayHit8& rh,
                 const Lanes& hits, const Light& light) {
    RTCRay8 ray{};
    int traced = 0;
    for (int k = 0; k < 8; ++k) {
        const float o[3] = {rh.ray.org_x[k], rh.ray.org_y[k], rh.ray.org_z[k]};
        const float d[3] = {rh.ray.dir_x[k], rh.ray.dir_y[k], rh.ray.dir_z[k]};
        const ShadowRay s = shadowRayFrom(o, d, rh.ray.tfar[k], light);
        ray.org_x[k] = s.org[0], ray.org_y[k] = s.org[1], ray.org_z[k] = s.org[2];
        ray.dir_x[k] = s.dir[0], ray.dir_y[k] = s.dir[1], ray.dir_z[k] = s.dir[2];
        ray.tnear[k] = s.tnear, ray.tfar[k] = 1, ray.mask[k] = ~0u;
        traced += hits.valid[k] != 0;
    }
    rtcOccluded8(hits.valid, scene, &context, &ray);
    return traced;
}

void tracePackets(RTCScene scene, const Scene& s, const Options& o, Figures& f) {
    const tracer::PinholeCamera camera(s.camera, o.width, o.height);
    std::atomic<uint64_t> rays{0}, hits{0};
    tbb::parallel_for(
        tbb::blocked_range<int>(0, (o.height + 1) / 2), [&](const tbb::blocked_range<int>& r) {
            uint64_t localRays = 0, localHits = 0;
            RTCIntersectContext context;
            rtcInitIntersectContext(&context);
            context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
            for (int band = r.begin(); band < r.end(); ++band)
                for (int x0 = 0; x0 < o.width; x0 += 4) {
                    RTCRayHit8 rh;
                    Lanes lanes, hit;
                    cameraPacket(camera, x0, 2 * band, o, rh, lanes);
                    rtcIntersect8(lanes.valid, scene, &context, &rh);
                    int count = 0;
                    for (int k = 0; k < 8; ++k) {
                        localRays += lanes.valid[k] != 0;
                        hit.valid[k] =
                            lanes.valid[k] != 0 && rh.hit.geomID[k] != RTC_INVALID_GEOMETRY_ID ? -1
                                                                                               : 0;
                        count += hit.valid[k] != 0;
                    }
                    localHits += count;
                    if (count == 0) continue;
                    for (const Light& light : s.lights)
                        localRays += shadowPacket(scene, context, rh, hit, light);
                }
            rays += localRays, hits += localHits;
        });
    f.passes.rays = rays, f.hits = hits;
}

void print(const Options& o, const Figures& f) {
    if (o.json) {
        nlohmann::json j = yardstick::traceJson(o, f.passes, f.peakRssBytes);
        j["triangles"] = f.triangles;
        j["expand_seconds"] = f.expandSeconds;
        j["build_seconds"] = f.buildSeconds;
        j["packets"] = !o.single;
        j["hits"] = f.hits;
        std::cout << j.dump(2) << "\n";
        return;
    }
    std::cout << fmt::format(
        "scene:           {}\nimage:           {}x{}, {} threads\ntriangles:       {}\n"
        "expand time:     {:.3f} s\nbuild time:      {:.3f} s\n"
        "trace time:      {:.3f} s, the median of {} passes ({})\n"
        "rays:            {}\nrays/s:          {:.0f}\npeak RSS:        {:.1f} MB\n",
        o.scene, o.width, o.height, o.threads, f.triangles, f.expandSeconds, f.buildSeconds,
        f.passes.median(), o.passes, o.single ? "one ray at a time" : "packets of 8", f.passes.rays,
        f.passes.raysPerSecond(), f.peakRssBytes / 1e6);
}

// Expands the scene; nothing (with the message printed) when it cannot be traced as a
// triangle mesh, and the exit status in `status`.
std::optional<ExpandedTree> loadTree(const Options& o, Graph& g, Figures& f, int& status) {
    const Clock::time_point start = Clock::now();
    std::optional<ExpandedTree> tree;
    try {
        ExpandOptions eo;
        eo.maxNodes = o.maxNodes;
        tree = expand(g, eo);
    } catch (const std::exception& e) {
        std::cerr << "pcsg-embree: " << o.scene << ": " << e.what() << "\n";
        status = 1;
        return std::nullopt;
    }
    f.expandSeconds = secondsSince(start);
    if (const std::string why = unsupportedIn(*tree); !why.empty()) {
        std::cerr << "pcsg-embree: " << o.scene << ": " << why << "\n";
        status = 2;
        return std::nullopt;
    }
    return tree;
}

int run(const Options& o) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(o.threads));
    tools::CompiledScene compiled = tools::compileScene(o.scene, std::cerr);
    if (!compiled.graph) return 1;
    Figures f;
    int status = 0;
    std::optional<ExpandedTree> tree = loadTree(o, *compiled.graph, f, status);
    if (!tree) return status;
    RTCDevice device = rtcNewDevice(fmt::format("threads={}", o.threads).c_str());
    if (!device) {
        std::cerr << "pcsg-embree: cannot create an Embree device\n";
        return 1;
    }
    Clock::time_point start = Clock::now();
    RTCScene scene = buildScene(device, std::move(*tree), f.triangles);
    tree.reset();
    f.buildSeconds = secondsSince(start);
    for (int pass = 0; pass < o.passes; ++pass) {
        start = Clock::now();
        if (o.single)
            trace(scene, compiled.graph->scene, o, f);
        else
            tracePackets(scene, compiled.graph->scene, o, f);
        f.passes.seconds.push_back(secondsSince(start));
    }
    f.peakRssBytes = yardstick::peakRssBytes();
    rtcReleaseScene(scene);
    rtcReleaseDevice(device);
    print(o, f);
    return 0;
}

}  // namespace
}  // namespace pcsg::embree_bench

int main(int argc, char** argv) {
    pcsg::embree_bench::Options o;
    CLI::App app{
        "Trace a triangle-only pcsg scene with Embree 3 on its expanded mesh (the yardstick of "
        "`pcsg bench`): one camera ray per pixel centre and one shadow ray per hit and light."};
    pcsg::yardstick::addTraceOptions(app, o);
    app.add_option("--max-nodes", o.maxNodes, "Expansion budget")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_flag("--single", o.single,
                 "Trace one ray at a time (rtcIntersect1 and rtcOccluded1) instead of packets "
                 "of 8 (rtcIntersect8 on 4 x 2 pixels, rtcOccluded8 for their shadow rays)");
    if (const int status = pcsg::yardstick::parse(app, argc, argv); status >= 0) return status;
    return pcsg::embree_bench::run(o);
}
