#include "sim_clock.h"

#include <algorithm>
#include <cmath>

namespace psys::viewer {

int SimClock::advance(double realSeconds) {
    int n = 1;
    if (!settings_.fixed) {
        owed_ += std::max(realSeconds, 0.0) * settings_.scale;
        // A step is owed once real time reaches it (less a hair, so that 60 frames of
        // exactly 1/60 s are 60 steps whatever the rounding of the sum).
        double whole = std::floor(owed_ / settings_.step + 1e-9);
        n = static_cast<int>(std::min(whole, static_cast<double>(settings_.maxSteps) + 1));
        owed_ -= n * settings_.step;
        if (n > settings_.maxSteps) {  // a stall: let the rest go, and count it
            ++capped_;
            dropped_ += (n - settings_.maxSteps) * settings_.step + std::max(owed_, 0.0);
            owed_ = 0;
            n = settings_.maxSteps;
        }
        owed_ = std::max(owed_, 0.0);
    }
    last_ = n;
    steps_ += static_cast<uint64_t>(n);
    simulated_ += n * stepSeconds();
    return n;
}

int SimClock::stepOnce() {
    last_ = 1;
    ++steps_;
    simulated_ += stepSeconds();
    return 1;
}

}  // namespace psys::viewer
