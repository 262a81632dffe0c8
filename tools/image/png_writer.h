// Writing rendered pixels as an 8-bit sRGB PNG through libpng, in the rendering process:
// libpng and zlib cost it well under a megabyte, where OpenImageIO's ~260 shared libraries
// would cost ~130 MB. EXR and TIFF files are pcsg-image's (tools/image/image_helper.h).
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
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

// A PNG written a row at a time, top to bottom, from the 8-bit sRGB values srgbBytes()
// gives: the file writePngBytes() writes, without the image held whole. Written to a
// temporary file beside the target and renamed by finish(); a writer destroyed before
// that (or failed) removes it. Each step throws std::runtime_error "cannot write 'PATH':
// why"; after one, the file is gone and every later step throws.
class PngRowWriter {
  public:
    PngRowWriter(const std::string& path, int width, int height);
    ~PngRowWriter();
    PngRowWriter(const PngRowWriter&) = delete;
    PngRowWriter& operator=(const PngRowWriter&) = delete;

    void write(std::span<const uint8_t> row);  // the next row's width * 3 values
    void finish();                             // after the last row

  private:
    struct State;
    std::unique_ptr<State> state_;
};

// A PNG of rows of linear RGB floats handed over in any order and from any thread (a
// render's RowSink, as its rows are finished): each row is turned into its 8-bit sRGB
// values where it is handed over, and written once the rows above it are; until then it
// waits, as bytes (a render's rows come in bands of 16, so a few rows wait at most).
class PngRows {
  public:
    PngRows(const std::string& path, int width, int height) : png_(path, width, height) {}
    // Row y's width * 3 floats.
    void put(int y, std::span<const float> rgb);
    // After every row was put: ends the file and renames it to the target.
    void finish() { png_.finish(); }

  private:
    std::mutex mutex_;
    PngRowWriter png_;
    int next_ = 0;  // the next row to write
    std::map<int, std::vector<uint8_t>> waiting_;
};

}  // namespace pcsg::tools
