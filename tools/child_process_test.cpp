// Feeding a child process's standard input through a pipe (what `pcsg render` does with
// pcsg-image): all of the data arrives, more than a pipe holds at once; a child that
// stops reading or dies early neither blocks nor kills the writer. AsyncChild, started
// before its input exists: fed later, or abandoned; always reaped.
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

// Waits until the child has exited, without reaping it (its pid stays its own).
void awaitExitUnreaped(pid_t pid) {
    siginfo_t info{};
    while (waitid(P_PID, static_cast<id_t>(pid), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
    }
}

// Whether `pid` is gone for good: reaped, not running and not a zombie of this process.
bool reaped(pid_t pid) {
    int status = 0;
    return waitpid(pid, &status, WNOHANG) < 0 && errno == ECHILD;
}

TEST(AsyncChild, FedLaterAllOfTheInputArrives) {
    const auto data = pattern(3 << 20);
    AsyncChild child({"cat"});
    ASSERT_TRUE(child.started());
    const pid_t pid = child.pid();
    ASSERT_GT(pid, 0);
    // In three pieces. cat echoes all of it while it is written: without reading its
    // output meanwhile, both pipes would fill up and each side wait for the other.
    const auto all = std::span<const std::byte>(data);
    EXPECT_EQ(child.feed(all.first(1000)), 1000u);
    EXPECT_EQ(child.feed(all.subspan(1000, 2 << 20)), size_t{2 << 20});
    EXPECT_EQ(child.feed(all.subspan(1000 + (2 << 20))), data.size() - 1000 - (2 << 20));
    const ChildResult r = child.wait();
    EXPECT_TRUE(r.started);
    EXPECT_EQ(r.exitCode, 0) << r.err;
    EXPECT_EQ(r.inputWritten, data.size());
    ASSERT_EQ(r.out.size(), data.size());
    EXPECT_TRUE(r.out == asString(data));
    EXPECT_EQ(child.pid(), -1);
    EXPECT_TRUE(reaped(pid));
    // Once waited for, it is done: nothing more is taken, and wait() says the same again.
    EXPECT_EQ(child.feed(all.first(10)), 0u);
    EXPECT_EQ(child.wait().out.size(), data.size());
}

TEST(AsyncChild, OutputWrittenBeforeTheInputIsCapturedWhole) {
    // 1 MB on standard error before the child reads anything: it blocks on the full pipe
    // until this process reads, which it does while feeding.
    AsyncChild child({"sh", "-c", "head -c 1000000 /dev/zero | tr '\\0' e >&2; wc -c"});
    ASSERT_TRUE(child.started());
    const auto data = pattern(200000);
    EXPECT_EQ(child.feed(data), data.size());
    const ChildResult r = child.wait();
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_EQ(r.err, std::string(1000000, 'e'));
    EXPECT_EQ(r.out, "200000\n");
}

TEST(AsyncChild, WaitWithoutFeedingIsAnEndOfFile) {
    AsyncChild child({"wc", "-c"});
    const ChildResult r = child.wait();
    EXPECT_EQ(r.exitCode, 0);
    EXPECT_EQ(r.out, "0\n");
    EXPECT_EQ(r.inputWritten, 0u);
}

TEST(AsyncChild, AbandonedItIsKilledAndReaped) {
    // cat would wait for its input for ever; abandon() neither waits for it to end nor
    // passes on what it said.
    AsyncChild child({"sh", "-c", "echo started; echo complaint >&2; exec cat"});
    ASSERT_TRUE(child.started());
    const pid_t pid = child.pid();
    const ChildResult r = child.abandon();
    EXPECT_TRUE(r.started);
    EXPECT_EQ(r.signal, SIGKILL);
    EXPECT_EQ(r.out, "");
    EXPECT_EQ(r.err, "");
    EXPECT_EQ(r.inputWritten, 0u);
    EXPECT_EQ(child.pid(), -1);
    EXPECT_TRUE(reaped(pid));
    EXPECT_EQ(child.feed(pattern(10)), 0u);
}

TEST(AsyncChild, AbandonedAfterItExitedItsStatusIsKept) {
    AsyncChild child({"sh", "-c", "exit 3"});
    const pid_t pid = child.pid();
    awaitExitUnreaped(pid);
    const ChildResult r = child.abandon();
    EXPECT_EQ(r.exitCode, 3);
    EXPECT_EQ(r.signal, 0);
    EXPECT_TRUE(reaped(pid));
}

TEST(AsyncChild, TheDestructorReaps) {
    pid_t pid = -1;
    {
        AsyncChild child({"cat"});
        ASSERT_TRUE(child.started());
        pid = child.pid();
        child.feed(pattern(100));
    }
    EXPECT_TRUE(reaped(pid));
}

TEST(AsyncChild, AChildThatExitsBeforeReadingTakesNothing) {
    AsyncChild child({"sh", "-c", "echo gone >&2; exit 3"});
    ASSERT_TRUE(child.started());
    awaitExitUnreaped(child.pid());  // surely gone before the first byte is written
    const auto data = pattern(8 << 20);
    EXPECT_EQ(child.feed(data), 0u);  // EPIPE at once; SIGPIPE would kill this test
    EXPECT_FALSE(sigpipePending());
    EXPECT_EQ(child.feed(data), 0u);  // the input is closed now
    const ChildResult r = child.wait();
    EXPECT_EQ(r.exitCode, 3);
    EXPECT_EQ(r.err, "gone\n");
    EXPECT_EQ(r.inputWritten, 0u);
}

TEST(AsyncChild, AChildKilledWhileWaitingForItsInputIsReported) {
    AsyncChild child({"cat"});
    ASSERT_TRUE(child.started());
    ASSERT_EQ(kill(child.pid(), SIGKILL), 0);
    awaitExitUnreaped(child.pid());
    EXPECT_EQ(child.feed(pattern(1 << 20)), 0u);
    EXPECT_FALSE(sigpipePending());
    const ChildResult r = child.wait();
    EXPECT_TRUE(r.started);
    EXPECT_EQ(r.signal, SIGKILL);
    EXPECT_EQ(r.exitCode, -1);
}

TEST(AsyncChild, AChildKilledWhileReadingEndsTheFeeding) {
    // It reads 100 KB, then kills itself: the rest of the 8 MB cannot go anywhere.
    AsyncChild child({"sh", "-c", "head -c 100000 >/dev/null; kill -KILL $$"});
    const auto data = pattern(8 << 20);
    const size_t taken = child.feed(data);
    EXPECT_GE(taken, 100000u);
    EXPECT_LT(taken, data.size());
    EXPECT_FALSE(sigpipePending());
    const ChildResult r = child.wait();
    EXPECT_EQ(r.signal, SIGKILL);
    EXPECT_EQ(r.inputWritten, taken);
}

TEST(AsyncChild, AMissingProgramIsNotStarted) {
    AsyncChild child({"pcsg-no-such-program-here"});
    EXPECT_FALSE(child.started());
    EXPECT_EQ(child.feed(pattern(10)), 0u);
    EXPECT_FALSE(child.wait().started);
    EXPECT_FALSE(child.abandon().started);
}

TEST(AsyncChild, TheChildDoesNotInheritABlockedSigpipe) {
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
