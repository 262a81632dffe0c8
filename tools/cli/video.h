// Videos of `pcsg render -o OUT.mp4 --frames N` (also .webm and .gif): the frames are
// rendered as PNG files, into a temporary directory (or next to OUT with --keep-frames,
// under POV-Ray's names), then encoded by ffmpeg.
#pragma once

#include <string>

namespace pcsg::tools {

// Whether the file is a video pcsg encodes: .mp4, .webm or .gif (any case).
bool isVideoOutput(const std::string& path);

// Where the frames of a video go and what ffmpeg reads.
struct VideoFrames {
    std::string pattern;  // the frames' output for the frame loop: DIR/STEM.png
    std::string tempDir;  // the temporary directory, removed afterwards; empty with --keep-frames
};

// Chooses the frames' place for OUT: DIR/STEM.png beside OUT with keepFrames, else in a
// new temporary directory. False (with `error`) when that cannot be made.
bool videoFramesFor(const std::string& output, bool keepFrames, VideoFrames& frames,
                    std::string& error);

// Encodes frames first..last of `frames` (their names from frameFileName(pattern, f,
// frames)) into `output` at fps frames per second with ffmpeg. Returns the error message,
// empty on success.
std::string encodeVideo(const std::string& output, const std::string& pattern, int first, int last,
                        int frames, double fps);

// Removes the temporary directory of the frames, if any.
void removeVideoFrames(const VideoFrames& frames);

}  // namespace pcsg::tools
