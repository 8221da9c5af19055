// The viewer's clock: how many steps of the simulation a frame runs.
//
// Real time (the window's default): a frame adds the wall-clock time since the last one,
// times the time scale, to what is owed, and runs as many whole steps of the fixed step
// (1/60 s unless --dt says) as that pays — none on a fast frame, two on a slow one — so N
// wall-clock seconds are N simulated seconds at any frame rate, and every step is the
// same size (results do not depend on how fast the machine draws). After a stall (a
// breakpoint, a dragged window, a reload) at most `maxSteps` run in one frame; the rest
// is dropped, and counted, rather than a burst of catch-up frames that each fall further
// behind.
//
// Fixed (headless, recording): one step of `step × scale` a frame, whatever the frame
// took: frame N is the same image on any machine.
#pragma once

#include <cstdint>

namespace psys::viewer {

class SimClock {
public:
    struct Settings {
        double step = 1.0 / 60;  // seconds a step simulates (at scale 1)
        bool fixed = false;      // one step a frame, not real time
        double scale = 1;        // simulated seconds per wall-clock second
        int maxSteps = 8;        // the most steps one real-time frame runs
    };
    SimClock() = default;
    explicit SimClock(Settings settings) : settings_(settings) {}

    // A frame `realSeconds` after the last one (running): the steps it runs, each
    // `stepSeconds()` long.
    int advance(double realSeconds);
    // One step whatever real time says (the S key while paused).
    int stepOnce();
    double stepSeconds() const { return settings_.fixed ? settings_.step * settings_.scale : settings_.step; }

    Settings& settings() { return settings_; }
    const Settings& settings() const { return settings_; }
    // Real-time owes nothing after a pause or a switch of mode.
    void resetDebt() { owed_ = 0; }

    double simulated() const { return simulated_; }       // seconds the steps covered
    uint64_t steps() const { return steps_; }
    double dropped() const { return dropped_; }           // simulated seconds the cap let go
    uint64_t cappedFrames() const { return capped_; }     // frames the cap cut short
    int lastSteps() const { return last_; }

private:
    Settings settings_;
    double owed_ = 0;  // simulated seconds real time has run ahead of the steps
    double simulated_ = 0, dropped_ = 0;
    uint64_t steps_ = 0, capped_ = 0;
    int last_ = 0;
};

}  // namespace psys::viewer
