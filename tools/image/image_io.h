// Writing rendered pixels to an image file: EXR and TIFF through OpenImageIO, PNG through
// libpng (tools/image/png_writer.h). Part of the pcsg_image library, which only the
// pcsg-image helper and the image tests link: `pcsg render` writes a PNG itself and pipes
// an EXR's or TIFF's pixels to `pcsg-image write`, so that a PNG render never pays for
// OpenImageIO's ~260 shared libraries (~130 MB of peak RSS, half a second of start-up).
#pragma once

#include <cstddef>
#include <span>
#include <string>

#include "image_format.h"

namespace pcsg::tools {

// Writes linear RGB pixels (row-major from the top-left, width * height * 3 floats) by
// the file name's extension: .png 8-bit sRGB, .tif/.tiff 16-bit sRGB, .exr linear 32-bit
// float. Writes to a temporary file beside the target and renames it, so a failed write
// never leaves a partial image (nor the temporary file). Throws std::runtime_error with a
// message that names the path.
void writeImage(const std::string& path, int width, int height, std::span<const float> rgb);

}  // namespace pcsg::tools
