#include "png_writer.h"

#include <fmt/format.h>
#include <png.h>
#include <unistd.h>

#include <algorithm>
#include <bit>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <stdexcept>

#include "image_format.h"

namespace pcsg::tools {

namespace {

namespace fs = std::filesystem;

constexpr size_t kMessageSize = 256;

// libpng reports an error through its callback, which must not return: this one keeps the
// message (in the error pointer's buffer) and jumps back to the setjmp of the step that
// called libpng.
[[noreturn]] void onPngError(png_structp png, png_const_charp message) {
    char* into = static_cast<char*>(png_get_error_ptr(png));
    std::snprintf(into, kMessageSize, "%s", message);
    png_longjmp(png, 1);
}

void onPngWarning(png_structp, png_const_charp) {}

// libpng's steps, each behind a setjmp of its own (libpng reports an error by a longjmp
// back to it, the message in the error pointer's buffer): false when libpng failed. No C++
// object lives across a setjmp.
bool startPng(png_structp png, png_infop info, FILE* file, int width, int height) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_init_io(png, file);
    png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
                 PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_text software{};
    software.compression = PNG_TEXT_COMPRESSION_NONE;
    software.key = const_cast<png_charp>("Software");
    software.text = const_cast<png_charp>("pcsg");
    png_set_text(png, info, &software, 1);
    // zlib's fastest level: the same pixels in a file about 5% larger (renders compress
    // well), encoded with 30% fewer instructions, on one thread after the render's all.
    // No row filter: libpng's default tries all five on every row and keeps the best, 75 M
    // of the 95 M instructions of a 640x480 frame of the growing tree; unfiltered rows take
    // 20 M, and renders (flat sky, smooth shading) compress as well at this level: the
    // growing tree's frames 3% to 12% smaller, the gallery's stills from 8% smaller to 5%
    // larger (docs/benchmarks.md, issue 14).
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
    png_set_compression_level(png, 1);
    // zlib's hash table and output buffer at memory level 6 instead of 8: the encoder's
    // state, alive for the whole render while rows stream in, takes 160 KB instead of 256 KB
    // (its 32 KB window kept), for files within 1% of the size (the growing tree's 48
    // frames 1.1% smaller, terrain_sea and landsberg 0.5% larger). The 48 frames' peak RSS
    // is a target at 1/10 of POV-Ray's (docs/benchmarks.md).
    png_set_compression_mem_level(png, 6);
    png_write_info(png, info);
    return true;
}

bool writePngRow(png_structp png, const uint8_t* row) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_write_row(png, row);
    return true;
}

bool endPng(png_structp png, png_infop info) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_write_end(png, info);
    return true;
}

}  // namespace

namespace {

uint8_t srgbByte(float linear) {
    return static_cast<uint8_t>(std::lround(srgbEncode(linear) * 255.0));
}

// srgbByte by table: for each byte k > 0 the smallest float in (0, 1) that gives k or
// more, found by bisecting the floats' bit patterns (which order the positive floats) with
// srgbByte itself; a value's byte is then the number of thresholds at or below it, counted
// from the byte at the start of its bucket (the floats with the same top 16 bits), which
// mostly is the answer. The same bytes as srgbByte, which rises with its argument, for 255
// x 30 calls of pow instead of three per pixel.
class SrgbTable {
  public:
    SrgbTable() {
        for (int k = 1; k < 256; ++k) {
            uint32_t lo = 0, hi = kOne;  // srgbByte(1) = 255
            while (lo < hi) {
                const uint32_t mid = lo + (hi - lo) / 2;
                if (srgbByte(std::bit_cast<float>(mid)) >= k)
                    hi = mid;
                else
                    lo = mid + 1;
            }
            threshold_[k - 1] = std::bit_cast<float>(lo);
        }
        for (uint32_t b = 0; b < kBuckets; ++b)
            start_[b] = static_cast<uint8_t>(
                std::upper_bound(threshold_, threshold_ + 255, std::bit_cast<float>(b << 16)) -
                threshold_);
    }
    uint8_t operator()(float linear) const {
        if (!(linear > 0) || linear >= 1) return srgbByte(linear);  // 0 (also NaN) or 255
        uint32_t k = start_[std::bit_cast<uint32_t>(linear) >> 16];
        while (k < 255 && threshold_[k] <= linear) ++k;
        return static_cast<uint8_t>(k);
    }

  private:
    static constexpr uint32_t kOne = 0x3f800000;  // the bits of 1.0f
    static constexpr uint32_t kBuckets = (kOne >> 16) + 1;
    float threshold_[255];
    uint8_t start_[kBuckets];
};

}  // namespace

void srgbBytesInto(std::span<const float> rgb, std::span<uint8_t> out) {
    static const SrgbTable table;
    const size_t n = std::min(rgb.size(), out.size());
    // A value is mostly the one three before it (the same channel of the pixel to the left:
    // the sky, flat faces), whose byte is known: the same float bits, the same byte.
    for (size_t i = 0; i < n; ++i)
        out[i] = i >= 3 && std::bit_cast<uint32_t>(rgb[i]) == std::bit_cast<uint32_t>(rgb[i - 3])
                     ? out[i - 3]
                     : table(rgb[i]);
}

std::vector<uint8_t> srgbBytes(std::span<const float> rgb) {
    std::vector<uint8_t> bytes(rgb.size());
    srgbBytesInto(rgb, bytes);
    return bytes;
}

void writePng(const std::string& path, int width, int height, std::span<const float> rgb) {
    writePngBytes(path, width, height, srgbBytes(rgb));
}

void writePngBytes(const std::string& path, int width, int height, std::span<const uint8_t> bytes) {
    if (width > 0 && height > 0 && bytes.size() != static_cast<size_t>(width) * height * 3)
        throw std::runtime_error(
            fmt::format("cannot write '{}': {} values for a {}x{} RGB image (expected {})", path,
                        bytes.size(), width, height, static_cast<size_t>(width) * height * 3));
    PngRowWriter png(path, width, height);
    const size_t stride = static_cast<size_t>(width) * 3;
    for (int y = 0; y < height; ++y) png.write(bytes.subspan(y * stride, stride));
    png.finish();
}

// The file being written: its temporary name, libpng's state, and whether it is done.
struct PngRowWriter::State {
    std::string path;
    int width = 0, height = 0, rows = 0;
    fs::path tmp;
    FILE* file = nullptr;
    png_structp png = nullptr;
    png_infop info = nullptr;
    char message[kMessageSize] = "";
    bool finished = false;

    ~State() { close(); }
    // Lets go of libpng and the file, and removes the file unless it was finished.
    void close() {
        if (png) png_destroy_write_struct(&png, &info);
        png = nullptr, info = nullptr;
        if (file) std::fclose(file);
        file = nullptr;
        std::error_code ec;
        if (!finished && !tmp.empty()) fs::remove(tmp, ec);
    }
    [[noreturn]] void fail(const std::string& why) {
        close();
        throw std::runtime_error(fmt::format("cannot write '{}': {}", path, why));
    }
};

PngRowWriter::PngRowWriter(const std::string& path, int width, int height)
    : state_(std::make_unique<State>()) {
    State& s = *state_;
    s.path = path, s.width = width, s.height = height;
    if (width <= 0 || height <= 0)
        s.fail(fmt::format("the image size {}x{} is not positive", width, height));
    s.tmp = temporaryBeside(fs::path(path));
    s.file = std::fopen(s.tmp.c_str(), "wb");
    if (!s.file) {
        const std::string why = std::strerror(errno);
        s.tmp.clear();  // (nothing was made)
        s.fail(why);
    }
    s.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, s.message, onPngError, onPngWarning);
    s.info = s.png ? png_create_info_struct(s.png) : nullptr;
    if (!s.info) s.fail("libpng could not start");
    if (!startPng(s.png, s.info, s.file, width, height)) s.fail(s.message);
}

PngRowWriter::~PngRowWriter() = default;

void PngRowWriter::write(std::span<const uint8_t> row) {
    State& s = *state_;
    if (!s.png) s.fail("the file was closed by an earlier error");
    if (row.size() != static_cast<size_t>(s.width) * 3 || s.rows >= s.height)
        s.fail(fmt::format("row {} of {} values for a {}x{} RGB image", s.rows, row.size(), s.width,
                           s.height));
    if (!writePngRow(s.png, row.data())) s.fail(s.message);
    ++s.rows;
}

void PngRowWriter::finish() {
    State& s = *state_;
    if (!s.png) s.fail("the file was closed by an earlier error");
    if (s.rows != s.height) s.fail(fmt::format("{} rows of {} written", s.rows, s.height));
    if (!endPng(s.png, s.info)) s.fail(s.message);
    png_destroy_write_struct(&s.png, &s.info);
    s.png = nullptr, s.info = nullptr;
    // fclose flushes what stdio buffered: it can fail too (a full disk).
    const bool flushed = std::ferror(s.file) == 0;
    const bool closed = std::fclose(s.file) == 0;
    s.file = nullptr;
    if (!flushed || !closed) s.fail(std::strerror(errno));
    std::error_code ec;
    fs::rename(s.tmp, fs::path(s.path), ec);
    if (ec) s.fail(ec.message());
    s.finished = true;
}

void PngRows::put(int y, std::span<const float> rgb) {
    std::vector<uint8_t> bytes(rgb.size());
    srgbBytesInto(rgb, bytes);
    std::lock_guard<std::mutex> lock(mutex_);
    if (y != next_) {
        waiting_.emplace(y, std::move(bytes));
        return;
    }
    png_.write(bytes);
    for (++next_; !waiting_.empty() && waiting_.begin()->first == next_; ++next_) {
        png_.write(waiting_.begin()->second);
        waiting_.erase(waiting_.begin());
    }
}

}  // namespace pcsg::tools
