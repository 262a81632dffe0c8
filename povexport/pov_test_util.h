// Running POV-Ray from the povexport tests (test code only): a private HOME with an
// empty user configuration (so POV-Ray does not complain about a missing one), a
// single thread, no display, PPM output that the tests read without an image library.
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace pcsg::povtest {

inline bool povrayInstalled() {
    return std::system("command -v povray >/dev/null 2>&1") == 0;
}

struct PovRun {
    int status = -1;
    std::string log;  // POV-Ray's console output (stdout and stderr)
    int width = 0, height = 0;
    std::vector<unsigned char> rgb;  // 8-bit RGB, row 0 at the top
    double seconds = 0;

    // The lines of the log that report a problem with the scene.
    std::string problems() const {
        std::istringstream in(log);
        std::string line, out;
        while (std::getline(in, line))
            if (line.find("Warning:") != std::string::npos ||
                line.find("Error") != std::string::npos || line.find("error") != std::string::npos)
                out += line + "\n";
        return out;
    }
    unsigned char at(int x, int y, int c) const {
        return rgb[(static_cast<size_t>(y) * width + x) * 3 + c];
    }
};

inline std::vector<unsigned char> readPpm(const std::string& path, int& w, int& h) {
    std::ifstream in(path, std::ios::binary);
    std::string magic;
    in >> magic;
    if (magic != "P6") return {};
    auto next = [&in]() {
        // Skips white space and comment lines, reads one number.
        for (;;) {
            in >> std::ws;
            if (in.peek() == '#') {
                std::string skip;
                std::getline(in, skip);
                continue;
            }
            long v = -1;
            in >> v;
            return v;
        }
    };
    w = static_cast<int>(next());
    h = static_cast<int>(next());
    const long maxval = next();
    in.get();  // the single white space after the header
    if (w <= 0 || h <= 0 || maxval != 255) return {};
    std::vector<unsigned char> px(static_cast<size_t>(w) * h * 3);
    in.read(reinterpret_cast<char*>(px.data()), static_cast<std::streamsize>(px.size()));
    if (!in) return {};
    return px;
}

struct PovJob {
    std::string name;
    std::string text;
    int width = 64, height = 48;
};

// POV-Ray gave up before rendering because its worker threads did not start in time,
// which happens when the machine is loaded (many renders at once beside sanitizer
// tests). The scene is not at fault, so such a run is tried again.
inline bool povThreadsTimedOut(const PovRun& run) {
    return run.log.find("Timed out waiting for worker thread startup") != std::string::npos;
}

// Renders POV-Ray scenes without anti-aliasing, each in a fresh directory under `root`,
// all at once (POV-Ray spends most of a small render sleeping between its threads'
// messages, so running them side by side costs little CPU and saves most of the wall
// time).
inline std::vector<PovRun> renderPovBatch(const std::vector<PovJob>& jobs,
                                          const std::filesystem::path& root) {
    namespace fs = std::filesystem;
    fs::remove_all(root);
    std::string script = "#!/bin/sh\n";
    for (size_t i = 0; i < jobs.size(); ++i) {
        const fs::path dir = root / (std::to_string(i) + "_" + jobs[i].name);
        fs::create_directories(dir / ".povray" / "3.7");
        std::ofstream(dir / ".povray" / "3.7" / "povray.conf").flush();
        std::ofstream(dir / "scene.pov") << jobs[i].text;
        script += "(cd '" + dir.string() + "' && HOME='" + dir.string() +
                  "' povray +Iscene.pov +Oout.ppm +FP +W" + std::to_string(jobs[i].width) + " +H" +
                  std::to_string(jobs[i].height) +
                  " -D -A -V +WT1 >log.txt 2>&1; echo $? >status.txt) &\n";
    }
    script += "wait\n";
    std::ofstream(root / "run.sh") << script;
    const auto start = std::chrono::steady_clock::now();
    const int rc = std::system(("sh '" + (root / "run.sh").string() + "'").c_str());
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::vector<PovRun> runs(jobs.size());
    for (size_t i = 0; i < jobs.size(); ++i) {
        const fs::path dir = root / (std::to_string(i) + "_" + jobs[i].name);
        PovRun& r = runs[i];
        r.seconds = seconds;
        std::ifstream statusf(dir / "status.txt");
        if (!(statusf >> r.status) || rc != 0) r.status = r.status == 0 ? -1 : r.status;
        std::ifstream logf(dir / "log.txt");
        std::stringstream ss;
        ss << logf.rdbuf();
        r.log = ss.str();
        r.rgb = readPpm((dir / "out.ppm").string(), r.width, r.height);
    }
    fs::remove_all(root);
    return runs;
}

// renderPovBatch, with the runs whose threads timed out tried again (one at a time, up
// to `retries` times each), so that a loaded machine does not fail a test. A run that
// still times out is returned as it is, and fails its test.
inline std::vector<PovRun> renderPovMany(const std::vector<PovJob>& jobs, int retries = 3) {
    const std::filesystem::path root =
        std::filesystem::path(::testing::TempDir()) / ("pcsg_pov_" + std::to_string(::getpid()));
    std::vector<PovRun> runs = renderPovBatch(jobs, root);
    for (size_t i = 0; i < runs.size(); ++i)
        for (int attempt = 0; attempt < retries && povThreadsTimedOut(runs[i]); ++attempt)
            runs[i] = renderPovBatch({jobs[i]}, root).front();
    return runs;
}

inline PovRun renderPov(const std::string& text, int w, int h, const std::string& name) {
    return renderPovMany({PovJob{name, text, w, h}}).front();
}

}  // namespace pcsg::povtest
