// Writing rendered pixels as an 8-bit sRGB PNG through libpng, in the rendering process:
// libpng and zlib cost it well under a megabyte, where OpenImageIO's ~260 shared libraries
// would cost ~130 MB. EXR and TIFF files are pcsg-image's (tools/image/image_helper.h).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace pcsg::tools {

// The 8-bit sRGB values of linear RGB floats: round(srgbEncode(v) * 255) each, the one
// encoding of every 8-bit image pcsg writes.
std::vector<uint8_t> srgbBytes(std::span<const float> rgb);
// The same into `out` (as many values as both hold), for callers that split the image.
void srgbBytesInto(std::span<const float> rgb, std::span<uint8_t> out);

// Writes linear RGB pixels (row-major from the top-left, width * height * 3 floats) as an
// 8-bit sRGB PNG. Writes to a temporary file beside the target and renames it, so a
// failed write never leaves a partial image (nor the temporary file). Throws
// std::runtime_error with a message "cannot write 'PATH': why".
void writePng(const std::string& path, int width, int height, std::span<const float> rgb);

// The same, from the 8-bit sRGB values srgbBytes() gives (width * height * 3 bytes).
void writePngBytes(const std::string& path, int width, int height, std::span<const uint8_t> bytes);

}  // namespace pcsg::tools
