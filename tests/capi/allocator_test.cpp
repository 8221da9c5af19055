// The host's allocator (psys_options.allocator): a system's particle memory — its
// columns and its pools' arrays — comes from it and goes back to it, every block with the
// size it was asked for and by the system's end; results are the same bits as with the
// library's own; a steady state asks nothing of it; an allocator that says no fails the
// call that asked, in words, and the system goes on once it gives again.
#include <doctest/doctest.h>

#include <atomic>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "psys/psys.h"

namespace {

std::string saidBy(psys_error* e) {
    std::string m = e ? psys_error_message(e) : "";
    psys_error_free(e);
    return m;
}

// A host's allocator that keeps account: every block it gave and its size, what it has
// out, how many calls; it gives nothing past `limit` bytes out.
struct Arena {
    std::mutex mutex;
    std::map<void*, size_t> blocks;
    size_t out = 0, peak = 0, limit = SIZE_MAX;
    long refuseAt = -1;  // the allocation (counted from 0) that gets nothing: -1 none
    long calls = 0, wrongSizes = 0, unknown = 0, badAlignments = 0;
    bool misalign = false;  // gives blocks one byte off the alignment asked

    static void* allocate(void* user, size_t bytes, size_t alignment) {
        auto& a = *static_cast<Arena*>(user);
        std::lock_guard lock(a.mutex);
        ++a.calls;
        if (alignment == 0 || (alignment & (alignment - 1)) || alignment > 64) ++a.badAlignments;
        if (a.out + bytes > a.limit) return nullptr;
        if (a.refuseAt >= 0 && a.refuseAt-- == 0) return nullptr;
        auto* p = static_cast<std::byte*>(std::aligned_alloc(64, (bytes + 1 + 63) / 64 * 64));
        if (a.misalign) ++p;
        a.blocks[p] = bytes;
        a.out += bytes;
        a.peak = std::max(a.peak, a.out);
        return p;
    }
    static void release(void* user, void* memory, size_t bytes) {
        auto& a = *static_cast<Arena*>(user);
        std::lock_guard lock(a.mutex);
        ++a.calls;
        auto it = a.blocks.find(memory);
        if (it == a.blocks.end()) {
            ++a.unknown;
            return;
        }
        if (it->second != bytes) ++a.wrongSizes;
        a.out -= it->second;
        a.blocks.erase(it);
        std::free(a.misalign ? static_cast<std::byte*>(memory) - 1 : memory);
    }
    psys_allocator allocator() { return {&Arena::allocate, &Arena::release, this}; }
};

struct Sys {
    psys_system* s = nullptr;
    ~Sys() { psys_system_free(s); }
};

psys_options hostOptions(const char* backend, psys_allocator allocator = {}) {
    psys_options o;
    psys_options_init(&o);
    o.backend = backend;
    o.math = "exact";
    o.threads = 2;
    o.allocator = allocator;
    return o;
}

std::vector<psys_point> allPoints(psys_system* s) {
    std::vector<psys_point> all;
    for (size_t t = 0; t < psys_type_count(s); ++t) {
        size_t n = 0;
        REQUIRE(saidBy(psys_read_points(s, t, nullptr, 0, &n)) == "");
        std::vector<psys_point> some(n);
        REQUIRE(saidBy(psys_read_points(s, t, some.data(), n, &n)) == "");
        all.insert(all.end(), some.begin(), some.end());
    }
    return all;
}

bool sameBits(const std::vector<psys_point>& a, const std::vector<psys_point>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(psys_point)) == 0;
}

void stepFrames(psys_system* s, int n) {
    for (int i = 0; i < n; ++i) REQUIRE(saidBy(psys_step(s, 1.0 / 60)) == "");
}

}  // namespace

TEST_CASE("a host's allocator gives a system its particle memory, all of it back at the end, the same bits") {
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(std::string(backend));
        const std::string fire = std::string(PSYS_SAMPLES_DIR) + "/fire.psys";
        Arena arena;
        std::vector<psys_point> own, hosts;
        size_t live = 0;
        {
            Sys mine, theirs;
            psys_options plain = hostOptions(backend), given = hostOptions(backend, arena.allocator());
            REQUIRE(saidBy(psys_compile_file(fire.c_str(), &plain, &mine.s)) == "");
            REQUIRE(saidBy(psys_compile_file(fire.c_str(), &given, &theirs.s)) == "");
            stepFrames(mine.s, 90);
            stepFrames(theirs.s, 90);
            own = allPoints(mine.s);
            hosts = allPoints(theirs.s);
            live = hosts.size();
            // A hot reload's state takes its memory from the same allocator.
            REQUIRE(saidBy(psys_reload(theirs.s, nullptr)) == "");
            stepFrames(theirs.s, 10);
            CHECK(arena.out > 0);
        }
        CHECK(live > 300);
        CHECK(sameBits(own, hosts));
        // Columns of floats for every live object at least: it had the particles' memory.
        CHECK(arena.peak >= live * 4 * 8);
        CHECK(arena.out == 0);
        CHECK(arena.blocks.empty());
        CHECK(arena.wrongSizes == 0);
        CHECK(arena.unknown == 0);
        CHECK(arena.badAlignments == 0);
    }
}

TEST_CASE("a steady state asks nothing of the host's allocator once its rows are reserved") {
    for (const char* backend : {"llvm", "interp"}) {
        CAPTURE(std::string(backend));
        Arena arena;
        Sys s;
        psys_options o = hostOptions(backend, arena.allocator());
        REQUIRE(saidBy(psys_compile_file((std::string(PSYS_SAMPLES_DIR) + "/fountain.psys").c_str(), &o, &s.s)) == "");
        stepFrames(s.s, 240);
        for (size_t t = 0; t < psys_type_count(s.s); ++t) {
            psys_type_stats st;
            REQUIRE(saidBy(psys_get_type_stats(s.s, t, &st)) == "");
            const size_t before = arena.out;
            REQUIRE(saidBy(psys_reserve(s.s, t, 2 * st.live + 1024)) == "");
            CHECK(arena.out > before);  // (memory now, not address space)
        }
        stepFrames(s.s, 60);
        const long calls = arena.calls;
        stepFrames(s.s, 300);
        CHECK(arena.calls == calls);
    }
}

TEST_CASE("an allocator that gives nothing fails the call that asked, in words, and the system goes on") {
    Arena arena;
    Sys s;
    psys_options o = hostOptions("llvm", arena.allocator());
    REQUIRE(saidBy(psys_compile_file((std::string(PSYS_SAMPLES_DIR) + "/fountain.psys").c_str(), &o, &s.s)) == "");
    stepFrames(s.s, 30);
    arena.limit = arena.out;  // nothing more
    std::string e = saidBy(psys_reserve(s.s, 0, 500000));
    CHECK(e.find("psys_reserve: the host's allocator gave no memory for ") == 0);
    // A step that needs rows it cannot have fails in words; given memory again, it steps on.
    bool failed = false;
    for (int i = 0; i < 600 && !failed; ++i) {
        std::string m = saidBy(psys_step(s.s, 1.0 / 60));
        if (m.empty()) continue;
        CHECK(m.find("psys_step: the host's allocator gave no memory for ") == 0);
        failed = true;
    }
    CHECK(failed);
    arena.limit = SIZE_MAX;
    stepFrames(s.s, 60);
    psys_type_stats st;
    REQUIRE(saidBy(psys_get_type_stats(s.s, 0, &st)) == "");
    CHECK(st.live > 0);
    CHECK(allPoints(s.s).size() > 0);
}

TEST_CASE("a refusal in the middle of a pool's growth leaves the pool whole: the steps after go on") {
    // Each of the first allocations of a growth refused in turn — a column moved before it,
    // a mask, a host array: the pool keeps its rows as they were (Pool::roomFor), and the
    // masks point at their columns (ASan would see a step through a released block).
    for (long k = 0; k < 12; ++k) {
        CAPTURE(k);
        Arena arena;
        Sys s;
        psys_options o = hostOptions("llvm", arena.allocator());
        REQUIRE(saidBy(psys_compile_file((std::string(PSYS_SAMPLES_DIR) + "/fire.psys").c_str(), &o, &s.s)) == "");
        stepFrames(s.s, 20);
        arena.refuseAt = k;
        bool failed = false;
        for (int i = 0; i < 200 && !failed; ++i) failed = !saidBy(psys_step(s.s, 1.0 / 60)).empty();
        CHECK(failed);
        arena.refuseAt = -1;
        stepFrames(s.s, 60);
        CHECK(allPoints(s.s).size() > 100);
        psys_system_free(s.s);
        s.s = nullptr;
        CHECK(arena.out == 0);
        CHECK(arena.unknown == 0);
        CHECK(arena.wrongSizes == 0);
    }
}

TEST_CASE("a bad allocator is refused in words") {
    Sys s;
    const std::string fountain = std::string(PSYS_SAMPLES_DIR) + "/fountain.psys";
    psys_options o = hostOptions("llvm");
    o.allocator.allocate = &Arena::allocate;  // and no release
    CHECK(saidBy(psys_compile_file(fountain.c_str(), &o, &s.s)) ==
          "psys_compile_file: psys_options.allocator needs both allocate and release (or neither, for the library's own)");
    CHECK(s.s == nullptr);
    // One that gives memory not aligned as asked: the step that asked says so.
    Arena arena;
    arena.misalign = true;
    o = hostOptions("llvm", arena.allocator());
    REQUIRE(saidBy(psys_compile_file(fountain.c_str(), &o, &s.s)) == "");
    std::string m = saidBy(psys_step(s.s, 1.0 / 60));
    for (int i = 0; i < 10 && m.empty(); ++i) m = saidBy(psys_step(s.s, 1.0 / 60));
    CHECK(m.find("the host's allocator gave ") != std::string::npos);
    CHECK(m.find("not aligned to ") != std::string::npos);
    psys_system_free(s.s);
    s.s = nullptr;
    CHECK(arena.out == 0);
    // A header before the allocator (0.2's options end at it): read, with the library's own.
    o = hostOptions("llvm");
    o.size = offsetof(psys_options, allocator);
    REQUIRE(saidBy(psys_compile_file(fountain.c_str(), &o, &s.s)) == "");
    stepFrames(s.s, 5);
}
