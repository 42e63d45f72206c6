// Runs fn(begin, end) over [0, n) split across persistent worker threads: a
// CPU batch's stepping.
#pragma once

#include <condition_variable>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace psc_host {

class WorkerPool {
public:
    // Throws std::system_error when the system gives fewer threads (the ones started are stopped first).
    explicit WorkerPool(int threads);
    ~WorkerPool();
    WorkerPool(const WorkerPool&) = delete;
    WorkerPool& operator=(const WorkerPool&) = delete;

    void run(int n, const std::function<void(int, int)>& fn);

private:
    void stop();
    int chunkEnd(int i) const { return static_cast<int>(static_cast<long long>(n_) * (i + 1) / threads_); }
    void loop(int index);

    std::vector<std::thread> workers_;
    int threads_ = 1;
    std::mutex mutex_;
    std::condition_variable wake_;
    std::condition_variable done_;
    const std::function<void(int, int)>* job_ = nullptr;
    int n_ = 0;
    int pending_ = 0;
    unsigned long long generation_ = 0;
    bool stopping_ = false;
};

}  // namespace psc_host
