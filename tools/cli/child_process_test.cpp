// Feeding a child process's standard input through a pipe (what `pcsg render` does with
// pcsg-image for an EXR or TIFF file): all of the data arrives, more than a pipe holds at
// once; a child that stops reading or dies early neither blocks nor kills the writer.
#include "child_process.h"

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <cerrno>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace pcsg::tools {
namespace {

// Bytes 0..255 repeated (zeros included), more than a pipe's 64 KB buffer.
std::vector<std::byte> pattern(size_t size) {
    std::vector<std::byte> data(size);
    for (size_t i = 0; i < size; ++i) data[i] = static_cast<std::byte>((i * 7 + i / 256) & 0xff);
    return data;
}

std::string asString(std::span<const std::byte> bytes) {
    return std::string(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

bool sigpipePending() {
    sigset_t pending;
    sigemptyset(&pending);
    sigpending(&pending);
    return sigismember(&pending, SIGPIPE) == 1;
}

TEST(ChildProcess, AllOfTheInputReachesTheChild) {
    const auto data = pattern(3 << 20);
    const ChildResult r = runChild({"cat"}, data);
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.inputWritten, data.size());
    ASSERT_EQ(r.out.size(), data.size());
    EXPECT_TRUE(r.out == asString(data));  // not EXPECT_EQ: no 3 MB message on failure
}

TEST(ChildProcess, EmptyInputIsAnEndOfFile) {
    const ChildResult r = runChild({"wc", "-c"}, std::span<const std::byte>());
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_EQ(r.out, "0\n");
    EXPECT_EQ(r.inputWritten, 0u);
}

TEST(ChildProcess, AChildThatStopsReadingEndsTheWriting) {
    const auto data = pattern(8 << 20);
    // head exits after 10 bytes: the rest of the writes fail with EPIPE. Were SIGPIPE
    // delivered, it would kill this test program.
    const ChildResult r = runChild({"head", "-c", "10"}, data);
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, asString(std::span(data).first(10)));
    EXPECT_LT(r.inputWritten, data.size());
    EXPECT_FALSE(sigpipePending());
}

TEST(ChildProcess, AChildThatDiesEarlyIsReportedNotFatal) {
    const auto data = pattern(8 << 20);
    const ChildResult r = runChild({"sh", "-c", "kill -KILL $$"}, data);
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.signal, SIGKILL);
    EXPECT_EQ(r.exitCode, -1);
    EXPECT_LT(r.inputWritten, data.size());
    EXPECT_FALSE(sigpipePending());
}

TEST(ChildProcess, AMissingProgramIsNotStarted) {
    const auto data = pattern(1000);
    const ChildResult r = runChild({"pcsg-no-such-program-here"}, data);
    EXPECT_FALSE(r.started);
}

TEST(ChildProcess, WithoutInputTheChildReadsNothing) {
    const ChildResult r = runChild({"wc", "-c"});
    ASSERT_TRUE(r.started);
    EXPECT_EQ(r.out, "0\n");
}

TEST(ChildProcess, TheChildDoesNotInheritABlockedSigpipe) {
    // Blocked here (as while feeding another child), the child must still have it
    // unblocked: pcsg-image relies on SIGPIPE's default when pcsg is gone.
    sigset_t pipeSignal, old;
    sigemptyset(&pipeSignal);
    sigaddset(&pipeSignal, SIGPIPE);
    pthread_sigmask(SIG_BLOCK, &pipeSignal, &old);
    const ChildResult r = runChild({"grep", "^SigBlk:", "/proc/self/status"});
    pthread_sigmask(SIG_SETMASK, &old, nullptr);
    ASSERT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.out, "SigBlk:\t0000000000000000\n");
}

}  // namespace
}  // namespace pcsg::tools
