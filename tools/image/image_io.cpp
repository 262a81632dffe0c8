#include "image_io.h"

#include <OpenImageIO/imageio.h>
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "png_writer.h"

namespace pcsg::tools {

void writeImage(const std::string& path, int width, int height, std::span<const float> rgb) {
    namespace fs = std::filesystem;
    const auto format = imageFormatOf(path);
    if (!format)
        throw std::runtime_error(fmt::format("cannot write '{}': unknown image type '{}' ({})",
                                             path, fs::path(path).extension().string(),
                                             kImageTypesHint));
    if (width <= 0 || height <= 0)
        throw std::runtime_error(fmt::format(
            "cannot write '{}': the image size {}x{} is not positive", path, width, height));
    const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height) * 3;
    if (rgb.size() != n)
        throw std::runtime_error(
            fmt::format("cannot write '{}': {} values for a {}x{} RGB image (expected {})", path,
                        rgb.size(), width, height, n));

    // The one 8-bit sRGB encoder, also pcsg render's own.
    if (*format == ImageFormat::png) return writePng(path, width, height, rgb);
    OIIO::TypeDesc type = OIIO::TypeDesc::FLOAT;
    std::vector<uint16_t> bytes16;
    const void* data = rgb.data();
    if (*format == ImageFormat::tiff) {
        type = OIIO::TypeDesc::UINT16;
        bytes16.resize(n);
        for (size_t i = 0; i < n; ++i)
            bytes16[i] = static_cast<uint16_t>(std::lround(srgbEncode(rgb[i]) * 65535.0));
        data = bytes16.data();
    }

    const fs::path target(path);
    const fs::path tmp = temporaryBeside(target);
    // Every failure removes the temporary file (OpenImageIO may have created it).
    auto fail = [&](const std::string& why) {
        std::error_code ec;
        fs::remove(tmp, ec);
        throw std::runtime_error(fmt::format("cannot write '{}': {}", path, why));
    };
    auto out = OIIO::ImageOutput::create(tmp.string());
    if (!out) fail(OIIO::geterror());
    OIIO::ImageSpec spec(width, height, 3, type);
    spec.attribute("oiio:ColorSpace", *format == ImageFormat::exr ? "Linear" : "sRGB");
    spec.attribute("Software", "pcsg");
    if (!out->open(tmp.string(), spec)) fail(out->geterror());
    const bool written = out->write_image(type, data);
    std::string error = written ? std::string() : out->geterror();
    // close() flushes what the format buffered: it can fail too (a full disk).
    const bool closed = out->close();
    if (written && !closed) error = out->geterror();
    if (!written || !closed) fail(error.empty() ? "the write failed" : error);
    out.reset();
    std::error_code ec;
    fs::rename(tmp, target, ec);
    if (ec) fail(ec.message());
}

}  // namespace pcsg::tools
