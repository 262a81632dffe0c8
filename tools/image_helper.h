// Image files through the pcsg-image helper (tools/pcsg_image.cpp). pcsg itself does not
// link OpenImageIO, whose ~260 shared libraries would cost every process ~130 MB of peak
// RSS and half a second of start-up: `pcsg render` pipes its linear float pixels to
// `pcsg-image write`, and `pcsg verify` runs `pcsg-image compare`.
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
    // Wall time from the first byte of the pixels to the helper's exit: what the caller
    // waited for once it had the pixels (the piping, the encoding, and whatever of the
    // helper's start-up was still going on).
    double seconds = 0;
    double helperSeconds = 0;  // the helper's whole wall time, from its start
};

// `pcsg-image write PATH WIDTH HEIGHT`, started before the pixels exist so that its
// start-up (loading OpenImageIO's shared libraries, about half a second) overlaps the
// work that makes them; it then waits on its standard input. Either finish() gives it
// the pixels, or abandon() (or the destructor) stops it.
class ImageWriter {
  public:
    ImageWriter(const std::string& helper, const std::string& path, int width, int height);

    // Pipes the pixels (linear RGB floats, row-major from the top-left) to the helper and
    // waits for it to write the file.
    ImageWriteResult finish(std::span<const float> rgb);

    // No image after all: the helper, which cannot have written anything without its
    // input, is killed and reaped, and what it said is dropped (so its complaint about a
    // truncated input never reaches the user).
    void abandon();

  private:
    AsyncChild child_;
};

// `pcsg-image write PATH WIDTH HEIGHT` with the pixels (linear RGB floats, row-major from
// the top-left) on its standard input: ImageWriter's start and finish() at once.
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
