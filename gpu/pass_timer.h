// Where a step's GPU time goes, by pass: the kernels, and every piece of work the backend
// records around them — staging a launch's words, scatters and gathers of creation and
// parents, clearings, compactions of kills, read-back copies, columns growing. While
// timing is on, each piece is timed alone: a glFinish before it and one after (its wall
// time, what a GL whose timer does not see compute work, as llvmpipe's, can give) and a
// timer query around it (GPU time). Off, nothing is added to the work.
#pragma once

#include <chrono>
#include <cstddef>
#include <map>
#include <string>

namespace psys::gpu {

class PassTimer {
public:
    struct Time {
        double milliseconds = 0;      // GPU time (timer queries)
        double wallMilliseconds = 0;  // from a glFinish before to one after
        size_t launches = 0;          // pieces of work timed
        size_t rows = 0;              // rows (or invocations) they covered
    };
    PassTimer() = default;
    ~PassTimer();
    PassTimer(const PassTimer&) = delete;
    PassTimer& operator=(const PassTimer&) = delete;
    // Its GL objects deleted, while the context is current (the owner's destructor).
    void release();
    void enable(bool on) { on_ = on; }
    bool on() const { return on_ && depth_ == 0; }
    const std::map<std::string, Time>& times() const { return times_; }

    // Times the work recorded while it lives under `pass`; nested inside another, it adds
    // nothing (the outer one's time holds it).
    class Scope {
    public:
        Scope(PassTimer* timer, const char* pass, size_t rows);
        ~Scope();
        Scope(const Scope&) = delete;
        Scope& operator=(const Scope&) = delete;

    private:
        PassTimer* timer_;
        const char* pass_;
        size_t rows_;
        std::chrono::steady_clock::time_point start_;
    };

private:
    bool on_ = false;
    int depth_ = 0;
    unsigned query_ = 0;
    std::map<std::string, Time> times_;
};

}  // namespace psys::gpu
