// The JIT's own promises: update loops vectorize, compiled code is cached by kernel text,
// one backend serves system after system, and the number of threads never changes a
// result.
#include <doctest/doctest.h>

#include <chrono>
#include <cstring>
#include <cstdlib>
#include <functional>
#include <map>
#include <thread>
#include <atomic>

#include <unistd.h>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <llvm/ExecutionEngine/Orc/ExecutorProcessControl.h>
#include <llvm/IR/IRBuilder.h>

#include "codegen_llvm/compile_threads.h"
#include "codegen_llvm/jit_engine.h"
#include "codegen_llvm/library_symbols.h"
#include "codegen_llvm/llvm_backend.h"
#include "driver/compile.h"
#include "interp/interpreter.h"
#include "rt/system.h"
#include "tests/system_support.h"
#include "tests/unexpected_op.h"

using namespace psys;

namespace {

std::string sample(const std::string& name) {
    std::ifstream in(std::string(PSYS_SAMPLES_DIR) + "/" + name + ".psys");
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

using test::drawnBytes;

ir::Module compile(const std::string& text) { return test::compileModule(text); }

}  // namespace

TEST_CASE("the update loops of the benchmark effects vectorize") {
    for (std::string name : {"fountain", "fire", "fireworks"}) {
        INFO(name);
        codegen_llvm::LlvmBackend jit;
        rt::System system(compile(sample(name)), jit);
        size_t updates = 0, vectorized = 0;
        for (const auto& r : jit.report().remarks) {
            bool update = r.loop.find(".update.") != std::string::npos && r.loop.find(".created") == std::string::npos;
            updates += update;
            vectorized += update && r.vectorized;
            INFO(r.loop, ": ", r.message);
            if (update) CHECK(r.vectorized);
        }
        CHECK(updates >= 1);
        CHECK(vectorized == updates);
    }
}

TEST_CASE("kernels are cached by their structure: compiling a system again compiles nothing") {
    codegen_llvm::LlvmBackend jit;
    std::string text = sample("fireworks");
    { rt::System first(compile(text), jit); }
    auto before = jit.report();
    CHECK(before.kernels > 0);
    rt::System again(compile(text), jit);
    CHECK(jit.report().kernels == before.kernels);
    CHECK(jit.report().cacheHits > before.cacheHits);
    drawnBytes(again, 60);
}

TEST_CASE("one backend runs system after system, each as a fresh interpreter would") {
    // Systems come and go (a viewer reloading on save): kernels of a destroyed system
    // must never be mistaken for those of a new one at the same address.
    codegen_llvm::LlvmBackend jit(codegen_llvm::MathMode::Exact);
    for (int round = 0; round < 2; ++round)
        for (std::string name : {"fire", "fountain", "fireworks", "swamp", "follow_parent"}) {
            INFO((name + " round " + std::to_string(round)));
            interp::Interpreter interpreter;
            rt::System a(compile(sample(name)), interpreter), b(compile(sample(name)), jit);
            CHECK(drawnBytes(a, 90) == drawnBytes(b, 90));
        }
}

TEST_CASE("the number of threads never changes a result") {
    // 30 000 drops: four chunks of rows, so the update loops really split.
    std::string text = sample("fountain");
    std::string reference;
    for (unsigned threads : {1u, 2u, 0u}) {
        INFO("threads ", threads);
        codegen_llvm::LlvmBackend jit;
        rt::SystemOptions options;
        options.threads = threads;
        rt::System system(compile(text), jit, options);
        float population = 30000;
        REQUIRE_FALSE(system.setExtern("population", {&population, 1}));
        std::string out = drawnBytes(system, 200);
        CHECK(system.pool(static_cast<size_t>(system.typeIndex("drop"))).live() > 25000);
        if (reference.empty()) reference = out;
        CHECK(out == reference);
    }
}

TEST_CASE("with PSYS_PERF_MAP set, every compiled function and its loop are named in perf's map") {
    std::string path = "/tmp/perf-" + std::to_string(::getpid()) + ".map";
    std::filesystem::remove(path);
    ::setenv("PSYS_PERF_MAP", "1", 1);
    {
        codegen_llvm::LlvmBackend jit;
        rt::System system(compile(sample("fountain")), jit);
        system.step(1.0 / 60);
    }
    ::unsetenv("PSYS_PERF_MAP");
    std::ifstream in(path);
    REQUIRE(in);
    std::map<std::string, std::pair<uint64_t, uint64_t>> functions;
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream fields(line);
        std::string start, size, name;
        fields >> start >> size >> name;
        INFO(line);
        REQUIRE(!name.empty());
        functions[name] = {std::stoull(start, nullptr, 16), std::stoull(size, nullptr, 16)};
    }
    std::filesystem::remove(path);
    REQUIRE(functions.count("drop.update.1"));
    REQUIRE(functions.count("drop.update.1.loop"));
    CHECK(functions["drop.update.1.loop"].second > functions["drop.update.1"].second);  // the loop is the work
    // No two functions overlap.
    uint64_t end = 0;
    std::map<uint64_t, uint64_t> byStart;
    for (auto& [name, range] : functions) byStart[range.first] = range.second;
    for (auto& [start, size] : byStart) {
        CHECK(start >= end);
        CHECK(size > 0);
        end = start + size;
    }
}

TEST_CASE("without PSYS_PERF_MAP no map is written") {
    std::string path = "/tmp/perf-" + std::to_string(::getpid()) + ".map";
    std::filesystem::remove(path);
    ::unsetenv("PSYS_PERF_MAP");
    codegen_llvm::LlvmBackend jit;
    rt::System system(compile(sample("fountain")), jit);
    system.step(1.0 / 60);
    CHECK_FALSE(std::filesystem::exists(path));
}

TEST_CASE("the JIT's render loops mark what is drawn as the run-time's rule says: visible, every value finite") {
    // k = 0: a NaN position; 1: drawn; 2: an infinite size; 3: a NaN colour; 4: not visible.
    const char* text =
        "object a(k: float) {\n"
        "    when k != 4 { point(k == 0 ? vec3(k) / k : vec3(k), k == 3 ? vec4(0.0 / 0.0) : white,\n"
        "                        k == 2 ? 1 / (k - 2) : 1); }\n"
        "}\n"
        "spawn a(0); spawn a(1); spawn a(2); spawn a(3); spawn a(4);";
    interp::Interpreter interpreter;
    codegen_llvm::LlvmBackend jit;
    rt::System slow(compile(text), interpreter), fast(compile(text), jit);
    REQUIRE(jit.marksDrawn());
    for (rt::System* s : {&slow, &fast}) {
        s->step(1.0 / 60);
        auto points = s->points(0);
        REQUIRE(points.size() == 1);
        CHECK(points[0].position[0] == 1);
        CHECK(s->draw(0).drawn == 1);
        CHECK(s->stats().nonFiniteRender == 3);
    }
}

TEST_CASE("a component every point draws alike has no column: the JIT and the interpreter hand over its value") {
    // a: colour (0, 1 - age, 0, 1), size 2: five constants, one colour column. b: a NaN
    // size, constant: no point of b is drawn, each counted as not finite.
    const char* text =
        "object a { point(vec3(age, 1, 2), mix(green, black, age), 2); }\n"
        "object b { point(vec3(age), white, 0.0 / 0.0); }\n"
        "spawn a; spawn a; spawn b;";
    interp::Interpreter interpreter;
    codegen_llvm::LlvmBackend jit;
    rt::System slow(compile(text), interpreter), fast(compile(text), jit);
    for (rt::System* s : {&slow, &fast}) {
        s->step(0.25);
        const rt::DrawColumns& a = s->draw(0);
        CHECK(a.drawn == 2);
        CHECK(a.position[0].valid());
        for (int c : {1, 2}) CHECK_FALSE(a.position[c].valid());
        CHECK(a.constant[1] == 1);
        CHECK(a.constant[2] == 2);
        CHECK_FALSE(a.color[0].valid());
        CHECK(a.color[1].valid());
        CHECK_FALSE(a.color[2].valid());
        CHECK_FALSE(a.color[3].valid());
        CHECK_FALSE(a.size.valid());
        CHECK(a.constant[7] == 2);
        auto points = s->points(0);
        REQUIRE(points.size() == 2);
        for (const rt::RenderPoint& p : points) {
            CHECK(p.position[0] == 0.25f);
            CHECK(p.position[2] == 2);
            CHECK(p.color[0] == 0);
            CHECK(p.color[1] == 0.75f);
            CHECK(p.color[3] == 1);
            CHECK(p.size == 2);
        }
        CHECK(s->draw(1).drawn == 0);
        CHECK(s->points(1).empty());
        CHECK(s->stats().nonFiniteRender == 1);
    }
}

TEST_CASE("the JIT draws as the step goes what it draws after the step: bit for bit in exact maths") {
    // In fast maths an object created during a step is rendered in its creation batch, where
    // its row may fall in the vector body or the scalar remainder of the loop unlike in the
    // pool: vector and scalar maths functions differ in the last bits (within fast maths'
    // tolerance, which the differential tests hold the JIT to either way).
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR)) {
        if (entry.path().extension() != ".psys") continue;
        INFO(entry.path().filename().string());
        std::string text = sample(entry.path().stem().string());
        for (auto drawOn : {std::function<bool(int)>([](int) { return true; }), std::function<bool(int)>([](int f) { return f % 3 == 2; })}) {
            codegen_llvm::LlvmBackend a(codegen_llvm::MathMode::Exact), b(codegen_llvm::MathMode::Exact);
            CHECK(test::hostSees(text, a, true, 120, drawOn) == test::hostSees(text, b, false, 120, drawOn));
        }
    }
}

TEST_CASE("fast maths calls glibc's vector functions at the loops' full width — exact maths calls libm's") {
    codegen_llvm::LlvmBackend fast(codegen_llvm::MathMode::Fast), exact(codegen_llvm::MathMode::Exact);
    // The 16-lane (AVX-512) variants where loops run 16 floats a register, else 8 (AVX) or 4.
    std::string wide = fast.lanes() == 16 ? "_ZGVeN16v_expf" : fast.lanes() == 8 ? "_ZGVdN8v_expf" : "_ZGVbN4v_expf";
    rt::System a(compile(sample("fire")), fast), b(compile(sample("fire")), exact);
    auto calls = [](const rt::Backend& backend) {
        std::string all;
        for (const std::string& c : backend.report().calls) all += c + " ";
        return all;
    };
    INFO("fast: " << calls(fast) << "; exact: " << calls(exact));
    CHECK(calls(fast).find(wide + " ") != std::string::npos);
    CHECK(calls(exact).find("expf ") != std::string::npos);
    CHECK(calls(exact).find("_ZGV") == std::string::npos);
}

TEST_CASE("compiled objects are cached on disk: a second backend loads them, runs the same bits, and survives a damaged file") {
    std::filesystem::path folder = std::filesystem::temp_directory_path() / ("psys-jit-cache-" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder);
    ::setenv("PSYS_JIT_CACHE", folder.c_str(), 1);
    auto run = [](codegen_llvm::LlvmBackend& backend) {
        rt::System system(compile(sample("fireworks")), backend);
        return drawnBytes(system, 120);
    };
    codegen_llvm::LlvmBackend first;
    std::string compiled = run(first);
    CHECK(first.report().fromDisk == 0);
    size_t files = 0;
    for (auto& entry : std::filesystem::directory_iterator(folder)) files += entry.path().extension() == ".o";
    CHECK(files == first.report().kernels);
    codegen_llvm::LlvmBackend second;
    CHECK(run(second) == compiled);
    CHECK(second.report().fromDisk == second.report().kernels);
    CHECK(second.report().remarks.size() == first.report().remarks.size());  // kept beside the objects
    // A damaged object is removed and its module compiled again.
    std::filesystem::path damaged;
    for (auto& entry : std::filesystem::directory_iterator(folder))
        if (entry.path().extension() == ".o") damaged = entry.path();
    std::ofstream(damaged, std::ios::trunc) << "not an object";
    codegen_llvm::LlvmBackend third;
    CHECK(run(third) == compiled);
    CHECK(third.report().fromDisk == third.report().kernels - 1);
    ::setenv("PSYS_JIT_CACHE", "0", 1);
    codegen_llvm::LlvmBackend off;
    CHECK(run(off) == compiled);
    CHECK(off.report().fromDisk == 0);
    ::unsetenv("PSYS_JIT_CACHE");
    std::filesystem::remove_all(folder);
}

TEST_CASE("the disk cache keeps at most 4096 objects, dropping the least recently used") {
    std::filesystem::path folder = std::filesystem::temp_directory_path() / ("psys-jit-prune-" + std::to_string(::getpid()));
    std::filesystem::remove_all(folder);
    std::filesystem::create_directories(folder);
    auto now = std::filesystem::file_time_type::clock::now();
    for (int i = 0; i < 4100; ++i) {
        std::filesystem::path file = folder / (std::to_string(i) + ".o");
        std::ofstream(file) << "x";
        std::ofstream(folder / (std::to_string(i) + ".remarks")) << "";
        std::filesystem::last_write_time(file, now - std::chrono::hours(5000 - i));  // 0 the oldest
    }
    ::setenv("PSYS_JIT_CACHE", folder.c_str(), 1);
    { codegen_llvm::LlvmBackend jit; }
    ::unsetenv("PSYS_JIT_CACHE");
    size_t objects = 0, remarks = 0;
    for (auto& entry : std::filesystem::directory_iterator(folder)) {
        objects += entry.path().extension() == ".o";
        remarks += entry.path().extension() == ".remarks";
    }
    CHECK(objects == 3072);
    CHECK(remarks == 3072);
    CHECK_FALSE(std::filesystem::exists(folder / "0.o"));
    CHECK(std::filesystem::exists(folder / "4099.o"));
    std::filesystem::remove_all(folder);
}

TEST_CASE("the JIT refuses an op it has no code for with the located internal error every backend gives") {
    codegen_llvm::LlvmBackend jit;
    CHECK(test::refusal(jit) == test::expectedRefusal("the LLVM backend"));
}

// ORC decides what a lookup's generator must define before it takes the generator: two
// modules linked at once could both ask the process for `sinf`, and the second
// definition failed the whole batch ("Duplicate definition of symbol 'sinf'").
TEST_CASE("a library symbol another link defined in the meantime is skipped, the rest defined") {
    llvm::orc::ExecutionSession session(std::make_unique<llvm::orc::UnsupportedExecutorProcessControl>());
    llvm::orc::JITDylib& jd = session.createBareJITDylib("main");
    auto symbol = [](void* address) {
        return llvm::orc::ExecutorSymbolDef(llvm::orc::ExecutorAddr::fromPtr(address), llvm::JITSymbolFlags::Exported);
    };
    auto sinf = session.intern("sinf"), cosf = session.intern("cosf");
    // (Stand-ins: taking libm's own addresses here would make this executable export
    // them, which hides them from the JIT's process lookups under ASan.)
    static int sine = 0, cosine = 0;
    REQUIRE_FALSE(llvm::errorToBool(codegen_llvm::defineMissing(jd, {{sinf, symbol(&sine)}})));
    llvm::orc::SymbolMap both{{sinf, symbol(&sine)}, {cosf, symbol(&cosine)}};
    CHECK(llvm::toString(jd.define(llvm::orc::absoluteSymbols(both))).find("Duplicate definition") != std::string::npos);
    CHECK_FALSE(llvm::errorToBool(codegen_llvm::defineMissing(jd, both)));
    auto found = session.lookup({&jd}, cosf);
    REQUIRE(bool(found));
    CHECK(found->getAddress().toPtr<void*>() == &cosine);
    CHECK_FALSE(llvm::errorToBool(session.endSession()));
}

namespace {

// A unit whose function `name` (float → float) is what `body` builds from its argument.
using Body = std::function<llvm::Value*(llvm::IRBuilder<>&, llvm::Module&, llvm::Value*)>;
codegen_llvm::JitEngine::Unit floatKernel(const codegen_llvm::JitEngine& jit, const std::string& name, const Body& body) {
    codegen_llvm::JitEngine::Unit unit{jit.newContext(), nullptr, name};
    unit.module = jit.newModule(*unit.context);
    llvm::Type* f32 = llvm::Type::getFloatTy(*unit.context);
    auto* f = llvm::Function::Create(llvm::FunctionType::get(f32, {f32}, false), llvm::Function::ExternalLinkage, name,
                                     *unit.module);
    llvm::IRBuilder<> b(llvm::BasicBlock::Create(*unit.context, "entry", f));
    b.CreateRet(body(b, *unit.module, f->getArg(0)));
    return unit;
}

}  // namespace

// Some kernels of an add are still compiling when another fails to link: the engine that
// threw must wait for them when it goes (ASan saw them use it after it had gone).
TEST_CASE("a kernel that cannot link fails its add with LLVM's error, and the engine goes cleanly") {
    for (int round = 0; round < 4; ++round) {
        codegen_llvm::JitEngine jit(codegen_llvm::MathMode::Exact);
        std::vector<codegen_llvm::JitEngine::Unit> units;
        for (int i = 0; i < 8; ++i)
            units.push_back(floatKernel(jit, "kernel" + std::to_string(i), [&](auto& b, llvm::Module& m, llvm::Value* x) {
                llvm::Type* f32 = x->getType();
                if (i == 0)  // quick to compile, and fails
                    return static_cast<llvm::Value*>(b.CreateCall(
                        m.getOrInsertFunction("psys_no_such_function", llvm::FunctionType::get(f32, {f32}, false)), {x}));
                llvm::Value* a = x;  // the others still compiling then
                for (int k = 0; k < 4000; ++k) a = b.CreateFAdd(b.CreateFMul(a, x), llvm::ConstantFP::get(f32, k));
                return a;
            }));
        std::string error;
        try {
            jit.add(std::move(units));
        } catch (const std::runtime_error& e) {
            error = e.what();
        }
        CHECK(error.find("kernel0") != std::string::npos);
    }
}

TEST_CASE("kernels linked at once that call the same libm functions all link") {
    const char* names[] = {"sinf", "cosf", "expf", "logf", "tanf", "sqrtf", "atan2f", "powf"};
    for (codegen_llvm::MathMode mode : {codegen_llvm::MathMode::Exact, codegen_llvm::MathMode::Fast}) {
        for (int round = 0; round < 8; ++round) {
            codegen_llvm::JitEngine jit(mode);
            std::vector<codegen_llvm::JitEngine::Unit> units;
            for (int i = 0; i < 12; ++i)
                units.push_back(floatKernel(jit, "kernel" + std::to_string(i), [&](auto& b, llvm::Module& m, llvm::Value* x) {
                    llvm::Type* f32 = x->getType();
                    auto* one = llvm::FunctionType::get(f32, {f32}, false);
                    auto* two = llvm::FunctionType::get(f32, {f32, f32}, false);
                    for (int k = 0; k < 8; ++k) {  // each module asks in its own order
                        std::string name = names[(i + k) % 8];
                        bool binary = name == "atan2f" || name == "powf";
                        auto callee = m.getOrInsertFunction(name, binary ? two : one);
                        x = binary ? b.CreateCall(callee, {x, x}) : b.CreateCall(callee, {x});
                    }
                    return x;
                }));
            std::vector<void*> kernels;
            CHECK_NOTHROW(kernels = jit.add(std::move(units)));
            CHECK(kernels.size() == 12);
        }
    }
}

namespace {

// Everything written to stderr while `body` runs.
std::string stderrOf(const std::function<void()>& body) {
    std::fflush(stderr);
    char path[] = "/tmp/psys-stderr-XXXXXX";
    int file = mkstemp(path);
    REQUIRE(file >= 0);
    int saved = dup(2);
    dup2(file, 2);
    body();
    std::fflush(stderr);
    dup2(saved, 2);
    close(saved);
    close(file);
    std::ifstream in(path);
    std::ostringstream text;
    text << in.rdbuf();
    std::filesystem::remove(path);
    return text.str();
}

}  // namespace

// What a task holds (a materialization unit's symbol names) must be gone when shutdown()
// returns, or the session that goes next finds its names still referenced (an abort in
// CI's ASan run: "Dangling references at pool destruction time"). LLVM 19's own
// dispatcher frees a thread's last task after counting it done: with it in place of
// CompileThreads this fails.
TEST_CASE("the JIT's compile threads free every task before shutdown returns") {
    struct Slow {
        std::atomic<int>* freed;
        ~Slow() {
            if (!freed) return;
            std::this_thread::sleep_for(std::chrono::milliseconds(20));
            ++*freed;
        }
        Slow(std::atomic<int>* f) : freed(f) {}
        Slow(Slow&& o) noexcept : freed(o.freed) { o.freed = nullptr; }
    };
    std::atomic<int> freed = 0, ran = 0;
    codegen_llvm::CompileThreads threads(2);
    for (int i = 0; i < 6; ++i)
        threads.dispatch(llvm::orc::makeGenericNamedTask([slow = Slow(&freed), &ran]() { ++ran; }, "slow to free"));
    threads.shutdown();
    CHECK(ran == 6);
    CHECK(freed == 6);
}

// LLVM 19 completes a lookup in a task of its own: `add` can return while the compile
// thread that emitted the last module still tears its link down, and an engine that goes
// at once must wait for that thread before the session removes its dylibs, or the thread
// finds its resource tracker defunct ("JIT session error") and frees into a dylib being
// cleared (psys_bench's compile loop aborted in CI, "corrupted double-linked list"). A
// thread per core kept busy widens the window as CI's other tests do: without the wait
// this failed 11 runs of 16 on 2 cores; with it, none of 10.
TEST_CASE("a backend that goes right after compiling waits for the compile threads' last work") {
    std::vector<std::string> texts;
    for (auto& entry : std::filesystem::directory_iterator(PSYS_SAMPLES_DIR))
        if (entry.path().extension() == ".psys") texts.push_back(sample(entry.path().stem().string()));
    std::vector<ir::Module> modules;
    for (const std::string& text : texts) modules.push_back(compile(text));
    std::atomic<bool> done = false;
    std::vector<std::thread> busy;
    for (unsigned core = 0; core < std::max(1u, std::thread::hardware_concurrency()); ++core)
        busy.emplace_back([&] {
            volatile double x = 0;
            while (!done) x = x + 1;
        });
    std::string said = stderrOf([&] {
        for (int round = 0; round < 4; ++round)
            for (const ir::Module& module : modules) {
                codegen_llvm::LlvmBackend backend;
                rt::System system(module, backend);
            }
    });
    done = true;
    for (std::thread& t : busy) t.join();
    CHECK(said.find("JIT session error") == std::string::npos);
    CHECK(said.empty());
}
