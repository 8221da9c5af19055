// Instances against one system (docs/embedding.md, "Instances"): the same spark effect as
// one system of N·k sparks, as N instances of k sparks each in one system, and as the
// program without `instance` (what instancing itself costs); then what starting an
// instance costs against compiling a system of its own, and what instances at their own
// speeds cost (rt/system_speeds.cpp). Steady-state steps, the median of
// the frames measured; ratios from one run (docs/performance.md).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "psys/psys.h"

namespace {

// Sparks thrown up from where their instance is, falling for a second: `rate` a second
// makes `rate` alive once it has run a second.
const char* const kInstanced = R"(
extern rate: float = 100 range(0, 1e7);
object spark(v: vec3) {
    vel = v + integrate(vec3(0, -9.8, 0));
    pos = snapshot(instance.pos) + integrate(vel);
    col = mix(vec4(1, 0.8, 0.3, 1), vec4(0.5, 0.1, 0, 0), age);
    point(pos, col, 2);
    kill when age >= 1;
}
object emitter { emit spark(nrand3() * 2 + vec3(0, 4, 0)) at rate per second; }
spawn emitter;
)";

std::string plainProgram() {  // the same without `instance`: one system as it was before
    std::string s = kInstanced;
    s.replace(s.find("snapshot(instance.pos)"), std::strlen("snapshot(instance.pos)"), "origin");
    return s;
}

// The plain program with `n` emitters made by a root at the start: what 1,000 emitters
// cost without instances (the emission per emitter is the same).
std::string manyEmitters(int n) {
    std::string s = plainProgram();
    s.replace(s.find("spawn emitter;"), std::strlen("spawn emitter;"),
              "object root { emit emitter count " + std::to_string(n) + "; }\nspawn root;");
    return s;
}

double seconds() {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void check(psys_error* e) {
    if (!e) return;
    std::fprintf(stderr, "instances_bench: %s\n", psys_error_message(e));
    std::exit(1);
}

psys_system* compile(const std::string& source, unsigned threads) {
    psys_options o;
    psys_options_init(&o);
    o.threads = threads;
    psys_system* s = nullptr;
    check(psys_compile_string(source.c_str(), "sparks.psys", &o, &s));
    return s;
}

struct Run {
    double median = 0;  // seconds a step
    size_t live = 0;
    double update = 0, emit = 0, create = 0;  // of the measured steps, a step's (the stats')
};

// Runs 90 frames to fill the pools, then measures `frames`.
Run measure(psys_system* s, int frames) {
    for (int f = 0; f < 90; ++f) check(psys_step(s, 1.0 / 60));
    psys_stats before, after;
    check(psys_get_stats(s, &before));
    std::vector<double> t;
    for (int f = 0; f < frames; ++f) {
        double a = seconds();
        check(psys_step(s, 1.0 / 60));
        t.push_back(seconds() - a);
    }
    std::sort(t.begin(), t.end());
    psys_type_stats st;
    check(psys_get_type_stats(s, 0, &st));
    check(psys_get_stats(s, &after));
    return {t[t.size() / 2], st.live, (after.update_seconds - before.update_seconds) / frames,
            (after.emit_seconds - before.emit_seconds) / frames, (after.create_seconds - before.create_seconds) / frames};
}

}  // namespace

int main(int argc, char** argv) {
    int instances = 1000, each = 100, frames = 120;
    unsigned threads = 1;
    for (int i = 1; i + 1 < argc; i += 2) {
        std::string a = argv[i];
        int v = std::atoi(argv[i + 1]);
        if (a == "--instances") instances = v;
        else if (a == "--each") each = v;
        else if (a == "--frames") frames = v;
        else if (a == "--threads") threads = static_cast<unsigned>(v);
        else {
            std::fprintf(stderr, "usage: psys_instances_bench [--instances N] [--each K] [--frames F] [--threads T]\n");
            return 2;
        }
    }
    const float total = static_cast<float>(instances) * static_cast<float>(each), per = static_cast<float>(each);
    std::printf("%d instances of %d sparks against one system of %.0f, %u thread%s, median of %d steps\n", instances,
                each, total, threads, threads == 1 ? "" : "s", frames);

    psys_system* plain = compile(plainProgram(), threads);
    check(psys_set_extern(plain, "rate", &total, 1));
    Run p = measure(plain, frames);
    psys_system_free(plain);

    psys_system* emitters = compile(manyEmitters(instances), threads);
    check(psys_set_extern(emitters, "rate", &per, 1));
    Run e = measure(emitters, frames);
    psys_system_free(emitters);

    psys_system* one = compile(kInstanced, threads);
    check(psys_set_extern(one, "rate", &total, 1));
    Run o = measure(one, frames);
    psys_system_free(one);

    psys_system* many = compile(kInstanced, threads);
    check(psys_set_extern(many, "rate", &per, 1));
    check(psys_instance_kill(many, 0));
    std::vector<psys_instance> played(static_cast<size_t>(instances));
    double start = seconds();
    for (int i = 0; i < instances; ++i) {
        float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, static_cast<float>(i % 40), 0, static_cast<float>(i / 40), 1};
        check(psys_play(many, m, &played[static_cast<size_t>(i)]));
    }
    const double play = (seconds() - start) / instances;
    Run m = measure(many, frames);
    // Half of them at half speed: each row's dt a column, its creation time moved on.
    for (int i = 0; i < instances; i += 2) check(psys_instance_set_speed(many, played[static_cast<size_t>(i)], 0.5f));
    Run paced = measure(many, frames);
    psys_system_free(many);

    start = seconds();
    psys_system* fresh = compile(kInstanced, threads);
    const double compileOne = seconds() - start;
    psys_system_free(fresh);

    auto parts = [](const Run& r) {
        std::printf("      update %.3f, emit %.3f, create %.3f ms a step (means)\n", r.update * 1e3, r.emit * 1e3,
                    r.create * 1e3);
    };
    std::printf("  one system, no `instance`     %8.3f ms a step  (%zu sparks)\n", p.median * 1e3, p.live);
    parts(p);
    std::printf("  %d emitters, no `instance`  %8.3f ms a step  (%zu sparks)  %.2f× the first\n", instances,
                e.median * 1e3, e.live, e.median / p.median);
    parts(e);
    std::printf("  one system, instanced         %8.3f ms a step  (%zu sparks)  %.2f× the first\n", o.median * 1e3,
                o.live, o.median / p.median);
    parts(o);
    std::printf("  %d instances                %8.3f ms a step  (%zu sparks)  %.2f× the first, %.2f× the emitters\n",
                instances, m.median * 1e3, m.live, m.median / p.median, m.median / e.median);
    parts(m);
    std::printf("  the same, half at speed 0.5     %8.3f ms a step  (%zu sparks)  %.2f× the instances at 1\n",
                paced.median * 1e3, paced.live, paced.median / m.median);
    parts(paced);
    std::printf("  starting an instance          %8.2f µs (a system compiled for it: %.1f ms, %.0f×)\n", play * 1e6,
                compileOne * 1e3, compileOne / play);
    return 0;
}
