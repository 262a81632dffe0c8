// The SVG of pcsg bench --plot (bench_plot.h): time and peak memory against the
// Sierpinski order, one panel each, log-scaled, drawn by hand as SVG text.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <functional>

#include "bench_plot.h"
#include "stats.h"

namespace pcsg::tools {

namespace {

constexpr const char* kNames[3] = {"pcsg (cyclic graph)", "POV-Ray (exported tree)",
                                   "Embree (expanded mesh)"};
constexpr const char* kColours[3] = {"#d95f02", "#1b9e77", "#7570b3"};
constexpr double kPanelW = 380, kPanelH = 260, kLeft = 70, kTop = 40, kGap = 110;

// A panel's axes: orders along x, decades of the values along y.
struct Axes {
    double x0, y0;  // the plot area's top-left corner
    int fromOrder, toOrder;
    double loDecade, hiDecade;  // log10 of the y range
    double x(int order) const {
        return x0 + kPanelW * (order - fromOrder) / std::max(toOrder - fromOrder, 1);
    }
    double y(double v) const {
        return y0 + kPanelH * (hiDecade - std::log10(v)) / (hiDecade - loDecade);
    }
};

using Value = std::function<std::optional<double>(const ScalingPoint&, int renderer)>;

Axes axesFor(const std::vector<ScalingPoint>& points, const Value& value, double x0) {
    double lo = INFINITY, hi = -INFINITY;
    for (const ScalingPoint& p : points)
        for (int r = 0; r < 3; ++r)
            if (const auto v = value(p, r); v && *v > 0) {
                lo = std::min(lo, std::log10(*v));
                hi = std::max(hi, std::log10(*v));
            }
    if (!(lo <= hi)) lo = 0, hi = 1;
    const int from = points.empty() ? 0 : points.front().order;
    const int to = points.empty() ? 1 : points.back().order;
    return Axes{x0, kTop, from, to, std::floor(lo), std::max(std::ceil(hi), std::floor(lo) + 1)};
}

// The frame, the order ticks and the decade ticks with their labels.
std::string axesSvg(const Axes& a, const std::string& title,
                    const std::function<std::string(double)>& label) {
    std::string s = fmt::format(
        "<rect x='{}' y='{}' width='{}' height='{}' fill='none' stroke='#444'/>\n"
        "<text x='{}' y='{}' text-anchor='middle' font-weight='bold'>{}</text>\n"
        "<text x='{}' y='{}' text-anchor='middle'>Sierpinski order</text>\n",
        a.x0, a.y0, kPanelW, kPanelH, a.x0 + kPanelW / 2, a.y0 - 14, title, a.x0 + kPanelW / 2,
        a.y0 + kPanelH + 36);
    for (int k = a.fromOrder; k <= a.toOrder; ++k)
        s += fmt::format(
            "<line x1='{0:.1f}' y1='{1}' x2='{0:.1f}' y2='{2}' stroke='#444'/>"
            "<text x='{0:.1f}' y='{3}' text-anchor='middle'>{4}</text>\n",
            a.x(k), a.y0 + kPanelH, a.y0 + kPanelH + 5, a.y0 + kPanelH + 18, k);
    for (double d = a.loDecade; d <= a.hiDecade + 1e-9; d += 1) {
        const double y = a.y(std::pow(10.0, d));
        s += fmt::format(
            "<line x1='{0}' y1='{1:.1f}' x2='{2}' y2='{1:.1f}' stroke='#ddd'/>"
            "<text x='{3}' y='{4:.1f}' text-anchor='end'>{5}</text>\n",
            a.x0, y, a.x0 + kPanelW, a.x0 - 6, y + 4, label(std::pow(10.0, d)));
    }
    return s;
}

// One renderer's line and markers over the orders it ran.
std::string seriesSvg(const std::vector<ScalingPoint>& points, const Axes& a, const Value& value,
                      int r) {
    std::string path, marks;
    for (const ScalingPoint& p : points) {
        const auto v = value(p, r);
        if (!v || *v <= 0) continue;
        path += fmt::format("{}{:.1f},{:.1f}", path.empty() ? "M" : " L", a.x(p.order), a.y(*v));
        marks += fmt::format("<circle cx='{:.1f}' cy='{:.1f}' r='3.5' fill='{}'/>", a.x(p.order),
                             a.y(*v), kColours[r]);
    }
    if (path.empty()) return {};
    return fmt::format("<path d='{}' fill='none' stroke='{}' stroke-width='2'/>\n{}\n", path,
                       kColours[r], marks);
}

std::string panelSvg(const std::vector<ScalingPoint>& points, const Value& value, double x0,
                     const std::string& title, const std::function<std::string(double)>& label) {
    const Axes a = axesFor(points, value, x0);
    std::string s = axesSvg(a, title, label);
    for (int r = 0; r < 3; ++r) s += seriesSvg(points, a, value, r);
    return s;
}

std::string xmlText(const std::string& text) {
    std::string s;
    for (char c : text) {
        if (c == '&')
            s += "&amp;";
        else if (c == '<')
            s += "&lt;";
        else if (c == '>')
            s += "&gt;";
        else
            s += c;
    }
    return s;
}

std::string secondsLabel(double v) {
    return v >= 1 ? fmt::format("{:g} s", v) : fmt::format("{:g} ms", v * 1000);
}

}  // namespace

std::string scalingSvg(const std::vector<ScalingPoint>& points, const std::string& caption) {
    const double width = kLeft + 2 * kPanelW + kGap + 30, height = kTop + kPanelH + 110;
    std::string s = fmt::format(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{0}' height='{1}' viewBox='0 0 {0} {1}' "
        "font-family='sans-serif' font-size='12'>\n<rect width='100%' height='100%' "
        "fill='white'/>\n",
        width, height);
    const Value seconds = [](const ScalingPoint& p, int r) { return p.seconds[r]; };
    const Value memory = [](const ScalingPoint& p, int r) -> std::optional<double> {
        if (!p.rss[r]) return std::nullopt;
        return double(*p.rss[r]);
    };
    s += panelSvg(points, seconds, kLeft, "render time (whole command)", secondsLabel);
    s += panelSvg(points, memory, kLeft + kPanelW + kGap, "peak RSS (whole command)",
                  [](double v) { return humanBytes(uint64_t(std::llround(v))); });
    const double legendY = kTop + kPanelH + 62;
    for (int r = 0; r < 3; ++r)
        s += fmt::format(
            "<rect x='{0}' y='{1}' width='14' height='4' fill='{2}'/>"
            "<text x='{3}' y='{4}'>{5}</text>\n",
            kLeft + r * 230, legendY - 4, kColours[r], kLeft + r * 230 + 20, legendY, kNames[r]);
    s += fmt::format("<text x='{}' y='{}' fill='#555'>{}</text>\n</svg>\n", kLeft, legendY + 24,
                     xmlText(caption));
    return s;
}

}  // namespace pcsg::tools
