// Helpers for the tests that read image files back (image_tests, which links OpenImageIO).
#pragma once

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pcsg::tools::testing {

// Reads every channel of an image file in the given type.
template <class T>
std::vector<T> readBack(const std::string& path, OIIO::TypeDesc type, OIIO::ImageSpec& spec) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
        return {};
    }
    spec = in->spec();
    std::vector<T> pixels(static_cast<size_t>(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, type, pixels.data())) << in->geterror();
    return pixels;
}

}  // namespace pcsg::tools::testing
