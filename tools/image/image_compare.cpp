#include "image_compare.h"

#include <OpenImageIO/imagebufalgo.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "heat_ramp.h"
#include "image_format.h"

namespace pcsg::tools {

namespace {
float linearToSrgb(float v) {
    return static_cast<float>(srgbEncode(v));
}
float srgbToLinear(float v) {
    return static_cast<float>(srgbDecode(v));
}
}  // namespace

bool readLinear(const std::string& path, OIIO::ImageBuf& out, std::string& error) {
    OIIO::ImageBuf in(path);
    if (!in.read(0, 0, true, OIIO::TypeDesc::FLOAT)) {
        error = "cannot read " + path + ": " + in.geterror();
        return false;
    }
    const OIIO::ImageSpec& spec = in.spec();
    // The file's own pixel type (the buffer holds floats): integer files are sRGB-encoded.
    const OIIO::TypeDesc stored = in.nativespec().format;
    const bool encoded =
        stored.basetype == OIIO::TypeDesc::UINT8 || stored.basetype == OIIO::TypeDesc::UINT16;
    OIIO::ImageSpec rgb(spec.width, spec.height, 3, OIIO::TypeDesc::FLOAT);
    out.reset(rgb);
    const int channels = spec.nchannels;
    std::vector<float> pixel(static_cast<size_t>(channels));
    for (int y = 0; y < spec.height; ++y)
        for (int x = 0; x < spec.width; ++x) {
            in.getpixel(x + spec.x, y + spec.y, pixel.data(), channels);
            float v[3];
            for (int c = 0; c < 3; ++c) {
                const float s = pixel[static_cast<size_t>(std::min(c, channels - 1))];
                v[c] = encoded ? srgbToLinear(s) : s;
            }
            out.setpixel(x, y, v, 3);
        }
    return true;
}

OIIO::ImageBuf boxReduce(const OIIO::ImageBuf& linear, int k) {
    if (k <= 1) return linear;
    const OIIO::ImageSpec& s = linear.spec();
    OIIO::ROI roi(0, s.width / k, 0, s.height / k, 0, 1, 0, s.nchannels);
    // A box filter one destination pixel wide averages exactly the K×K source block.
    return OIIO::ImageBufAlgo::resize(linear, "box", 1.0f, roi, 1);
}

ImageMetrics compareImages(const OIIO::ImageBuf& a, const OIIO::ImageBuf& b, const Thresholds& t) {
    ImageMetrics m;
    const OIIO::ImageSpec& s = a.spec();
    m.width = s.width;
    m.height = s.height;
    if (b.spec().width != s.width || b.spec().height != s.height) return m;
    double sum = 0, sum2 = 0;
    size_t off = 0;
    const size_t pixels = static_cast<size_t>(s.width) * static_cast<size_t>(s.height);
    for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) {
            float pa[3], pb[3];
            a.getpixel(x, y, pa, 3);
            b.getpixel(x, y, pb, 3);
            double worst = 0;
            for (int c = 0; c < 3; ++c) {
                const double d = std::fabs(double(linearToSrgb(pa[c])) - linearToSrgb(pb[c]));
                sum += d;
                sum2 += d * d;
                worst = std::max(worst, d);
            }
            if (worst > m.maxError) {
                m.maxError = worst;
                m.maxX = x;
                m.maxY = y;
            }
            if (worst > t.pixelOff) ++off;
        }
    const double n = 3.0 * static_cast<double>(pixels);
    m.meanAbsError = pixels ? sum / n : 0;
    m.rmse = pixels ? std::sqrt(sum2 / n) : 0;
    m.psnr = m.rmse > 0 ? 20.0 * std::log10(1.0 / m.rmse) : std::numeric_limits<double>::infinity();
    m.shareOff = pixels ? static_cast<double>(off) / static_cast<double>(pixels) : 0;
    m.agree = pixels > 0 && m.shareOff <= t.maxShareOff && m.meanAbsError <= t.maxMeanError;
    return m;
}

OIIO::ImageBuf diffHeatMap(const OIIO::ImageBuf& a, const OIIO::ImageBuf& b) {
    const OIIO::ImageSpec& s = a.spec();
    OIIO::ImageBuf out(OIIO::ImageSpec(s.width, s.height, 3, OIIO::TypeDesc::FLOAT));
    for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) {
            float pa[3], pb[3];
            a.getpixel(x, y, pa, 3);
            b.getpixel(x, y, pb, 3);
            float d = 0;
            for (int c = 0; c < 3; ++c)
                d = std::max(d, std::fabs(linearToSrgb(pa[c]) - linearToSrgb(pb[c])));
            const HeatRgb rgb = heatColour(d);
            const float lin[3] = {srgbToLinear(rgb.r), srgbToLinear(rgb.g), srgbToLinear(rgb.b)};
            out.setpixel(x, y, lin, 3);
        }
    return out;
}

bool writeSrgbPng(const OIIO::ImageBuf& linear, const std::string& path, std::string& error) {
    const OIIO::ImageSpec& s = linear.spec();
    OIIO::ImageBuf enc(OIIO::ImageSpec(s.width, s.height, 3, OIIO::TypeDesc::FLOAT));
    for (int y = 0; y < s.height; ++y)
        for (int x = 0; x < s.width; ++x) {
            float p[3];
            linear.getpixel(x, y, p, 3);
            for (float& v : p) v = linearToSrgb(v);
            enc.setpixel(x, y, p, 3);
        }
    enc.specmod().attribute("oiio:ColorSpace", "sRGB");
    if (!enc.write(path, OIIO::TypeDesc::UINT8)) {
        error = "cannot write " + path + ": " + enc.geterror();
        return false;
    }
    return true;
}

}  // namespace pcsg::tools
