// What pcsg asks of the pcsg-image helper (tools/image/pcsg_image.cpp), run to its end
// as a process of its own. pcsg itself does not link OpenImageIO, whose ~260 shared
// libraries would cost every process ~130 MB of peak RSS and half a second of start-up:
// `pcsg render` writes a PNG itself (png_writer.h) but pipes an EXR's or TIFF's linear
// float pixels to `pcsg-image write`, and `pcsg verify` runs `pcsg-image compare`.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>

#include "child_process.h"
#include "image_metrics.h"

namespace pcsg::tools {

inline constexpr const char* kImageHelperName = "pcsg-image";

// The helper's path: beside the running executable (where the build and an install put
// it), else the name itself when it is found in PATH; nullopt when it is in neither.
std::optional<std::string> findImageHelper();

// What to say when findImageHelper() found nothing.
std::string missingImageHelperMessage();

struct ImageWriteResult {
    bool ok = false;
    std::string error;          // why not, as the helper said it (one or more lines)
    uint64_t peakRssBytes = 0;  // the helper process's
    double seconds = 0;         // the helper's wall time, start-up included
};

// `pcsg-image write PATH WIDTH HEIGHT` with the pixels (linear RGB floats, row-major from
// the top-left) on its standard input, for an EXR or TIFF file; waits for it to finish.
ImageWriteResult writeImageWithHelper(const std::string& helper, const std::string& path, int width,
                                      int height, std::span<const float> rgb);

struct ImageCompareRun {
    ChildResult child;
    int status = 2;  // 0 the images agree, 1 they differ, 2 the comparison could not run
    std::string error;
    std::optional<ImageMetrics> metrics;
    int widthA = 0, heightA = 0, widthB = 0, heightB = 0;  // before the reduction
};

struct ImageCompareOptions {
    int ss = 1;  // K: both images are reduced by K x K box filters first
    Thresholds thresholds;
    std::string heatMap;             // where to write the heat map (empty: nowhere)
    std::string reducedA, reducedB;  // where to write the reduced images as sRGB PNG
};

// `pcsg-image compare A B --ss K ...`, its JSON read back.
ImageCompareRun compareImagesWithHelper(const std::string& helper, const std::string& a,
                                        const std::string& b, const ImageCompareOptions& options);

}  // namespace pcsg::tools
