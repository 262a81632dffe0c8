// A sequence's PNG files, written beside the render: see frame_writer.h.
#include "frame_writer.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <utility>

#include "png_writer.h"
#include "thread_pool.h"

namespace pcsg::tools {

namespace {

// srgbBytes in parallel, in chunks of 16K values: between two frames the render's threads
// would wait for it (25 M instructions a 640x480 frame on one thread).
std::vector<uint8_t> parallelSrgbBytes(std::span<const float> rgb, int threads) {
    constexpr size_t kChunk = 16384;
    std::vector<uint8_t> bytes(rgb.size());
    const tracer::ParallelLimits limits(threads, 0);  // the render's pool, whatever its stacks
    tracer::parallelFor((rgb.size() + kChunk - 1) / kChunk, [&](size_t chunk, int) {
        const size_t begin = chunk * kChunk, n = std::min(kChunk, rgb.size() - begin);
        srgbBytesInto(rgb.subspan(begin, n), std::span(bytes).subspan(begin, n));
    });
    return bytes;
}

}  // namespace

FrameWriter::~FrameWriter() {
    if (pending_.valid()) pending_.wait();
}

void FrameWriter::start(const std::string& path, int width, int height,
                        std::span<const float> rgb) {
    if (pending_.valid()) throw std::logic_error("FrameWriter: the last write was not collected");
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<uint8_t> bytes = parallelSrgbBytes(rgb, threads_);
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
