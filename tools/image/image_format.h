// What every image writer agrees on, without OpenImageIO: the file types an image may be
// written as, where it is written before it is renamed, and the sRGB transfer function.
// `pcsg render` checks the output's type before it renders, then writes a PNG itself
// (tools/image/png_writer.h) or has pcsg-image write an EXR or TIFF (image_io.h).
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>
#include <string>

namespace pcsg::tools {

enum class ImageFormat {
    png,   // 8-bit sRGB
    tiff,  // 16-bit sRGB (.tif, .tiff)
    exr,   // linear 32-bit float
};

// The format a file name asks for, by its extension (case-insensitive); nullopt when it
// is none of .png, .tif, .tiff and .exr.
inline std::optional<ImageFormat> imageFormatOf(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (ext == ".png") return ImageFormat::png;
    if (ext == ".tif" || ext == ".tiff") return ImageFormat::tiff;
    if (ext == ".exr") return ImageFormat::exr;
    return std::nullopt;
}

// Where an image is written before it is renamed to `target`: a hidden file beside it
// with this process's id, so that a failed write never leaves a partial image in place.
inline std::filesystem::path temporaryBeside(const std::filesystem::path& target) {
    const std::filesystem::path dir =
        target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
    std::string name(1, '.');
    name.append(target.stem().string())
        .append(".tmp")
        .append(std::to_string(getpid()))
        .append(target.extension().string());
    return dir / name;
}

// For error messages about an unknown type.
inline constexpr const char* kImageTypesHint =
    "use .png for 8-bit sRGB, .exr for linear float, .tif or .tiff for 16-bit sRGB";

// The sRGB transfer function (IEC 61966-2-1): a linear value, clamped to [0, 1], to its
// encoded value, and back. The one implementation the writer and the comparison share.
inline double srgbEncode(double linear) {
    if (!(linear > 0)) return 0;  // also NaN
    if (linear >= 1) return 1;
    return linear <= 0.0031308 ? 12.92 * linear : 1.055 * std::pow(linear, 1.0 / 2.4) - 0.055;
}

inline double srgbDecode(double encoded) {
    return encoded <= 0.04045 ? encoded / 12.92 : std::pow((encoded + 0.055) / 1.055, 2.4);
}

}  // namespace pcsg::tools
