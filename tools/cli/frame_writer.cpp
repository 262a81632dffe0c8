// A sequence's PNG files, written beside the render: see frame_writer.h.
#include "frame_writer.h"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "png_writer.h"

namespace pcsg::tools {

FrameWriter::~FrameWriter() {
    if (pending_.valid()) pending_.wait();
}

void FrameWriter::start(const std::string& path, int width, int height,
                        std::span<const float> rgb) {
    if (pending_.valid()) throw std::logic_error("FrameWriter: the last write was not collected");
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<uint8_t> bytes = srgbBytes(rgb);
    const double convert =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    pending_ = std::async(std::launch::async, [path, width, height, convert,
                                               bytes = std::move(bytes)] {
        const auto t1 = std::chrono::steady_clock::now();
        Written w;
        try {
            writePngBytes(path, width, height, bytes);
        } catch (const std::exception& e) {
            w.error = e.what();
        }
        w.seconds =
            convert + std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
        return w;
    });
}

std::optional<FrameWriter::Written> FrameWriter::done() {
    if (!pending_.valid()) return std::nullopt;
    return pending_.get();
}

}  // namespace pcsg::tools
