#include "WorkerPool.h"

namespace psc_host {

WorkerPool::WorkerPool(int threads) {
    try {
        for (int i = 1; i < threads; ++i) workers_.emplace_back([this, i] { loop(i); });
    } catch (...) {
        stop();
        throw;
    }
    threads_ = threads;
}

WorkerPool::~WorkerPool() { stop(); }

void WorkerPool::run(int n, const std::function<void(int, int)>& fn) {
    if (threads_ == 1 || n < 2 * threads_) {
        fn(0, n);
        return;
    }
    {
        std::lock_guard<std::mutex> lock(mutex_);
        job_ = &fn;
        n_ = n;
        pending_ = threads_ - 1;
        ++generation_;
    }
    wake_.notify_all();
    fn(0, chunkEnd(0));
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [this] { return pending_ == 0; });
    job_ = nullptr;
}

void WorkerPool::stop() {
    {
        std::lock_guard<std::mutex> lock(mutex_);
        stopping_ = true;
        ++generation_;
    }
    wake_.notify_all();
    for (auto& w : workers_) w.join();
}

void WorkerPool::loop(int index) {
    unsigned long long seen = 0;
    for (;;) {
        const std::function<void(int, int)>* job;
        {
            std::unique_lock<std::mutex> lock(mutex_);
            wake_.wait(lock, [&] { return generation_ != seen; });
            seen = generation_;
            if (stopping_) return;
            job = job_;
        }
        (*job)(chunkEnd(index - 1), chunkEnd(index));
        {
            std::lock_guard<std::mutex> lock(mutex_);
            if (--pending_ == 0) done_.notify_one();
        }
    }
}

}  // namespace psc_host
