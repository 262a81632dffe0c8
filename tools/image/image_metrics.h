// The result of comparing two images, without OpenImageIO: `pcsg-image compare` computes
// it (tools/image/image_compare.h) and prints it as JSON; `pcsg verify` reads it back.
#pragma once

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>

namespace pcsg::tools {

// How far apart two images may be and still "agree". Edge pixels differ between any two
// renderers (a sub-pixel difference in where a ray hits an edge), so agreement allows a
// small share of pixels to be off and bounds the mean error; a wrong material, light or
// transform moves many pixels far and fails both.
struct Thresholds {
    double pixelOff = 0.1;       // a pixel is "off" when a channel differs by more than this
    double maxShareOff = 0.01;   // at most this share of the pixels may be off
    double maxMeanError = 0.01;  // mean absolute error over all channels
};

struct ImageMetrics {
    int width = 0, height = 0;
    double meanAbsError = 0;
    double rmse = 0;
    double psnr = 0;         // dB; infinite for identical images
    double maxError = 0;     // the largest channel difference
    int maxX = 0, maxY = 0;  // where it is
    double shareOff = 0;     // share of pixels with a channel off by more than pixelOff
    bool agree = false;
};

// JSON has no infinity: an infinite PSNR is the string "inf".
inline nlohmann::json metricsToJson(const ImageMetrics& m) {
    return {{"width", m.width},
            {"height", m.height},
            {"mean_abs_error", m.meanAbsError},
            {"rmse", m.rmse},
            {"psnr", std::isfinite(m.psnr) ? nlohmann::json(m.psnr) : nlohmann::json("inf")},
            {"max_error", m.maxError},
            {"max_x", m.maxX},
            {"max_y", m.maxY},
            {"share_off", m.shareOff},
            {"agree", m.agree}};
}

// The metrics in a JSON object written by metricsToJson; nullopt when a field is missing.
inline std::optional<ImageMetrics> metricsFromJson(const nlohmann::json& j) {
    try {
        ImageMetrics m;
        m.width = j.at("width").get<int>();
        m.height = j.at("height").get<int>();
        m.meanAbsError = j.at("mean_abs_error").get<double>();
        m.rmse = j.at("rmse").get<double>();
        const auto& psnr = j.at("psnr");
        m.psnr = psnr.is_number() ? psnr.get<double>() : std::numeric_limits<double>::infinity();
        m.maxError = j.at("max_error").get<double>();
        m.maxX = j.at("max_x").get<int>();
        m.maxY = j.at("max_y").get<int>();
        m.shareOff = j.at("share_off").get<double>();
        m.agree = j.at("agree").get<bool>();
        return m;
    } catch (const nlohmann::json::exception&) {
        return std::nullopt;
    }
}

}  // namespace pcsg::tools
