#include "host_cache.h"

#include <condition_variable>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <mutex>
#include <ostream>
#include <thread>
#include <vector>

#include <fmt/format.h>

namespace psys::bench {
namespace {

double threadSeconds() {
    timespec t{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_nsec) * 1e-9;
}

// Workers, one a core, that stream their share of a buffer three times a round; run()
// wakes them and blocks until all are done.
class Streamers {
public:
    Streamers(size_t floats, unsigned workers) : data_(floats + 1, 1.0f) {
        for (unsigned w = 0; w < workers; ++w) threads_.emplace_back([this, w, workers] { work(w, workers); });
    }
    ~Streamers() {
        {
            std::lock_guard lock(m_);
            quit_ = true;
        }
        wake_.notify_all();
        for (std::thread& t : threads_) t.join();
    }
    void run() {
        std::unique_lock lock(m_);
        ++round_;
        wake_.notify_all();
        done_.wait(lock, [&] { return finished_ == round_ * threads_.size(); });
    }

private:
    void work(unsigned w, unsigned workers) {
        size_t seen = 0, share = data_.size() / workers;
        std::unique_lock lock(m_);
        for (;;) {
            wake_.wait(lock, [&] { return round_ > seen || quit_; });
            if (quit_) return;
            seen = round_;
            lock.unlock();
            float* p = data_.data() + w * share;
            for (int pass = 0; pass < 3; ++pass)
                for (size_t i = 0; i < share; ++i) p[i] = p[i] * 0.999f + 1.0f;
            lock.lock();
            ++finished_;
            done_.notify_all();
        }
    }
    std::vector<float> data_;
    std::vector<std::thread> threads_;
    std::mutex m_;
    std::condition_variable wake_, done_;
    size_t round_ = 0, finished_ = 0;
    bool quit_ = false;
};

struct HostWork {
    std::map<int, int> tree;
    std::vector<char> from = std::vector<char>(400000, 1), to = std::vector<char>(400000);
    long sink = 0;
    HostWork() {
        for (int i = 0; i < 2000; ++i) tree[i * 7919 % 10007] = i;
    }
    void run() {
        for (const auto& [key, value] : tree) sink += value;
        std::memcpy(to.data(), from.data(), from.size());
        for (int k = 0; k < 8; ++k) sink += static_cast<long>(std::make_unique<std::vector<int>>(1000 + k)->size());
    }
};

}  // namespace

int hostCacheFigures(std::ostream& out, int rounds) {
    unsigned workers = std::max(1u, std::thread::hardware_concurrency());
    out << fmt::format("# the host's fixed work between blocking waits for {} workers that each stream their share of a "
                       "buffer three times a round (llvmpipe's shape: one worker a core); {} rounds a size, the mean\n\n",
                       workers, rounds);
    out << "| buffer the workers stream (MB) | host work a round (µs) | host CPU a round, its wait included (µs) | "
           "host work ÷ with no buffer |\n|---:|---:|---:|---:|\n";
    HostWork work;
    double warm = 0;
    for (size_t mb : {0, 4, 32, 256}) {
        Streamers streamers(mb << 18, workers);
        streamers.run();  // (the buffer's pages touched)
        double own = 0, all = 0;
        for (int r = 0; r < rounds; ++r) {
            double start = threadSeconds();
            work.run();
            double between = threadSeconds();
            streamers.run();
            own += between - start;
            all += threadSeconds() - start;
        }
        own /= rounds;
        all /= rounds;
        if (mb == 0) warm = own;
        out << fmt::format("| {} | {:.1f} | {:.1f} | {:.1f}× |\n", mb, own * 1e6, all * 1e6, own / warm);
    }
    out << fmt::format("\n(host work: a walk of a 2000-entry tree, a 400 KB copy, 8 allocations; checksum {})\n",
                       work.sink % 2);
    return 0;
}

}  // namespace psys::bench
