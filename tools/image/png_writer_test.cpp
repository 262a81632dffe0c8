// The in-process PNG writer of `pcsg render`: 8-bit sRGB values rounded as every 8-bit
// image of pcsg is, read back by OpenImageIO as they were written, and a failure that
// names the file and leaves nothing behind.
#include "png_writer.h"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "cli_test_util.h"
#include "image_format.h"
#include "image_test_util.h"

namespace pcsg::tools {
namespace {

using testing::filesIn;
using testing::readBack;
using testing::readFile;
using testing::TempDir;

// Black, white, mid-grey, clamping above 1 and below 0, and the linear segment near 0,
// with their 8-bit sRGB values worked out independently (see pcsg_image_test.cpp).
const std::vector<float> kPixels = {0.0f, 0.5f, 1.0f, 0.2f, 2.0f, -1.0f, 0.001f, 0.05f, 0.5f};
const std::vector<uint8_t> k8Bit = {0, 188, 255, 124, 255, 0, 3, 63, 188};

TEST(PngWriter, EncodesEightBitSrgb) {
    EXPECT_EQ(srgbBytes(kPixels), k8Bit);
}

// srgbBytes converts by a table of thresholds: the same bytes as the formula (the 8-bit
// value rounded from srgbEncode), checked on 2^20 values spread over [0, 1] and on both
// floats beside every 1/510th (where the rounding steps), whatever the table holds.
TEST(PngWriter, TheTableGivesTheFormulasBytes) {
    std::vector<float> values;
    for (int i = 0; i <= (1 << 20); ++i) values.push_back(static_cast<float>(i) / (1 << 20));
    for (int k = 0; k <= 510; ++k) {
        // the linear value whose encoding is k / 510, and the floats just around it
        const double e = k / 510.0;
        const float v =
            static_cast<float>(e <= 0.04045 ? e / 12.92 : std::pow((e + 0.055) / 1.055, 2.4));
        float below = v, above = v;
        for (int step = 0; step < 8; ++step) {
            below = std::nextafter(below, 0.0f);
            above = std::nextafter(above, 2.0f);
            values.insert(values.end(), {below, v, above});
        }
    }
    const std::vector<uint8_t> bytes = srgbBytes(values);
    size_t wrong = 0;
    for (size_t i = 0; i < values.size(); ++i)
        wrong += bytes[i] != static_cast<uint8_t>(std::lround(srgbEncode(values[i]) * 255.0));
    EXPECT_EQ(wrong, 0u);
}

// Runs of equal values (a flat sky) take the byte of the value three before them: still
// the formula's bytes, for runs, alternations, values equal but for their bits (0 and -0,
// NaNs) and spans that start anywhere.
TEST(PngWriter, RepeatedValuesGiveTheFormulasBytes) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    std::vector<float> values;
    for (float v : {0.3f, 0.3f, 0.3f, 0.3f, 0.7f, 0.3f, 0.3f,  0.0f,  -0.0f, 0.0f,  0.5f,  -0.0f,
                    nan,  0.2f, 0.9f, nan,  2.0f, 0.9f, 0.01f, 0.01f, 0.01f, 0.02f, 0.01f, 0.01f})
        values.push_back(v);
    for (int i = 0; i < 300; ++i) values.push_back(i % 7 < 4 ? 0.25f : 0.001f * i);
    auto formula = [](float v) { return static_cast<uint8_t>(std::lround(srgbEncode(v) * 255.0)); };
    for (size_t start : {size_t{0}, size_t{1}, size_t{2}, size_t{5}}) {
        const std::span<const float> part = std::span(values).subspan(start);
        std::vector<uint8_t> bytes(part.size(), 77);
        srgbBytesInto(part, bytes);
        for (size_t i = 0; i < part.size(); ++i)
            ASSERT_EQ(bytes[i], formula(part[i])) << "value " << start + i;
    }
}

TEST(PngWriter, OpenImageIOReadsBackWhatWasWritten) {
    TempDir dir;
    const std::string out = dir.file("img.png");
    writePng(out, 3, 1, kPixels);
    OIIO::ImageSpec spec;
    const auto px = readBack<uint8_t>(out, OIIO::TypeDesc::UINT8, spec);
    EXPECT_EQ(spec.width, 3);
    EXPECT_EQ(spec.height, 1);
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(px, k8Bit);
    EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"img.png"});
}

// The bytes of a PNG file's image data: its IDAT chunks joined and inflated.
std::vector<uint8_t> inflatedImageData(const std::string& path, size_t expected) {
    std::ifstream in(path, std::ios::binary);
    const std::vector<uint8_t> file{std::istreambuf_iterator<char>(in), {}};
    std::vector<uint8_t> deflated;
    for (size_t at = 8; at + 12 <= file.size();) {  // after the signature: length, type, data, CRC
        const size_t length = (size_t{file[at]} << 24) | (size_t{file[at + 1]} << 16) |
                              (size_t{file[at + 2]} << 8) | file[at + 3];
        if (std::string(file.begin() + at + 4, file.begin() + at + 8) == "IDAT")
            deflated.insert(deflated.end(), file.begin() + at + 8, file.begin() + at + 8 + length);
        at += 12 + length;
    }
    std::vector<uint8_t> out(expected + 1);
    uLongf size = out.size();
    EXPECT_EQ(uncompress(out.data(), &size, deflated.data(), deflated.size()), Z_OK);
    out.resize(size);
    return out;
}

// The rows are written unfiltered (filter type 0 before each row: libpng's adaptive choice
// among all five filters cost a frame of the growing tree three times the rest of the
// encoding, docs/benchmarks.md), and the file still holds exactly the pixels: a gradient
// with noise, on which the adaptive choice would pick Sub, Up or Paeth.
TEST(PngWriter, RowsAreUnfilteredAndHoldThePixels) {
    const int w = 61, h = 37;
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> noise(0.0f, 0.02f);
    std::vector<float> rgb;
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            rgb.insert(rgb.end(), {x / float(w) + noise(rng), y / float(h), 0.5f + noise(rng)});
    TempDir dir;
    const std::string out = dir.file("img.png");
    writePng(out, w, h, rgb);
    OIIO::ImageSpec spec;
    EXPECT_EQ(readBack<uint8_t>(out, OIIO::TypeDesc::UINT8, spec), srgbBytes(rgb));
    const size_t row = static_cast<size_t>(w) * 3 + 1;
    const std::vector<uint8_t> data = inflatedImageData(out, row * h);
    ASSERT_EQ(data.size(), row * h);
    const std::vector<uint8_t> bytes = srgbBytes(rgb);
    for (int y = 0; y < h; ++y) {
        EXPECT_EQ(data[y * row], 0) << "row " << y << " is filtered";
        EXPECT_TRUE(std::equal(bytes.begin() + y * (row - 1), bytes.begin() + (y + 1) * (row - 1),
                               data.begin() + y * row + 1))
            << "row " << y;
    }
}

TEST(PngWriter, AFailureNamesTheFileAndLeavesNothing) {
    TempDir dir;
    const std::string out = dir.file("no/such/dir/img.png");
    try {
        writePng(out, 3, 1, kPixels);
        ADD_FAILURE() << "no error";
    } catch (const std::runtime_error& e) {
        EXPECT_EQ(std::string(e.what()).rfind("cannot write '" + out + "': ", 0), 0u) << e.what();
    }
    EXPECT_THROW(writePng(dir.file("img.png"), 2, 1, kPixels), std::runtime_error);  // sizes
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

// The render hands its rows to PngRows in bands, in any order and from several threads:
// the file is writePng()'s byte for byte whatever the order, though no row is held longer
// than the rows above it take to come.
TEST(PngWriter, RowsInAnyOrderGiveWritePngsFile) {
    const int w = 23, h = 50;
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> value(-0.1f, 1.2f);
    std::vector<float> rgb(static_cast<size_t>(w) * h * 3);
    for (float& v : rgb) v = value(rng);
    TempDir dir;
    writePng(dir.file("ref.png"), w, h, rgb);
    std::vector<int> order(h);
    for (int y = 0; y < h; ++y) order[y] = y;
    for (int round = 0; round < 3; ++round) {
        std::shuffle(order.begin(), order.end(), rng);
        const std::string out = dir.file("rows" + std::to_string(round) + ".png");
        PngRows png(out, w, h);
        auto put = [&](int first) {  // every other row of the order
            for (int k = first; k < h; k += 2)
                png.put(order[k], std::span(rgb).subspan(order[k] * w * 3, w * 3));
        };
        std::thread other(put, 1);
        put(0);
        other.join();
        EXPECT_FALSE(std::filesystem::exists(out)) << "renamed before finish()";
        png.finish();
        EXPECT_EQ(readFile(out), readFile(dir.file("ref.png"))) << "round " << round;
    }
}

// A PNG whose rows did not all come, or that was never finished, leaves nothing behind.
TEST(PngWriter, AnUnfinishedPngLeavesNothing) {
    TempDir dir;
    {
        PngRowWriter png(dir.file("a.png"), 3, 2);
        png.write(k8Bit);
        EXPECT_EQ(filesIn(dir.path()).size(), 1u);  // its temporary file
        try {
            png.finish();
            ADD_FAILURE() << "finished with one row of two";
        } catch (const std::runtime_error& e) {
            EXPECT_EQ(std::string(e.what()).rfind("cannot write '" + dir.file("a.png") + "': ", 0),
                      0u)
                << e.what();
        }
        EXPECT_THROW(png.write(k8Bit), std::runtime_error);  // closed by the error
    }
    {
        PngRows rows(dir.file("b.png"), 3, 1);
        rows.put(0, kPixels);
    }  // not finished
    EXPECT_TRUE(filesIn(dir.path()).empty());
    EXPECT_THROW(PngRowWriter(dir.file("no/such/dir/c.png"), 3, 1), std::runtime_error);
    EXPECT_TRUE(filesIn(dir.path()).empty());
}

}  // namespace
}  // namespace pcsg::tools
