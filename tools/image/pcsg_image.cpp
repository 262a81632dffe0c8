// pcsg-image: pcsg's image files, through OpenImageIO, in a process of their own.
//
//   pcsg-image write OUT WIDTH HEIGHT     < WIDTH*HEIGHT*3 float32 linear RGB values
//   pcsg-image compare A B [--ss K] [--heatmap FILE] [--reduced-a FILE] [--reduced-b FILE]
//                          [--pixel-threshold T] [--max-off S] [--max-mean-error E]
//
// OpenImageIO pulls in ~260 shared libraries, which cost a process ~130 MB of peak RSS and
// half a second of start-up; `pcsg` does not link it, so that renders and tests stay
// small, and runs this helper, to its end, only where OpenImageIO is needed
// (tools/image/image_helper.h): `pcsg render` pipes an EXR's or TIFF's pixels to `write`
// (a PNG it writes itself, through the same libpng writer `write` uses for .png), and
// `pcsg verify` runs `compare`. See `pcsg-image --help`.
//
// Exit status: write: 0 written, 2 not (nothing is left behind); compare: 0 the images
// agree, 1 they differ, 2 the comparison could not run.
#include <fmt/format.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <memory>
#include <new>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "image_compare.h"
#include "image_io.h"

namespace pcsg::tools {

namespace {

struct WriteOptions {
    std::string output;
    int width = 0, height = 0;
};

// Reads up to `size` bytes from standard input; returns how many it got (fewer only at
// the end of the input). Throws std::runtime_error on a read error.
size_t readInput(std::byte* data, size_t size) {
    size_t got = 0;
    while (got < size) {
        const ssize_t n = read(STDIN_FILENO, data + got, size - got);
        if (n > 0) {
            got += static_cast<size_t>(n);
        } else if (n == 0) {
            break;
        } else if (errno != EINTR) {
            throw std::runtime_error(
                fmt::format("cannot read standard input: {}", std::strerror(errno)));
        }
    }
    return got;
}

int runWrite(const WriteOptions& o) {
    auto fail = [&](const std::string& why) {
        std::cerr << fmt::format("pcsg-image write: cannot write '{}': {}\n", o.output, why);
        return 2;
    };
    if (!imageFormatOf(o.output))
        return fail(fmt::format("unknown image type '{}' ({})",
                                std::filesystem::path(o.output).extension().string(),
                                kImageTypesHint));
    // 2^16 on a side is far beyond any render; it keeps width * height * 12 from overflowing.
    constexpr int kMaxSide = 1 << 16;
    if (o.width <= 0 || o.height <= 0 || o.width > kMaxSide || o.height > kMaxSide)
        return fail(fmt::format("the image size {}x{} must be between 1 and {} on each side",
                                o.width, o.height, kMaxSide));
    if (isatty(STDIN_FILENO))
        return fail(
            "standard input is a terminal: pipe the pixels in (WIDTH*HEIGHT*3 float32 values)");
    const size_t values = static_cast<size_t>(o.width) * static_cast<size_t>(o.height) * 3;
    const size_t bytes = values * sizeof(float);
    try {
        std::vector<float> rgb(values);
        const size_t got = readInput(reinterpret_cast<std::byte*>(rgb.data()), bytes);
        if (got < bytes)
            return fail(fmt::format(
                "standard input ended after {} of {} bytes ({}x{}x3 float32 values expected)", got,
                bytes, o.width, o.height));
        std::byte extra;
        if (readInput(&extra, 1) != 0)
            return fail(fmt::format(
                "standard input holds more than the {} bytes of a {}x{} image (wrong size?)", bytes,
                o.width, o.height));
        writeImage(o.output, o.width, o.height, rgb);
    } catch (const std::bad_alloc&) {
        return fail(fmt::format("not enough memory for a {}x{} image", o.width, o.height));
    } catch (const std::runtime_error& e) {
        // writeImage's messages already name the file.
        const std::string what = e.what();
        if (what.rfind("cannot write", 0) == 0) {
            std::cerr << "pcsg-image write: " << what << "\n";
            return 2;
        }
        return fail(what);
    }
    return 0;
}

struct CompareOptions {
    std::string a, b;
    int ss = 1;
    Thresholds thresholds;
    std::string heatMap, reducedA, reducedB;
};

int runCompare(const CompareOptions& o) {
    auto fail = [](const std::string& why) {
        std::cerr << "pcsg-image compare: " << why << "\n";
        return 2;
    };
    if (o.ss < 1) return fail("--ss must be at least 1");
    OIIO::ImageBuf a, b;
    std::string error;
    if (!readLinear(o.a, a, error) || !readLinear(o.b, b, error)) return fail(error);
    const OIIO::ImageSpec &sa = a.spec(), &sb = b.spec();
    nlohmann::json j = {{"a", {{"path", o.a}, {"width", sa.width}, {"height", sa.height}}},
                        {"b", {{"path", o.b}, {"width", sb.width}, {"height", sb.height}}},
                        {"ss", o.ss}};
    // The sizes go to standard output even when they differ: the caller may say more.
    auto failWithJson = [&](const std::string& why) {
        j["error"] = why;
        std::cout << j.dump(2) << "\n";
        return fail(why);
    };
    if (sa.width != sb.width || sa.height != sb.height)
        return failWithJson(fmt::format("the image sizes differ: {} is {}x{}, {} is {}x{}", o.a,
                                        sa.width, sa.height, o.b, sb.width, sb.height));
    if (sa.width < o.ss || sa.height < o.ss)
        return failWithJson(fmt::format("a {}x{} image is smaller than one {}x{} block", sa.width,
                                        sa.height, o.ss, o.ss));
    const OIIO::ImageBuf ra = boxReduce(a, o.ss), rb = boxReduce(b, o.ss);
    const ImageMetrics m = compareImages(ra, rb, o.thresholds);
    if ((!o.reducedA.empty() && !writeSrgbPng(ra, o.reducedA, error)) ||
        (!o.reducedB.empty() && !writeSrgbPng(rb, o.reducedB, error)) ||
        (!o.heatMap.empty() && !writeSrgbPng(diffHeatMap(ra, rb), o.heatMap, error)))
        return failWithJson(error);
    j.update(metricsToJson(m));
    std::cout << j.dump(2) << "\n";
    return m.agree ? 0 : 1;
}

}  // namespace

}  // namespace pcsg::tools

int main(int argc, char** argv) {
    using namespace pcsg::tools;
    CLI::App app{
        "pcsg-image: the image files of pcsg, through OpenImageIO, in a process of their own.\n"
        "pcsg does not link OpenImageIO (its shared libraries cost every process ~130 MB of\n"
        "memory), so that the renderer stays small: `pcsg render` writes a PNG itself, pipes\n"
        "an EXR's or TIFF's pixels to `pcsg-image write`, and `pcsg verify` runs\n"
        "`pcsg-image compare`. It is found beside the pcsg executable, or in PATH.",
        "pcsg-image"};
    app.require_subcommand(1);
    int status = 0;

    auto w = std::make_shared<WriteOptions>();
    auto* write = app.add_subcommand(
        "write",
        "Read WIDTH*HEIGHT*3 linear RGB values (float32 in the machine's byte order, row-major\n"
        "from the top-left pixel) from standard input and write them to OUT by its extension:\n"
        ".png 8-bit sRGB, .tif or .tiff 16-bit sRGB, .exr linear 32-bit float. The image is\n"
        "written to a temporary file beside OUT and renamed, so a failure (too little or too\n"
        "much input, an unwritable directory) leaves nothing behind.\n"
        "Exit status: 0 written, 2 not.");
    write->add_option("output", w->output, "The image file: .png, .tif, .tiff or .exr")->required();
    write->add_option("width", w->width, "Width in pixels")->required();
    write->add_option("height", w->height, "Height in pixels")->required();
    write->callback([w, &status] { status = runWrite(*w); });

    auto c = std::make_shared<CompareOptions>();
    auto* compare = app.add_subcommand(
        "compare",
        "Compare two images of the same size (what pcsg verify does with the native and the\n"
        "POV-Ray rendering): both are decoded to linear values (8- and 16-bit files as sRGB),\n"
        "reduced by the same KxK box filter, and compared in sRGB-encoded values. Prints the\n"
        "sizes and the metrics as JSON (mean absolute error, RMSE, PSNR, the largest\n"
        "difference and where it is, the share of pixels off, whether they agree).\n"
        "Exit status: 0 the images agree, 1 they differ, 2 the comparison could not run.");
    compare->add_option("a", c->a, "The first image")->required();
    compare->add_option("b", c->b, "The second image")->required();
    compare->add_option("--ss", c->ss, "Reduce both by KxK box filters first")
        ->capture_default_str();
    compare->add_option("--heatmap", c->heatMap,
                        "Write a heat map of the differences (8-bit sRGB PNG) here");
    compare->add_option("--reduced-a", c->reducedA, "Write the reduced first image (PNG) here");
    compare->add_option("--reduced-b", c->reducedB, "Write the reduced second image (PNG) here");
    compare
        ->add_option("--pixel-threshold", c->thresholds.pixelOff,
                     "A pixel is off when a channel differs by more than this (0..1)")
        ->capture_default_str();
    compare
        ->add_option("--max-off", c->thresholds.maxShareOff,
                     "Agree only if at most this share of pixels is off")
        ->capture_default_str();
    compare
        ->add_option("--max-mean-error", c->thresholds.maxMeanError,
                     "Agree only if the mean absolute error is at most this")
        ->capture_default_str();
    compare->callback([c, &status] { status = runCompare(*c); });

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e) == 0 ? 0 : 2;
    }
    return status;
}
