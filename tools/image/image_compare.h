// Comparing two renderings of one scene (`pcsg-image compare`, run by pcsg verify): both
// images are decoded to linear floats, reduced by the same K×K box filter through
// OpenImageIO, and compared in sRGB-encoded values, which is what a person sees. Part of
// the pcsg_image library (with tools/image/image_io.h), the only code that links OpenImageIO.
#pragma once

#include <OpenImageIO/imagebuf.h>

#include <string>

#include "image_metrics.h"

namespace pcsg::tools {

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
