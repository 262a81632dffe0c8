// Comparing two renderings of one scene (pcsg verify): both images are decoded to
// linear floats, reduced by the same K×K box filter through OpenImageIO, and compared
// in sRGB-encoded values, which is what a person sees.
#pragma once

#include <string>

#include <OpenImageIO/imagebuf.h>

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
    double psnr = 0;        // dB; infinite for identical images
    double maxError = 0;    // the largest channel difference
    int maxX = 0, maxY = 0; // where it is
    double shareOff = 0;    // share of pixels with a channel off by more than pixelOff
    bool agree = false;
};

// Reads an image file into linear float RGB (PNG and other 8/16-bit files are taken as
// sRGB-encoded, EXR as linear). Returns false with a message on failure.
bool readLinear(const std::string& path, OIIO::ImageBuf& out, std::string& error);

// Averages each K×K block of linear values into one pixel (OpenImageIO's box filter).
OIIO::ImageBuf boxReduce(const OIIO::ImageBuf& linear, int k);

// Compares two linear images of the same size in sRGB-encoded values.
ImageMetrics compareImages(const OIIO::ImageBuf& a, const OIIO::ImageBuf& b, const Thresholds& t);

// A heat map of the per-pixel largest channel difference (black = equal, through red
// and yellow to white = 1), in sRGB, for the report.
OIIO::ImageBuf diffHeatMap(const OIIO::ImageBuf& a, const OIIO::ImageBuf& b);

// Writes linear floats as an sRGB-encoded 8-bit PNG.
bool writeSrgbPng(const OIIO::ImageBuf& linear, const std::string& path, std::string& error);

}  // namespace pcsg::tools
