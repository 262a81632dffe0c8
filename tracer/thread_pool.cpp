#include "thread_pool.h"

#include <fmt/format.h>
#include <pthread.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <mutex>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

namespace pcsg::tracer {

namespace {

using Body = std::function<void(size_t, int)>;

// The stack of a pool started by a loop that asks for none (0).
constexpr size_t kDefaultStackBytes = size_t{8} << 20;

thread_local const ParallelLimits* currentLimits = nullptr;
thread_local bool inLoop = false;

int machineThreads() {
    const unsigned n = std::thread::hardware_concurrency();
    return n > 0 ? static_cast<int>(n) : 1;
}

// The pool's threads wait for a loop (a new generation), take indices until none is left,
// and report that they are done.
class Pool {
  public:
    ~Pool() { stop(); }

    // Runs the loop on `threads` threads; false, doing nothing, while another loop runs.
    bool tryRun(int threads, size_t stackBytes, size_t count, const Body& body) {
        std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
        if (!busy) return false;
        const size_t workers = static_cast<size_t>(threads - 1);
        if (workers != threads_.size() || stackBytes > stackBytes_) {
            stop();
            start(workers, stackBytes == 0 ? kDefaultStackBytes : stackBytes);
        }
        {
            std::lock_guard<std::mutex> lock(m_);
            body_ = &body, count_ = count, error_ = nullptr;
            next_.store(0, std::memory_order_relaxed);
            running_ = static_cast<int>(workers);
            ++generation_;
        }
        wake_.notify_all();
        work(0);
        std::unique_lock<std::mutex> lock(m_);
        finished_.wait(lock, [&] { return running_ == 0; });
        body_ = nullptr;
        if (error_) std::rethrow_exception(std::exchange(error_, nullptr));
        return true;
    }

  private:
    struct Start {
        Pool* pool;
        int slot;
        uint64_t generation;  // the last loop before the thread started
    };

    void start(size_t workers, size_t stackBytes) {
        const size_t page = static_cast<size_t>(sysconf(_SC_PAGESIZE));
        stackBytes = (stackBytes + page - 1) / page * page;
        pthread_attr_t attr;
        pthread_attr_init(&attr);
        pthread_attr_setstacksize(&attr, stackBytes);
        for (size_t slot = 1; slot <= workers; ++slot) {
            pthread_t t;
            auto* s = new Start{this, static_cast<int>(slot), generation_};
            if (pthread_create(&t, &attr, threadMain, s) != 0) {
                delete s;
                pthread_attr_destroy(&attr);
                stop();
                throw std::runtime_error(fmt::format(
                    "cannot start a render thread with a {} MB stack", stackBytes >> 20));
            }
            threads_.push_back(t);
        }
        pthread_attr_destroy(&attr);
        stackBytes_ = stackBytes;
    }

    void stop() {
        {
            std::lock_guard<std::mutex> lock(m_);
            quit_ = true;
        }
        wake_.notify_all();
        for (pthread_t t : threads_) pthread_join(t, nullptr);
        threads_.clear();
        stackBytes_ = 0;
        quit_ = false;
    }

    static void* threadMain(void* p) {
        const Start s = *static_cast<Start*>(p);
        delete static_cast<Start*>(p);
        s.pool->serve(s.slot, s.generation);
        return nullptr;
    }

    void serve(int slot, uint64_t seen) {
        std::unique_lock<std::mutex> lock(m_);
        for (;;) {
            wake_.wait(lock, [&] { return quit_ || generation_ != seen; });
            if (quit_) return;
            seen = generation_;
            lock.unlock();
            work(slot);
            lock.lock();
            if (--running_ == 0) finished_.notify_one();
        }
    }

    void work(int slot) {
        inLoop = true;
        for (size_t i; (i = next_.fetch_add(1, std::memory_order_relaxed)) < count_;) {
            try {
                (*body_)(i, slot);
            } catch (...) {
                std::lock_guard<std::mutex> lock(m_);
                if (!error_) error_ = std::current_exception();
                next_.store(count_, std::memory_order_relaxed);
            }
        }
        inLoop = false;
    }

    std::mutex busy_;  // held by the loop that runs
    std::mutex m_;     // what follows, but next_
    std::condition_variable wake_, finished_;
    std::vector<pthread_t> threads_;
    size_t stackBytes_ = 0;
    uint64_t generation_ = 0;
    bool quit_ = false;
    const Body* body_ = nullptr;
    size_t count_ = 0;
    std::atomic<size_t> next_{0};
    int running_ = 0;
    std::exception_ptr error_;
};

Pool& pool() {
    static Pool p;
    return p;
}

}  // namespace

ParallelLimits::ParallelLimits(int threads, size_t stackBytes)
    : threads_(threads), stackBytes_(stackBytes), outer_(currentLimits) {
    currentLimits = this;
}

ParallelLimits::~ParallelLimits() {
    currentLimits = outer_;
}

int parallelSlots() {
    if (!currentLimits || currentLimits->threads_ <= 0) return machineThreads();
    return currentLimits->threads_;
}

size_t parallelStackBytes() {
    return currentLimits ? currentLimits->stackBytes_ : 0;
}

void parallelFor(size_t count, const Body& body) {
    const int threads = parallelSlots();
    if (!inLoop && threads > 1 && count > 1 &&
        pool().tryRun(threads, parallelStackBytes(), count, body))
        return;
    for (size_t i = 0; i < count; ++i) body(i, 0);
}

}  // namespace pcsg::tracer
