// Encoding a frame sequence with ffmpeg (video.h).
#include "video.h"

#include <fmt/format.h>
#include <stdlib.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <vector>

#include "child_process.h"
#include "frames.h"

namespace pcsg::tools {

namespace fs = std::filesystem;

namespace {

std::string lowerExtension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    return ext;
}

// The codec arguments for the container. H.264 and VP9 in yuv420p need even sizes: an odd
// width or height is padded by one pixel. A GIF gets a palette computed from its frames.
std::vector<std::string> codecArguments(const std::string& ext) {
    const std::string even = "pad=ceil(iw/2)*2:ceil(ih/2)*2";
    if (ext == ".mp4") return {"-vf", even, "-c:v", "libx264", "-pix_fmt", "yuv420p", "-crf", "18"};
    if (ext == ".webm")
        return {"-vf",     even,   "-c:v", "libvpx-vp9", "-pix_fmt",
                "yuv420p", "-b:v", "0",    "-crf",       "30"};
    return {"-vf", "split[a][b];[a]palettegen[p];[b][p]paletteuse", "-loop", "0"};
}

}  // namespace

bool isVideoOutput(const std::string& path) {
    const std::string ext = lowerExtension(path);
    return ext == ".mp4" || ext == ".webm" || ext == ".gif";
}

bool videoFramesFor(const std::string& output, bool keepFrames, VideoFrames& frames,
                    std::string& error) {
    const fs::path out(output);
    const std::string png = out.stem().string() + ".png";
    if (keepFrames) {
        frames.pattern = (out.parent_path() / png).string();
        return true;
    }
    std::string tmpl = (fs::temp_directory_path() / "pcsg-frames-XXXXXX").string();
    if (!mkdtemp(tmpl.data())) {
        error = "cannot create a temporary directory for the frames";
        return false;
    }
    frames.tempDir = tmpl;
    frames.pattern = (fs::path(tmpl) / png).string();
    return true;
}

std::string encodeVideo(const std::string& output, const std::string& pattern, int first, int last,
                        int frames, double fps) {
    // frameFileName pads the frame number to the width of N: ffmpeg's %0Wd reads the same.
    const int width = static_cast<int>(std::to_string(frames).size());
    const fs::path p(pattern);
    const std::string input = (p.parent_path() / fmt::format("{}%0{}d{}", p.stem().string(), width,
                                                             p.extension().string()))
                                  .string();
    std::vector<std::string> argv = {"ffmpeg",
                                     "-y",
                                     "-loglevel",
                                     "error",
                                     "-framerate",
                                     fmt::format("{}", fps),
                                     "-start_number",
                                     std::to_string(first),
                                     "-i",
                                     input,
                                     "-frames:v",
                                     std::to_string(last - first + 1)};
    for (std::string& a : codecArguments(lowerExtension(output))) argv.push_back(std::move(a));
    argv.push_back(output);
    const ChildResult r = runChild(argv);
    if (!r.started) return "cannot run ffmpeg";
    if (r.exitCode != 0) return fmt::format("ffmpeg could not encode '{}':\n{}", output, r.err);
    return {};
}

void removeVideoFrames(const VideoFrames& frames) {
    if (frames.tempDir.empty()) return;
    std::error_code ec;
    fs::remove_all(frames.tempDir, ec);
}

}  // namespace pcsg::tools
