// POV-Ray 3.7's default solid noise, reproduced operation for operation so that the values
// are the same to the last bit (the sums are done in POV-Ray's order; this file is compiled
// without floating-point contraction, see tracer/CMakeLists.txt).
//
// What POV-Ray 3.7.0 does (source/backend/texture/texture.cpp: Initialize_Noise,
// InitTextureTable, OriNoise, OriDNoise, Turbulence, DTurbulence; EPSILON = 1e-10 from
// frame.h), in our words:
//
//  - A hash table of 8192 entries: the identity 0..4095 shuffled from the top down, entry i
//    swapped with entry j = ((r >> 16) & 0x7FFF) mod 4096, r the 32-bit linear congruential
//    generator r = r * 1812433253 + 12345 started at r = 0 and stepped before each draw;
//    then the 4096 entries repeated once.
//  - The random table: POV-Ray's 267 constants (noise_tables.cpp) at even indices, each
//    halved at the following odd index.
//  - A point's lattice cell: t = (int)x for x >= 0, (int)(x - (1 - EPSILON)) below (a floor
//    that rounds values within EPSILON below an integer up); the cell index is
//    (t + 10000) & 0xFFF and the fraction x - t. The same for y and z.
//  - Each of the 8 corners c takes m = 2 * (hash[hash[hash[ix] ^ iy] ^ iz] & 0xFF) into the
//    random table and contributes w * (R[m+1] + R[m+2] dx + R[m+4] dy + R[m+6] dz), with
//    dx, dy, dz the offsets from the corner and w the product of the smoothstep weights
//    s = f^2 (3 - 2 f) (1 - s on the low side).
//  - Noise (generator 2, "range corrected"): (sum + 1.05242) * 0.48985582, clamped to
//    [0, 1]. DNoise: the same with three tables offset by 0, 8 and 16 entries, one per
//    component, unclamped and without the offset, corners summed in another order.
//  - Turbulence (generator 2): clamp(2 noise(p) - 0.5, 0, 1) plus, for octaves 2..n,
//    omega^(i-1) (2 noise(lambda^(i-1) p) - 0.5), unclamped. DTurbulence: dnoise(p) plus
//    omega^(i-1) dnoise(lambda^(i-1) p).
#include "noise.h"

#include <cmath>
#include <cstdint>
#include <limits>

#include "noise_tables.h"

namespace pcsg {
namespace {

constexpr double kEpsilon = 1e-10;  // POV-Ray's EPSILON
constexpr int kMinCoordinate = -10000;

struct NoiseTables {
    uint16_t hash[8192];
    double r[267 * 2];
};

// POV-Ray's generator step: 32-bit wrap-around arithmetic, as its `int` computed in `long`
// and stored back into `int` does.
constexpr uint32_t nextRandom(uint32_t r) {
    return r * 1812433253u + 12345u;
}
constexpr int randomDraw(uint32_t r) {
    return static_cast<int>((r >> 16) & 0x7FFF);
}

constexpr NoiseTables buildTables() {
    NoiseTables t{};
    for (int i = 0; i < 4096; ++i) t.hash[i] = static_cast<uint16_t>(i);
    uint32_t r = 0;
    for (int i = 4095; i >= 0; --i) {
        r = nextRandom(r);
        const int j = randomDraw(r) % 4096;
        const uint16_t tmp = t.hash[i];
        t.hash[i] = t.hash[j];
        t.hash[j] = tmp;
    }
    for (int i = 0; i < 4096; ++i) t.hash[4096 + i] = t.hash[i];
    for (int i = 0; i < 267; ++i) {
        t.r[2 * i] = noise_detail::kRTableValues[i];
        t.r[2 * i + 1] = noise_detail::kRTableValues[i] * 0.5;
    }
    return t;
}

// Built by the compiler: constant data, nothing to initialise at run time, no guard on the
// hot path, the same for every thread.
constexpr NoiseTables kTables = buildTables();

const NoiseTables& tables() {
    return kTables;
}

// (int)v as x86-64 converts it: truncation, and INT_MIN when out of range (the C++ cast
// would be undefined there).
int truncateToInt(double v) {
    if (!(v > -2147483649.0 && v < 2147483648.0)) return std::numeric_limits<int>::min();
    return static_cast<int>(v);
}

struct LatticeAxis {
    int index;    // 0..4095
    double low;   // offset from the lower lattice plane
    double high;  // offset from the upper one (low - 1)
    double s;     // smoothstep weight of the upper plane
};

[[gnu::always_inline]] inline LatticeAxis latticeAxis(double x) {
    const int t = x >= 0 ? truncateToInt(x) : truncateToInt(x - (1 - kEpsilon));
    LatticeAxis a;
    a.index = static_cast<int>((static_cast<unsigned>(t) - static_cast<unsigned>(kMinCoordinate)) &
                               0xFFF);
    a.low = x - t;
    a.high = a.low - 1;
    a.s = a.low * a.low * (3.0 - 2.0 * a.low);
    return a;
}

// The 8 corners' weights and table offsets, shared by noise and dnoise.
struct Cell {
    LatticeAxis x, y, z;
    double txty, sxty, txsy, sxsy, tz, sz;
    int ixiy, jxiy, ixjy, jxjy;  // Hash2d of the four (x, y) corners
};

[[gnu::always_inline]] inline Cell cellOf(const Vec3& p, const NoiseTables& t) {
    Cell c;
    c.x = latticeAxis(p.x);
    c.y = latticeAxis(p.y);
    c.z = latticeAxis(p.z);
    const double tx = 1 - c.x.s, ty = 1 - c.y.s;
    c.tz = 1 - c.z.s;
    c.sz = c.z.s;
    c.txty = tx * ty;
    c.sxty = c.x.s * ty;
    c.txsy = tx * c.y.s;
    c.sxsy = c.x.s * c.y.s;
    const int ix = c.x.index, iy = c.y.index;
    c.ixiy = t.hash[t.hash[ix] ^ iy];
    c.jxiy = t.hash[t.hash[ix + 1] ^ iy];
    c.ixjy = t.hash[t.hash[ix] ^ (iy + 1)];
    c.jxjy = t.hash[t.hash[ix + 1] ^ (iy + 1)];
    return c;
}

// POV-Ray's INCRSUMP: s * (m[1] + m[2] x + m[4] y + m[6] z), summed in that order.
double corner(const double* m, double s, double x, double y, double z) {
    return s * (m[1] + m[2] * x + m[4] * y + m[6] * z);
}

const double* tableAt(const NoiseTables& t, int hash2d, int iz) {
    return &t.r[(t.hash[hash2d ^ iz] & 0xFF) * 2];
}

}  // namespace

std::span<const uint16_t, 8192> noise_detail::hashTable() {
    return std::span<const uint16_t, 8192>(kTables.hash);
}

double noise(const Vec3& p) {
    const NoiseTables& t = tables();
    const Cell c = cellOf(p, t);
    const int iz = c.z.index;
    const double xl = c.x.low, xh = c.x.high, yl = c.y.low, yh = c.y.high;
    const double zl = c.z.low, zh = c.z.high;
    double sum = corner(tableAt(t, c.ixiy, iz), c.txty * c.tz, xl, yl, zl);
    sum += corner(tableAt(t, c.jxiy, iz), c.sxty * c.tz, xh, yl, zl);
    sum += corner(tableAt(t, c.ixjy, iz), c.txsy * c.tz, xl, yh, zl);
    sum += corner(tableAt(t, c.jxjy, iz), c.sxsy * c.tz, xh, yh, zl);
    sum += corner(tableAt(t, c.ixiy, iz + 1), c.txty * c.sz, xl, yl, zh);
    sum += corner(tableAt(t, c.jxiy, iz + 1), c.sxty * c.sz, xh, yl, zh);
    sum += corner(tableAt(t, c.ixjy, iz + 1), c.txsy * c.sz, xl, yh, zh);
    sum += corner(tableAt(t, c.jxjy, iz + 1), c.sxsy * c.sz, xh, yh, zh);
    // noise_generator 2: POV-Ray's range correction of [-1.05242, 0.988997] to [0, 1].
    sum += 1.05242;
    sum *= 0.48985582;
    if (sum < 0.0) sum = 0.0;
    if (sum > 1.0) sum = 1.0;
    return sum;
}

namespace {

// One corner's contribution to the three components (tables 8 entries apart).
void addCorner(Vec3& r, const double* m, double s, double x, double y, double z, bool first) {
    const double cx = corner(m, s, x, y, z);
    const double cy = corner(m + 8, s, x, y, z);
    const double cz = corner(m + 16, s, x, y, z);
    if (first) {
        r = Vec3{cx, cy, cz};
    } else {
        r.x += cx;
        r.y += cy;
        r.z += cz;
    }
}

}  // namespace

Vec3 dnoise(const Vec3& p) {
    const NoiseTables& t = tables();
    const Cell c = cellOf(p, t);
    const int iz = c.z.index;
    const double xl = c.x.low, xh = c.x.high, yl = c.y.low, yh = c.y.high;
    const double zl = c.z.low, zh = c.z.high;
    Vec3 r;
    // POV-Ray's DNoise visits the corners in this order (not Noise's).
    addCorner(r, tableAt(t, c.ixiy, iz), c.txty * c.tz, xl, yl, zl, true);
    addCorner(r, tableAt(t, c.jxiy, iz), c.sxty * c.tz, xh, yl, zl, false);
    addCorner(r, tableAt(t, c.jxjy, iz), c.sxsy * c.tz, xh, yh, zl, false);
    addCorner(r, tableAt(t, c.ixjy, iz), c.txsy * c.tz, xl, yh, zl, false);
    addCorner(r, tableAt(t, c.ixjy, iz + 1), c.txsy * c.sz, xl, yh, zh, false);
    addCorner(r, tableAt(t, c.jxjy, iz + 1), c.sxsy * c.sz, xh, yh, zh, false);
    addCorner(r, tableAt(t, c.jxiy, iz + 1), c.sxty * c.sz, xh, yl, zh, false);
    addCorner(r, tableAt(t, c.ixiy, iz + 1), c.txty * c.sz, xl, yl, zh, false);
    return r;
}

double turbulence(const Vec3& p, const Turbulence& turb) {
    double value = 2.0 * noise(p) - 0.5;
    value = value < 0.0 ? 0.0 : (value > 1.0 ? 1.0 : value);
    double l = turb.lambda, o = turb.omega;
    for (int i = 2; i <= turb.octaves; ++i) {
        value += o * (2.0 * noise(p * l) - 0.5);
        if (i < turb.octaves) {
            l *= turb.lambda;
            o *= turb.omega;
        }
    }
    return value;
}

Vec3 dturbulence(const Vec3& p, const Turbulence& turb) {
    Vec3 result = dnoise(p);
    double l = turb.lambda, o = turb.omega;
    for (int i = 2; i <= turb.octaves; ++i) {
        result += dnoise(p * l) * o;
        if (i < turb.octaves) {
            l *= turb.lambda;
            o *= turb.omega;
        }
    }
    return result;
}

const NoiseWaves& noiseWaves() {
    static const NoiseWaves w = [] {
        NoiseWaves waves;
        uint32_t r = static_cast<uint32_t>(-560851967);
        for (int i = 0; i < NoiseWaves::kCount; ++i) {
            const Vec3 d = dnoise(Vec3{static_cast<double>(i), 0.0, 0.0});
            const double len = std::sqrt(dot(d, d));
            waves.source[i] = d / len;  // Vector3d::normalized() divides
            r = nextRandom(r);
            waves.frequency[i] = randomDraw(r) * 0.000030518509476 + 0.01;
        }
        return waves;
    }();
    return w;
}

}  // namespace pcsg
