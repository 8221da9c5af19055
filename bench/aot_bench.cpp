// An ahead-of-time build against the JIT, on the fountain: what starting costs (compiling
// from source and JIT-compiling its kernels, against opening the linked-in build) and what
// a step costs at a steady population (both stepped and drawn in turn, frame by frame, so
// that the machine's drift falls on both alike). The build is made by `psysc build` when
// this is built, for this machine's CPU (as the JIT compiles for it).
//   psys_aot_bench [--particles N] [--frames F]
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

#include "fountain.h"

namespace {

double now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

void check(psys_error* e) {
    if (!e) return;
    std::fprintf(stderr, "%s\n", psys_error_message(e));
    std::exit(1);
}

// One frame: a step and what the host would draw.
void frame(psys_system* s) {
    check(psys_step(s, 1.0 / 60));
    for (size_t t = 0; t < psys_type_count(s); ++t) {
        psys_draw d;
        check(psys_get_draw(s, t, &d));
    }
}

}  // namespace

int main(int argc, char** argv) {
    double particles = 1e6;
    int frames = 120;
    for (int i = 1; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--particles")) particles = std::atof(argv[i + 1]);
        if (!std::strcmp(argv[i], "--frames")) frames = std::atoi(argv[i + 1]);
    }
    psys_options o;
    psys_options_init(&o);
    psys_system *jit = nullptr, *aot = nullptr;
    std::string path = std::string(PSYS_SAMPLES_DIR) + "/fountain.psys";
    setenv("PSYS_JIT_CACHE", "0", 1);  // the JIT compiles, as a first run does
    double t0 = now();
    check(psys_compile_file(path.c_str(), &o, &jit));
    double t1 = now();
    check(fountain_open(&o, &aot));
    double t2 = now();
    float population = static_cast<float>(particles);
    check(psys_set_extern(jit, "population", &population, 1));
    check(fountain_set_population(aot, population));
    for (int f = 0; f < 200; ++f) {  // past 3 s: the steady population
        frame(jit);
        frame(aot);
    }
    double jitSeconds = 0, aotSeconds = 0;
    for (int f = 0; f < frames; ++f) {
        double a = now();
        frame(jit);
        double b = now();
        frame(aot);
        double c = now();
        jitSeconds += b - a;
        aotSeconds += c - b;
    }
    psys_type_stats drops;
    check(psys_get_type_stats(aot, fountain_type_drop, &drops));
    std::printf("fountain, %zu drops, %d frames (a step and a draw each), %s\n\n", drops.live, frames,
                psys_aot_choose_cpu(&fountain_aot)->name);
    std::printf("| | start | frame (ms) |\n|---|---:|---:|\n");
    std::printf("| JIT (compile from source, LLVM) | %.1f ms | %.2f |\n", (t1 - t0) * 1e3, jitSeconds * 1e3 / frames);
    std::printf("| AOT (psys_open_aot, no LLVM) | %.2f ms | %.2f |\n", (t2 - t1) * 1e3, aotSeconds * 1e3 / frames);
    std::printf("\nAOT / JIT per frame: %.3f\n", aotSeconds / jitSeconds);
    psys_system_free(jit);
    psys_system_free(aot);
    return 0;
}
