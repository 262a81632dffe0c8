// Frame sequences: see frames.h.
#include "frames.h"

#include <fmt/format.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace pcsg::tools {

double frameClock(const FramePlan& p, int frame) {
    if (p.frames <= 1) return p.clockFrom;
    const int steps = p.cyclic ? p.frames : p.frames - 1;
    // std::lerp: exactly a at the first frame and b at the last, monotone in between.
    return std::lerp(p.clockFrom, p.clockTo, static_cast<double>(frame - 1) / steps);
}

std::string frameFileName(const std::string& output, int frame, int frames) {
    const std::filesystem::path path(output);
    const int width = static_cast<int>(std::to_string(frames).size());
    const std::string name =
        fmt::format("{}{:0{}}{}", path.stem().string(), frame, width, path.extension().string());
    return (path.parent_path() / name).string();
}

bool FrameBoundsChoice::ownBoxes() const {
    switch (mode_) {
        case Mode::On:
            return true;
        case Mode::Off:
            return false;
        case Mode::Auto:
            break;
    }
    return std::min(share_[0], share_[1]) < kShare || sinceOwn_ + 1 >= kRetry;
}

void FrameBoundsChoice::frameDone(bool own, double boundsSeconds, double renderSeconds) {
    if (!own) {
        ++sinceOwn_;
        return;
    }
    sinceOwn_ = 0;
    share_[1] = share_[0];
    share_[0] = renderSeconds > 0 ? boundsSeconds / renderSeconds : kShare;
}

void useOneMallocArena() {
#if defined(__GLIBC__)
    mallopt(M_ARENA_MAX, 1);
#endif
}

std::optional<FrameBoundsChoice::Mode> frameBoundsMode(const std::string& text) {
    if (text == "auto") return FrameBoundsChoice::Mode::Auto;
    if (text == "on") return FrameBoundsChoice::Mode::On;
    if (text == "off") return FrameBoundsChoice::Mode::Off;
    return std::nullopt;
}

namespace {

// The two comma-separated parts of "X,Y", trimmed of nothing: both must be non-empty.
bool splitPair(const std::string& text, std::string& x, std::string& y) {
    const size_t comma = text.find(',');
    if (comma == std::string::npos || text.find(',', comma + 1) != std::string::npos) return false;
    x = text.substr(0, comma);
    y = text.substr(comma + 1);
    return !x.empty() && !y.empty();
}

std::optional<double> finiteNumber(const std::string& s) {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(s.c_str(), &end);
    if (end == s.c_str() || *end != '\0' || !std::isfinite(v)) return std::nullopt;
    return v;
}

}  // namespace

std::optional<std::pair<double, double>> parseClockRange(const std::string& text,
                                                         std::string& error) {
    std::string x, y;
    if (!splitPair(text, x, y)) {
        error = fmt::format("--clock-range takes A,B (two numbers), found '{}'", text);
        return std::nullopt;
    }
    const auto a = finiteNumber(x), b = finiteNumber(y);
    if (!a || !b) {
        error = fmt::format("--clock-range takes two finite numbers, found '{}'", text);
        return std::nullopt;
    }
    if (*b < *a) {
        error = fmt::format(
            "--clock-range {} is reversed: the first clock must not be "
            "larger than the last",
            text);
        return std::nullopt;
    }
    return std::pair{*a, *b};
}

std::optional<std::pair<int, int>> parseSubset(const std::string& text, int frames,
                                               std::string& error) {
    std::string x, y;
    const auto whole = [](const std::string& s) -> std::optional<int> {
        const auto v = finiteNumber(s);
        if (!v || *v != std::floor(*v) || *v < -1e9 || *v > 1e9) return std::nullopt;
        return static_cast<int>(*v);
    };
    std::optional<int> f, l;
    if (splitPair(text, x, y)) f = whole(x), l = whole(y);
    if (!f || !l || *f < 1 || *f > *l || *l > frames) {
        error = fmt::format("--subset takes F,L with 1 <= F <= L <= {} (the frames), found '{}'",
                            frames, text);
        return std::nullopt;
    }
    return std::pair{*f, *l};
}

}  // namespace pcsg::tools
