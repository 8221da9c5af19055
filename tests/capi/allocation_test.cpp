// A steady-state step makes no heap allocation: every call to the malloc family of this
// process (operator new, TBB, LLVM's code and the run-time alike) is counted while a host
// steps a system that has reached its steady state — the rows it needs in use, every list
// of the step as long as it gets — and sets an extern and reads its draw each frame, as a
// game does. On the interpreter, the JIT (fast and exact maths) and an ahead-of-time build
// (fountain.a, made by psysc build at this test's build).
//
// Not in the sanitized builds: the sanitizers own malloc. PSYS_ALLOCATION_STACKS=N prints
// the stacks of the first N counted allocations (the addresses for addr2line or gdb).
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <execinfo.h>
#include <malloc.h>
#include <unistd.h>
#include <string>

#include "alloc_fountain.h"
#include "psys/psys.h"

extern "C" {
void* __libc_malloc(size_t);
void* __libc_calloc(size_t, size_t);
void* __libc_realloc(void*, size_t);
void* __libc_memalign(size_t, size_t);
void __libc_free(void*);
}

namespace {

std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
long stacksToPrint = 0;  // PSYS_ALLOCATION_STACKS, read before counting starts

void count() {
    if (!counting.load(std::memory_order_relaxed)) return;
    if (allocations.fetch_add(1, std::memory_order_relaxed) < stacksToPrint) {
        void* frames[24];  // backtrace_symbols_fd allocates nothing
        int n = backtrace(frames, 24);
        (void)!write(2, "-- a counted allocation:\n", 25);
        backtrace_symbols_fd(frames, n, 2);
    }
}

}  // namespace

// glibc lets a program replace the malloc family (every library's calls come here); the
// real ones lie underneath as __libc_*.
extern "C" {
void* malloc(size_t n) {
    count();
    return __libc_malloc(n);
}
void* calloc(size_t n, size_t size) {
    count();
    return __libc_calloc(n, size);
}
void* realloc(void* p, size_t n) {
    count();
    return __libc_realloc(p, n);
}
void* memalign(size_t align, size_t n) {
    count();
    return __libc_memalign(align, n);
}
void* aligned_alloc(size_t align, size_t n) {
    count();
    return __libc_memalign(align, n);
}
int posix_memalign(void** out, size_t align, size_t n) {
    count();
    void* p = __libc_memalign(align, n);
    if (!p) return ENOMEM;
    *out = p;
    return 0;
}
void* valloc(size_t n) {
    count();
    return __libc_memalign(4096, n);
}
void* pvalloc(size_t n) {
    count();
    return __libc_memalign(4096, (n + 4095) & ~size_t(4095));
}
void free(void* p) { __libc_free(p); }
}

namespace {

std::string take(psys_error* e) {
    std::string m = e ? psys_error_message(e) : "";
    psys_error_free(e);
    return m;
}

// Steps `sys` for `warm` frames, then counts the heap allocations of `counted` more frames
// in which the host sets `extern_` (if any) and reads every type's draw columns.
long allocationsOfSteadySteps(psys_system* sys, const char* extern_, float value, int warm, int counted) {
    auto frame = [&] {
        if (extern_) REQUIRE(take(psys_set_extern(sys, extern_, &value, 1)) == "");
        REQUIRE(take(psys_step(sys, 1.0 / 60)) == "");
        psys_draw draw;
        for (size_t t = 0; t < psys_type_count(sys); ++t) REQUIRE(take(psys_get_draw(sys, t, &draw)) == "");
        psys_type_stats stats;
        REQUIRE(take(psys_get_type_stats(sys, 0, &stats)) == "");
    };
    for (int i = 0; i < warm; ++i) frame();
    if (const char* n = std::getenv("PSYS_ALLOCATION_STACKS")) stacksToPrint = std::atol(n);
    void* warmed[1];
    backtrace(warmed, 1);  // its first call loads libgcc: not in the count
    allocations = 0;
    counting = true;
    for (int i = 0; i < counted; ++i) frame();
    counting = false;
    return allocations.load();
}

struct Opened {
    psys_system* sys = nullptr;
    ~Opened() { psys_system_free(sys); }
};

psys_options options(const char* backend, const char* math, unsigned threads) {  // (strings that outlive it)
    psys_options o;
    psys_options_init(&o);
    o.backend = backend;
    o.math = math;
    o.threads = threads;
    return o;
}

const std::string kSamples = PSYS_SAMPLES_DIR;

// Reserves twice each type's live objects (at most its capacity): psys_reserve.
void reserveTwiceLive(psys_system* sys) {
    for (size_t t = 0; t < psys_type_count(sys); ++t) {
        psys_type_stats st;
        REQUIRE(take(psys_get_type_stats(sys, t, &st)) == "");
        REQUIRE(take(psys_reserve(sys, t, std::min<size_t>(2 * st.live + 1024, 1u << 20))) == "");
    }
}

// A sample's steady state: 6 s of warming (every sample's particles live at most 5 s),
// then 5 s counted. `wanders`: the sample's particles live a random time, so the most
// alive at once, and the most dying in one step, creep up now and then, and a new high
// takes room once — a chunk's list of deaths grown, a new chunk's, the step's list of
// deaths — counted and bounded. After 5 s the test reserves twice each type's live
// objects (psys_reserve): the chunks' lists no longer grow.
void checkSample(const std::string& sample, const std::string& backend, const std::string& math, unsigned threads,
                 const char* extern_, float value, bool wanders = false, bool reserve = true) {
    CAPTURE(sample);
    CAPTURE(backend);
    CAPTURE(math);
    CAPTURE(threads);
    CAPTURE(reserve);
    psys_options o = options(backend.c_str(), math.c_str(), threads);
    Opened s;
    REQUIRE(take(psys_compile_file((kSamples + "/" + sample + ".psys").c_str(), &o, &s.sys)) == "");
    allocationsOfSteadySteps(s.sys, extern_, value, 300, 0);
    if (reserve) reserveTwiceLive(s.sys);
    const int counted = 300;
    long n = allocationsOfSteadySteps(s.sys, extern_, value, 60, counted);
    if (!wanders) {
        CHECK(n == 0);
        return;
    }
    MESSAGE(sample << " on " << backend << ", " << threads << " thread(s), " << std::string(reserve ? "" : "nothing ")
                    << "reserved: " << n << " allocations in " << counted << " steps, each at a new high");
    // Reserved, what still grows is the step's list of deaths and the ledger's lists of
    // them, at a new high of deaths in one step (each doubles: a few times in all).
    CHECK(n <= (reserve ? counted / 50 : counted / 10));
}

}  // namespace

TEST_CASE("a steady-state step makes no heap allocation on the interpreter") {
    checkSample("fountain", "interp", "exact", 1, "population", 3000);
    checkSample("follow_parent", "interp", "exact", 2, nullptr, 0);
    checkSample("fire", "interp", "exact", 2, "rate", 3000, true);
    checkSample("fire", "interp", "exact", 2, "rate", 3000, true, false);
}

TEST_CASE("a steady-state step makes no heap allocation on the JIT, on one thread or two, fast maths or exact") {
    for (unsigned threads : {1u, 2u}) {
        checkSample("fountain", "llvm", "fast", threads, "population", 20000, false, false);
        checkSample("fountain", "llvm", "exact", threads, "population", 20000);
        checkSample("follow_parent", "llvm", "fast", threads, nullptr, 0);
        checkSample("fire", "llvm", "fast", threads, "rate", 100000, true);
        checkSample("fire", "llvm", "fast", threads, "rate", 100000, true, false);
        checkSample("fireworks", "llvm", "exact", threads, nullptr, 0, true);
        checkSample("fireworks", "llvm", "exact", threads, nullptr, 0, true, false);
    }
}

TEST_CASE("late kills of a nested type and of a top-level one in the same step recycle what they took") {
    // A comet (nested tails that die, read by nothing) beside sparks that only die: the
    // ledger frees both kinds each step (Ledger::free: a type read or nested, and a simple
    // one), and neither keeps what it took.
    const std::string source = R"(
object comet {
    pos = vec3(cos(age) * 5, 3, sin(age) * 5);
    point(pos, white, 1);
    emit tail(nrand3()) at 300 per second;
    emit spark(pos) at 500 per second;
    object tail(offset: vec3) {
        point(comet.pos + offset * age, white, 1);
        kill when age > 1;
    }
}
object spark(p: vec3) {
    point(p + vec3(0, age, 0), white, 1);
    kill when age > 0.5;
}
spawn comet;
)";
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(std::string(backend));
        psys_options o = options(backend, "exact", 2);
        Opened s;
        REQUIRE(take(psys_compile_string(source.c_str(), "comet_and_sparks.psys", &o, &s.sys)) == "");
        CHECK(allocationsOfSteadySteps(s.sys, nullptr, 0, 180, 300) == 0);
    }
}

TEST_CASE("a steady-state step makes no heap allocation on an ahead-of-time build") {
    for (unsigned threads : {1u, 2u}) {
        CAPTURE(threads);
        psys_options o = options("aot", "fast", threads);
        Opened s;
        REQUIRE(take(alloc_fountain_open(&o, &s.sys)) == "");
        allocationsOfSteadySteps(s.sys, "population", 20000, 300, 0);
        reserveTwiceLive(s.sys);
        CHECK(allocationsOfSteadySteps(s.sys, "population", 20000, 60, 300) == 0);
    }
}

TEST_CASE("a steady-state step of 50 instances moved every frame, some at their own speeds, makes no heap allocation") {
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(backend);
        psys_options o = options(backend, "fast", 2);
        Opened s;
        const std::string halo = std::string(PSYS_EXAMPLES_DIR) + "/effects/halo.psys";
        REQUIRE(take(psys_compile_file(halo.c_str(), &o, &s.sys)) == "");
        REQUIRE(take(psys_instance_kill(s.sys, 0)) == "");
        psys_instance played[50];
        float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
        for (psys_instance& h : played) REQUIRE(take(psys_play(s.sys, m, &h)) == "");
        // (Some at their own speeds: each row's dt a column, the kills' times a list.)
        for (int i = 0; i < 10; ++i) REQUIRE(take(psys_instance_set_speed(s.sys, played[i], 0.5f + 0.2f * i)) == "");
        REQUIRE(take(psys_instance_pause(s.sys, played[10], 1)) == "");
        int frame = 0;
        auto run = [&](int frames) {
            for (int f = 0; f < frames; ++f, ++frame) {
                for (int i = 0; i < 50; ++i) {
                    m[12] = static_cast<float>(i) + 0.01f * static_cast<float>(frame);
                    REQUIRE(take(psys_instance_transform(s.sys, played[i], m)) == "");
                }
                REQUIRE(take(psys_step(s.sys, 1.0 / 60)) == "");
                psys_draw draw;
                for (size_t t = 0; t < psys_type_count(s.sys); ++t) REQUIRE(take(psys_get_draw(s.sys, t, &draw)) == "");
                psys_instance done[4];  // (the system's own, killed, at the first step: no other)
                CHECK(psys_finished_instances(s.sys, done, 4) == (frame == 0 ? 1u : 0u));
            }
        };
        run(300);
        reserveTwiceLive(s.sys);
        run(60);
        allocations = 0;
        counting = true;
        run(300);
        counting = false;
        CHECK(allocations.load() == 0);
    }
}
