// `pcsg render` run as a program: it writes a PNG itself and has pcsg-image write an EXR
// or TIFF file, so the image must come out whole (size, and the same pixels whichever
// format carries them), a scene with a run-time error must leave no image, and a missing
// helper must be named when one is needed. The helper runs only once the pixels exist:
// a scene that does not compile or fails at run time starts none, a PNG render never
// does, and no exit leaves a helper process behind.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/inotify.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cli_test_util.h"
#include "image_format.h"
#include "image_test_util.h"
#include "test_support.h"

namespace pcsg::tools {
namespace {

using testing::filesIn;
using testing::pcsg;
using testing::readBack;
using testing::TempDir;

// Figure 3a with a camera and a light, small enough to render in a moment.
const char* kScene =
    R"(camera { location <-1.8, -5.4, 2.3>  look_at <0.1, 0.1, 0.0>  sky <0, 0, 1>  angle 40 }
light  { position <12, -6, 8>  color <1, 1, 1> }
background <0.1, 0.2, 0.4>
{c=3} S
S if(c > 0, 2, 1)
1: S -> tetrahedron
2: S -> {c=c-1} ( move(0.5,0.5,0.5) uscale(0.5) S ∪
                  move(-0.5,-0.5,0.5) uscale(0.5) S ∪
                  move(0.5,-0.5,-0.5) uscale(0.5) S ∪
                  move(-0.5,0.5,-0.5) uscale(0.5) S )
)";

// While it lives, descendants of this test process that lose their parent are re-parented
// to it instead of init: a pcsg-image that pcsg left running or unreaped turns up here.
class Subreaper {
  public:
    Subreaper() { prctl(PR_SET_CHILD_SUBREAPER, 1); }
    ~Subreaper() {
        leftovers();
        prctl(PR_SET_CHILD_SUBREAPER, 0);
    }
    Subreaper(const Subreaper&) = delete;
    Subreaper& operator=(const Subreaper&) = delete;

    // How many processes were left behind (now reaped). One still running is waited for:
    // with pcsg gone, its input is at an end.
    int leftovers() {
        int found = 0, status = 0;
        for (;;) {
            const pid_t p = waitpid(-1, &status, 0);
            if (p > 0) {
                ++found;
            } else if (errno != EINTR) {
                return found;  // ECHILD: none left
            }
        }
    }
};

// The number of times `what` occurs in `text`.
size_t occurrences(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

// A copy of pcsg alone in a directory with a stand-in pcsg-image beside it: a shell script
// that does `script` and then, if it gets that far, runs the real helper. An inotify watch
// on the script sees every start of it (exec opens the file), however soon it is killed.
class HelperBeside {
  public:
    HelperBeside(const TempDir& dir, const std::string& script) : dir_(dir) {
        namespace fs = std::filesystem;
        fs::copy_file(PCSG_EXECUTABLE, dir.file("pcsg"));
        dir.write("pcsg-image", "#!/bin/sh\n" + script + "\nexec '" +
                                    std::string(PCSG_IMAGE_EXECUTABLE) + "' \"$@\"\n");
        for (const char* name : {"pcsg", "pcsg-image"})
            fs::permissions(dir.file(name), fs::perms::owner_exec, fs::perm_options::add);
        watch_ = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
        EXPECT_GE(watch_, 0);
        EXPECT_GE(inotify_add_watch(watch_, dir.file("pcsg-image").c_str(), IN_OPEN), 0);
    }
    ~HelperBeside() {
        if (watch_ >= 0) close(watch_);
    }
    HelperBeside(const HelperBeside&) = delete;
    HelperBeside& operator=(const HelperBeside&) = delete;

    ChildResult pcsg(std::vector<std::string> args) const {
        args.insert(args.begin(), dir_.file("pcsg"));
        return runChild(args);
    }
    // Whether the helper was started since the last call.
    bool started() const {
        bool any = false;
        alignas(inotify_event) char events[4096];
        while (read(watch_, events, sizeof events) > 0) any = true;
        return any;
    }

  private:
    const TempDir& dir_;
    int watch_ = -1;
};

TEST(RenderCommand, WritesAPngOfTheRightSize) {
    Subreaper subreaper;
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    const std::string out = dir.file("s.png");
    const ChildResult r =
        pcsg({"render", scene, "-o", out, "--width", "40", "--height", "30", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    OIIO::ImageSpec spec;
    const auto px = readBack<uint8_t>(out, OIIO::TypeDesc::UINT8, spec);
    EXPECT_EQ(spec.width, 40);
    EXPECT_EQ(spec.height, 30);
    EXPECT_EQ(spec.nchannels, 3);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::UINT8);
    // Not a blank image: the background and the object are both there.
    ASSERT_FALSE(px.empty());
    EXPECT_NE(*std::min_element(px.begin(), px.end()), *std::max_element(px.begin(), px.end()));
    // The whole command's peak RSS; no writer process for a PNG.
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_GT(j.value("peak_rss_bytes", uint64_t{0}), 0u);
    EXPECT_TRUE(j.contains("image_write_seconds"));
    EXPECT_FALSE(j.contains("image_writer_peak_rss_bytes"));
    EXPECT_FALSE(j.contains("image_writer_seconds"));
    EXPECT_EQ(filesIn(dir.path()), (std::vector<std::string>{"s.pcsg", "s.png"}));
    EXPECT_EQ(subreaper.leftovers(), 0);
}

// The figures name the top level the render built: Sierpinski order 8's copies of one shared
// instance, and the terrain's cuts deferred to the walk (its instances are all unique), in
// the JSON and in the lines for people.
TEST(RenderCommand, TheFiguresNameTheTopLevel) {
    TempDir dir;
    const std::string terrain = tracer::testing::terrain(6);
    ASSERT_FALSE(terrain.empty());
    const std::string scenes[] = {std::string(PCSG_SOURCE_DIR) + "/tools/bench/sierpinski_8.pcsg",
                                  dir.write("t6.pcsg", terrain)};
    for (const std::string& scene : scenes) {
        const std::vector<std::string> args = {"render",     scene, "-o",       dir.file("x.png"),
                                               "--width",    "64",  "--height", "48",
                                               "--adaptive", "0.3"};
        std::vector<std::string> json = args;
        json.push_back("--json");
        const ChildResult r = pcsg(json), people = pcsg(args);
        ASSERT_EQ(r.exitCode, 0) << r.err;
        ASSERT_EQ(people.exitCode, 0) << people.err;
        const auto top = nlohmann::json::parse(r.out).at("top_level");
        EXPECT_TRUE(top.at("built").get<bool>()) << scene;
        EXPECT_GT(top.at("bytes").get<uint64_t>(), 0u) << scene;
        const bool deferred = scene == scenes[1];
        EXPECT_EQ(top.at("deferred_cuts").get<uint64_t>() > 0, deferred) << scene;
        EXPECT_EQ(top.at("copies").get<uint64_t>() > 0, !deferred) << scene;
        EXPECT_EQ(top.at("instances").get<uint64_t>(), deferred ? 0u : 1u) << scene;
        const std::string line = deferred ? "cuts deferred to the walk" : "copies of 1 instance,";
        EXPECT_NE(people.out.find(line), std::string::npos) << people.out;
    }
}

// A still PNG's rows go into the file as the render finishes them, and the figures say so.
TEST(RenderCommand, APngsRowsAreSaidToBeWrittenWhileRendering) {
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    const ChildResult r =
        pcsg({"render", scene, "-o", dir.file("s.png"), "--width", "40", "--height", "30"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_NE(r.out.find("(libpng, rows written while rendering)"), std::string::npos) << r.out;
}

TEST(RenderCommand, AnExrIsWrittenByTheHelperWhosePeakIsTheCommands) {
    Subreaper subreaper;
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    const std::string out = dir.file("s.exr");
    const ChildResult r =
        pcsg({"render", scene, "-o", out, "--width", "40", "--height", "30", "--json"});
    ASSERT_EQ(r.exitCode, 0) << r.err;
    OIIO::ImageSpec spec;
    readBack<float>(out, OIIO::TypeDesc::FLOAT, spec);
    EXPECT_EQ(spec.width, 40);
    EXPECT_EQ(spec.height, 30);
    // The writer's peak RSS beside the whole command's, which includes it.
    const auto j = nlohmann::json::parse(r.out);
    const uint64_t writer = j.value("image_writer_peak_rss_bytes", uint64_t{0});
    EXPECT_GT(writer, 0u);
    EXPECT_GE(j.value("peak_rss_bytes", uint64_t{0}), writer);
    EXPECT_TRUE(j.contains("image_write_seconds"));
    EXPECT_TRUE(j.contains("image_writer_seconds"));
    EXPECT_EQ(filesIn(dir.path()), (std::vector<std::string>{"s.exr", "s.pcsg"}));
    EXPECT_EQ(subreaper.leftovers(), 0);
}

TEST(RenderCommand, PngAndExrCarryTheSamePixels) {
    // The EXR holds the render's linear floats as they were piped: encoded to 8-bit sRGB
    // they must be the PNG, whose bytes the render's rows were turned into as they were
    // finished. A wrong byte order or row order on the pipe or in the rows would not be.
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    for (const char* name : {"s.png", "s.exr"})
        ASSERT_EQ(pcsg({"render", scene, "-o", dir.file(name), "--width", "24", "--height", "90",
                        "--threads", "2"})
                      .exitCode,
                  0)
            << name;
    OIIO::ImageSpec pngSpec, exrSpec;
    const auto png = readBack<uint8_t>(dir.file("s.png"), OIIO::TypeDesc::UINT8, pngSpec);
    const auto exr = readBack<float>(dir.file("s.exr"), OIIO::TypeDesc::FLOAT, exrSpec);
    ASSERT_EQ(png.size(), exr.size());
    ASSERT_EQ(png.size(), 24u * 90u * 3u);  // more rows than the render's window (66)
    for (size_t i = 0; i < png.size(); ++i)
        ASSERT_EQ(png[i], std::lround(srgbEncode(exr[i]) * 255.0)) << "value " << i;
}

// The selection returns 3, and S has two rules.
const char* kRunTimeError =
    "{c=2} S\n"
    "S if(c > 0, 3, 1)\n"
    "1: S -> sphere\n"
    "2: S -> {c=c-1} uscale(0.5) S\n";

TEST(RenderCommand, ARunTimeErrorExitsOneAndWritesNothing) {
    // Found by the primitive count before the render, and (the count stopped at once) by
    // the render itself: either way no image and no writer.
    for (const char* countVisits : {"20000000", "0"}) {
        SCOPED_TRACE(std::string("--count-visits ") + countVisits);
        Subreaper subreaper;
        TempDir dir;
        const std::string scene = dir.write("bad.pcsg", kRunTimeError);
        const std::string out = dir.file("bad.png");
        const ChildResult r = pcsg({"render", scene, "-o", out, "--width", "16", "--height", "12",
                                    "--count-visits", countVisits});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_EQ(r.signal, 0);
        // Exactly the one error, with its module path; nothing from pcsg-image.
        EXPECT_EQ(occurrences(r.err, "error"), 1u) << r.err;
        EXPECT_EQ(r.err.rfind(scene + ":2:3: error: the selection function of module S", 0), 0u)
            << r.err;
        EXPECT_EQ(r.err.find("pcsg-image"), std::string::npos) << r.err;
        EXPECT_EQ(r.out, "");
        EXPECT_FALSE(std::filesystem::exists(out));
        EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"bad.pcsg"});
        EXPECT_EQ(subreaper.leftovers(), 0);
    }
}

// Two errors: A's comes first in the count's walk (behind the camera); B's is in view.
const char* kTwoRunTimeErrors =
    "camera { location <0, -6, 0>  look_at <0, 0, 0>  sky <0, 0, 1>  angle 40 }\n"
    "{c=2} (move(0, -40, 0) A \u222a B)\n"
    "A if(c > 0, 3, 1)\n"
    "1: A -> sphere\n"
    "2: A -> {c=c-1} uscale(0.5) A\n"
    "B if(c > 0, 4, 1)\n"
    "1: B -> sphere\n"
    "2: B -> {c=c-1} uscale(0.5) B\n";

TEST(RenderCommand, TheCountsErrorWinsOverTheRendersAsWhenTheyRanInTurn) {
    // The count runs beside the render; what is reported is still the count's first error
    // (A's), as when the count ran first, whatever the threads.
    for (const char* threads : {"1", "2"}) {
        SCOPED_TRACE(std::string("--threads ") + threads);
        TempDir dir;
        const std::string scene = dir.write("two.pcsg", kTwoRunTimeErrors);
        const std::string out = dir.file("two.png");
        const ChildResult r = pcsg(
            {"render", scene, "-o", out, "--width", "32", "--height", "24", "--threads", threads});
        EXPECT_EQ(r.exitCode, 1) << r.err;
        EXPECT_EQ(occurrences(r.err, "error"), 1u) << r.err;
        EXPECT_EQ(r.err.rfind(scene + ":3:3: error: the selection function of module A", 0), 0u)
            << r.err;
        EXPECT_FALSE(std::filesystem::exists(out));
    }
}

TEST(RenderCommand, ARunTimeErrorStartsNoWriter) {
    // This writer would complain; for an EXR that fails at run time it never runs.
    Subreaper subreaper;
    TempDir dir;
    HelperBeside helper(dir, "echo 'pcsg-image write: a complaint' >&2");
    const std::string scene = dir.write("bad.pcsg", kRunTimeError);
    const ChildResult r = helper.pcsg(
        {"render", scene, "-o", dir.file("bad.exr"), "--width", "16", "--height", "12"});
    EXPECT_EQ(r.exitCode, 1) << r.err;
    EXPECT_FALSE(helper.started());
    EXPECT_EQ(occurrences(r.err, "error"), 1u) << r.err;
    EXPECT_EQ(r.err.find("complaint"), std::string::npos) << r.err;
    EXPECT_FALSE(std::filesystem::exists(dir.file("bad.exr")));
    EXPECT_EQ(subreaper.leftovers(), 0);
}

TEST(RenderCommand, ACompileErrorStartsNoWriter) {
    Subreaper subreaper;
    TempDir dir;
    HelperBeside helper(dir, "");
    const ChildResult bad =
        helper.pcsg({"render", dir.write("bad.pcsg", "sphere ∪\n"), "-o", dir.file("bad.exr")});
    EXPECT_EQ(bad.exitCode, 1) << bad.err;
    EXPECT_NE(bad.err.find("error"), std::string::npos) << bad.err;
    EXPECT_FALSE(helper.started());
    EXPECT_FALSE(std::filesystem::exists(dir.file("bad.exr")));
    // A PNG that renders is written without the helper too.
    const std::string scene = dir.write("s.pcsg", kScene);
    const ChildResult png =
        helper.pcsg({"render", scene, "-o", dir.file("s.png"), "--width", "16", "--height", "12"});
    EXPECT_EQ(png.exitCode, 0) << png.err;
    EXPECT_FALSE(helper.started());
    EXPECT_TRUE(std::filesystem::exists(dir.file("s.png")));
    // The watch does see a start: an EXR of a scene that renders runs the helper.
    const ChildResult good =
        helper.pcsg({"render", scene, "-o", dir.file("s.exr"), "--width", "16", "--height", "12"});
    EXPECT_EQ(good.exitCode, 0) << good.err;
    EXPECT_TRUE(helper.started());
    EXPECT_TRUE(std::filesystem::exists(dir.file("s.exr")));
    EXPECT_EQ(subreaper.leftovers(), 0);
}

TEST(RenderCommand, AWriterThatDiesBeforeReadingIsAnError) {
    // The writer is gone before it reads the pixels: writing them must fail with EPIPE,
    // not kill pcsg with SIGPIPE, and what the writer said is the error.
    Subreaper subreaper;
    TempDir dir;
    HelperBeside helper(dir, "echo 'pcsg-image: out of order' >&2; exit 3");
    const std::string out = dir.file("s.exr");
    const ChildResult r = helper.pcsg(
        {"render", dir.write("s.pcsg", kScene), "-o", out, "--width", "16", "--height", "12"});
    EXPECT_EQ(r.signal, 0);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_EQ(r.err, "pcsg render: pcsg-image: out of order\n");
    EXPECT_EQ(r.out, "");
    EXPECT_FALSE(std::filesystem::exists(out));
    EXPECT_EQ(subreaper.leftovers(), 0);
}

TEST(RenderCommand, AMissingImageHelperIsNamed) {
    // A copy of pcsg alone in a directory, with a PATH that has no pcsg-image either.
    TempDir dir;
    const std::string lonely = dir.file("pcsg");
    std::filesystem::copy_file(PCSG_EXECUTABLE, lonely);
    std::filesystem::permissions(lonely, std::filesystem::perms::owner_exec,
                                 std::filesystem::perm_options::add);
    const std::string scene = dir.write("s.pcsg", kScene);
    for (const char* name : {"s.exr", "s.tif"}) {
        const std::string out = dir.file(name);
        const ChildResult r = runChild({"env", "PATH=" + dir.file("empty-bin"), lonely, "render",
                                        scene, "-o", out, "--width", "16", "--height", "12"});
        ASSERT_TRUE(r.started);
        EXPECT_EQ(r.exitCode, 2) << r.err;
        EXPECT_NE(r.err.find("pcsg-image is missing"), std::string::npos) << r.err;
        EXPECT_FALSE(std::filesystem::exists(out));
    }
    // A PNG needs no helper.
    const std::string png = dir.file("s.png");
    const ChildResult r = runChild({"env", "PATH=" + dir.file("empty-bin"), lonely, "render", scene,
                                    "-o", png, "--width", "16", "--height", "12"});
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_TRUE(std::filesystem::exists(png));
}

TEST(RenderCommand, AnUnwritableOutputIsAnError) {
    Subreaper subreaper;
    TempDir dir;
    const std::string scene = dir.write("s.pcsg", kScene);
    // One line, the writer's reason under pcsg render's name: the PNG writer's own, and
    // pcsg-image's for an EXR.
    for (const auto& [name, writer] :
         {std::pair{"missing/s.png", ""}, std::pair{"missing/s.exr", "pcsg-image write: "}}) {
        const std::string out = dir.file(name);
        const ChildResult r = pcsg({"render", scene, "-o", out, "--width", "16", "--height", "12"});
        EXPECT_EQ(r.exitCode, 2);
        EXPECT_EQ(
            r.err.rfind(std::string("pcsg render: ") + writer + "cannot write '" + out + "': ", 0),
            0u)
            << r.err;
        EXPECT_EQ(occurrences(r.err, "\n"), 1u) << r.err;
        EXPECT_EQ(r.out, "");
        EXPECT_EQ(filesIn(dir.path()), std::vector<std::string>{"s.pcsg"});
    }
    EXPECT_EQ(subreaper.leftovers(), 0);
}

}  // namespace
}  // namespace pcsg::tools
