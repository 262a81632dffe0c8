// The PNG files of a frame sequence (`pcsg render --frames N`), each encoded on a thread of
// its own while the next frame renders: libpng and zlib took one thread some 120 M
// instructions a 640x480 frame (30 ms; 20 to 40 M since the rows are written unfiltered,
// png_writer.cpp), during which the render's other threads used to wait. The pixels are
// turned into 8-bit sRGB values (png_writer.h's srgbBytes, in parallel) before the
// hand-over, so what waits is 0.9 MB of bytes, not the 3.7 MB of floats; and one file at a
// time is written: the next is handed over only once the last is done. The files are byte
// for byte those writePng() writes.
#pragma once

#include <cstdint>
#include <future>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace pcsg::tools {

class FrameWriter {
  public:
    // How a write ended: the error message (empty: written) and the seconds it took
    // (the conversion to bytes and the encoding).
    struct Written {
        std::string error;
        double seconds = 0;
    };

    // `threads`: how many convert the pixels (the render's --threads; 0: all cores).
    explicit FrameWriter(int threads = 0) : threads_(threads) {}
    ~FrameWriter();  // waits for the write in progress
    FrameWriter(const FrameWriter&) = delete;
    FrameWriter& operator=(const FrameWriter&) = delete;

    // Starts writing the linear RGB pixels to `path` as a PNG and returns at once, the
    // pixels converted (so `rgb` may go). The last write must have been collected
    // (done()); a logic error otherwise.
    void start(const std::string& path, int width, int height, std::span<const float> rgb);
    // Whether a write was started and not yet collected.
    bool busy() const { return pending_.valid(); }
    // Waits for the write in progress and returns how it ended; nothing when none was.
    std::optional<Written> done();

  private:
    int threads_;
    std::future<Written> pending_;
};

}  // namespace pcsg::tools
