// The C API (include/psys/psys.h) as a host calls it: systems compiled from files and
// strings, run on every backend, their draws read without a copy; every bad input an
// error value with its message, nothing changed and nothing crashed.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <cmath>
#include <cstddef>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "driver/compile.h"
#include "ir/printer.h"
#include "psys/psys.h"

#include <unistd.h>

namespace {

const std::string kSamples = PSYS_SAMPLES_DIR;

// The message of an error (freed), or "" for none.
std::string take(psys_error* e) {
    std::string m = e ? psys_error_message(e) : "";
    psys_error_free(e);
    return m;
}

struct System {
    psys_system* s = nullptr;
    ~System() { psys_system_free(s); }
};

psys_options options(const char* backend, const char* math = "fast") {
    psys_options o;
    psys_options_init(&o);
    o.backend = backend;
    o.math = math;
    return o;
}

// tests/programs/beads.psys, read once.
std::string readBeads() {
    std::ifstream in(std::string(PSYS_PROGRAMS_DIR) + "/beads.psys");
    return {std::istreambuf_iterator<char>(in), {}};
}
const std::string kBeadsText = readBeads();
const char* const kDots = kBeadsText.c_str();

std::vector<psys_point> points(psys_system* s, size_t type) {
    size_t n = 0;
    REQUIRE(take(psys_read_points(s, type, nullptr, 0, &n)).empty());
    std::vector<psys_point> out(n);
    REQUIRE(take(psys_read_points(s, type, out.data(), out.size(), &n)).empty());
    return out;
}

}  // namespace

TEST_CASE("a system compiled from a string runs, and its draw columns are the points it draws, with no copy") {
    System sys;
    psys_options o = options("llvm", "exact");
    REQUIRE(take(psys_compile_string(kDots, "dots.psys", &o, &sys.s)) == "");
    CHECK(psys_type_count(sys.s) == 2);
    int dot = psys_type_index(sys.s, "bead");
    REQUIRE(dot >= 0);
    CHECK(std::string(psys_type_name(sys.s, static_cast<size_t>(dot))) == "bead");
    CHECK(psys_type_name(sys.s, 2) == nullptr);
    CHECK(psys_type_index(sys.s, "nothing") == -1);
    for (int f = 0; f < 30; ++f) REQUIRE(take(psys_step(sys.s, 1.0 / 60)) == "");
    CHECK(psys_step_count(sys.s) == 30);
    CHECK(psys_time(sys.s) == doctest::Approx(0.5));

    psys_draw d;
    REQUIRE(take(psys_get_draw(sys.s, static_cast<size_t>(dot), &d)) == "");
    std::vector<psys_point> expected = points(sys.s, static_cast<size_t>(dot));
    CHECK(expected.size() == 30);
    CHECK(d.drawn == 30);
    REQUIRE(d.visible.data);
    REQUIRE(d.position[0].data);
    CHECK(d.visible.gl_buffer == 0);
    // The size is the same for every bead: a constant, not a column.
    CHECK(d.size.data == nullptr);
    CHECK(d.size.gl_buffer == 0);
    CHECK(d.size.constant == 2.0f);
    auto* visible = static_cast<const float*>(d.visible.data);
    auto* x = static_cast<const float*>(d.position[0].data);
    auto* ids = static_cast<const uint32_t*>(d.ids.data);
    size_t k = 0;
    for (size_t r = 0; r < d.rows; ++r) {
        if (visible[r] != 1.0f) continue;
        REQUIRE(k < expected.size());
        CHECK(ids[r] == expected[k].id);
        CHECK(x[r] == expected[k].position[0]);
        ++k;
    }
    CHECK(k == expected.size());
    // Read again: the same memory, not a copy made for the call.
    psys_draw again;
    REQUIRE(take(psys_get_draw(sys.s, static_cast<size_t>(dot), &again)) == "");
    CHECK(again.position[0].data == d.position[0].data);

    psys_stats st;
    REQUIRE(take(psys_get_stats(sys.s, &st)) == "");
    CHECK(st.steps == 30);
    psys_type_stats ts;
    REQUIRE(take(psys_get_type_stats(sys.s, static_cast<size_t>(dot), &ts)) == "");
    CHECK(ts.created == 30);
    CHECK(ts.live == 30);
    CHECK(psys_finished(sys.s) == 0);
}

TEST_CASE("a sample runs the same through the C API on the JIT in exact maths and on the interpreter, bit for bit") {
    System jit, interp;
    psys_options a = options("llvm", "exact"), b = options("interp");
    std::string path = kSamples + "/fountain.psys";
    REQUIRE(take(psys_compile_file(path.c_str(), &a, &jit.s)) == "");
    REQUIRE(take(psys_compile_file(path.c_str(), &b, &interp.s)) == "");
    size_t compared = 0;
    for (int f = 0; f < 120; ++f) {
        REQUIRE(take(psys_step(jit.s, 1.0 / 60)) == "");
        REQUIRE(take(psys_step(interp.s, 1.0 / 60)) == "");
        if (f % 20 != 19) continue;
        for (size_t t = 0; t < psys_type_count(jit.s); ++t) {
            std::vector<psys_point> p = points(jit.s, t), q = points(interp.s, t);
            REQUIRE(p.size() == q.size());
            if (!p.empty()) CHECK(std::memcmp(p.data(), q.data(), p.size() * sizeof(psys_point)) == 0);
            compared += p.size();
        }
    }
    CHECK(compared > 1000);
}

TEST_CASE("a program with errors gives every diagnostic with its file, line and column, and no system") {
    psys_system* s = reinterpret_cast<psys_system*>(1);
    psys_error* e = psys_compile_string("object a {\n    point(vec3(0), red, nope);\n}\nspawn a;\n", "bad.psys",
                                        nullptr, &s);
    REQUIRE(e);
    CHECK(s == nullptr);
    std::string m = psys_error_message(e);
    CHECK(m.find("bad.psys:2:") != std::string::npos);
    CHECK(m.find("nope") != std::string::npos);
    REQUIRE(psys_error_diagnostic_count(e) >= 1);
    psys_diagnostic d;
    REQUIRE(psys_error_diagnostic(e, 0, &d) == 0);
    CHECK(d.severity == PSYS_SEVERITY_ERROR);
    CHECK(std::string(d.file) == "bad.psys");
    CHECK(d.line == 2);
    CHECK(d.column == 25);
    CHECK(d.end_column == 29);
    CHECK(std::string(d.message).find("nope") != std::string::npos);
    CHECK(psys_error_diagnostic(e, 99, &d) == -1);
    psys_error_free(e);

    e = psys_compile_file("/no/such/file.psys", nullptr, &s);
    REQUIRE(e);
    CHECK(std::string(psys_error_message(e)).find("/no/such/file.psys") != std::string::npos);
    psys_error_free(e);
}

TEST_CASE("a warning does not stop a system: it is kept with the system, located") {
    System sys;
    REQUIRE(take(psys_compile_string("object a {\n    unused = 1;\n    point(vec3(0), red, 1);\n}\nspawn a;\n", "w.psys",
                                     nullptr, &sys.s)) == "");
    REQUIRE(psys_warning_count(sys.s) == 1);
    psys_diagnostic d;
    REQUIRE(psys_warning(sys.s, 0, &d) == 0);
    CHECK(d.severity == PSYS_SEVERITY_WARNING);
    CHECK(d.line == 2);
    CHECK(std::string(d.message).find("never used") != std::string::npos);
    CHECK(psys_warning(sys.s, 1, &d) == -1);
}

TEST_CASE("externs and triggers: described, set and fired by name, and a wrong name, count or value refused, changing nothing") {
    System sys;
    REQUIRE(take(psys_compile_string(kDots, nullptr, nullptr, &sys.s)) == "");
    REQUIRE(psys_extern_count(sys.s) == 2);
    psys_input in;
    REQUIRE(psys_extern_info(sys.s, 1, &in) == 0);
    CHECK(std::string(in.name) == "tint");
    CHECK(std::string(in.type) == "color");
    CHECK(in.values == 4);
    CHECK(psys_extern_info(sys.s, 2, &in) == -1);
    REQUIRE(psys_trigger_count(sys.s) == 1);
    REQUIRE(psys_trigger_info(sys.s, 0, &in) == 0);
    CHECK(std::string(in.name) == "burst");
    CHECK(std::string(in.type) == "vec3, float");
    CHECK(in.values == 4);

    float two = 2, nan = NAN, eleven = 11, v[4] = {};
    CHECK(take(psys_set_extern(sys.s, "speed", &two, 1)) == "");
    CHECK(psys_get_extern(sys.s, "speed", v) == 1);
    CHECK(v[0] == 2);
    CHECK(take(psys_set_extern(sys.s, "sped", &two, 1)) == "psys_set_extern: there is no extern `sped`");
    CHECK(take(psys_set_extern(sys.s, "speed", v, 3)).find("takes 1 value, not 3") != std::string::npos);
    CHECK(take(psys_set_extern(sys.s, "speed", &nan, 1)).find("finite") != std::string::npos);
    CHECK(take(psys_set_extern(sys.s, "speed", &eleven, 1)).find("outside its range") != std::string::npos);
    CHECK(psys_get_extern(sys.s, "speed", v) == 1);
    CHECK(v[0] == 2);  // kept
    CHECK(psys_get_extern(sys.s, "sped", v) == -1);
    psys_stats st;
    REQUIRE(take(psys_get_stats(sys.s, &st)) == "");
    CHECK(st.rejected_externs == 2);

    float args[4] = {0, 0, 0, 5};
    CHECK(take(psys_fire(sys.s, "burst", args, 4)) == "");
    CHECK(take(psys_fire(sys.s, "bust", args, 4)).find("bust") != std::string::npos);
    CHECK(!take(psys_fire(sys.s, "burst", args, 2)).empty());
    args[3] = NAN;
    CHECK(!take(psys_fire(sys.s, "burst", args, 4)).empty());
    psys_type_stats ts;
    REQUIRE(take(psys_get_type_stats(sys.s, 0, &ts)) == "");
    CHECK(ts.created == 5);  // the first burst alone
}

TEST_CASE("a step of NaN, an infinity or a negative time is refused and counted, and 0 moves nothing") {
    System sys;
    REQUIRE(take(psys_compile_string(kDots, nullptr, nullptr, &sys.s)) == "");
    CHECK(take(psys_step(sys.s, NAN)).find("finite, non-negative") != std::string::npos);
    CHECK(!take(psys_step(sys.s, INFINITY)).empty());
    CHECK(!take(psys_step(sys.s, -1)).empty());
    CHECK(take(psys_step(sys.s, 0)) == "");
    CHECK(psys_time(sys.s) == 0);
    psys_stats st;
    REQUIRE(take(psys_get_stats(sys.s, &st)) == "");
    CHECK(st.rejected_steps == 3);
}

TEST_CASE("NULL handles and arguments, an unknown type and bad options are errors that name the call, never a crash") {
    float one = 1;
    psys_draw d;
    psys_stats st;
    psys_type_stats ts;
    psys_system* out = nullptr;
    CHECK(take(psys_step(nullptr, 1)) == "psys_step: the system is NULL");
    CHECK(take(psys_set_extern(nullptr, "a", &one, 1)) == "psys_set_extern: the system is NULL");
    CHECK(take(psys_fire(nullptr, "a", &one, 1)) == "psys_fire: the system is NULL");
    CHECK(take(psys_reload(nullptr, "")) == "psys_reload: the system is NULL");
    CHECK(take(psys_get_draw(nullptr, 0, &d)) == "psys_get_draw: the system is NULL");
    CHECK(take(psys_get_stats(nullptr, &st)) == "psys_get_stats: the system is NULL");
    CHECK(take(psys_get_type_stats(nullptr, 0, &ts)) == "psys_get_type_stats: the system is NULL");
    CHECK(take(psys_read_points(nullptr, 0, nullptr, 0, nullptr)) == "psys_read_points: the system is NULL");
    CHECK(take(psys_compile_file(nullptr, nullptr, &out)) == "psys_compile_file: the path is NULL");
    CHECK(take(psys_compile_string(nullptr, nullptr, nullptr, &out)) == "psys_compile_string: the source is NULL");
    CHECK(!take(psys_compile_string(kDots, nullptr, nullptr, nullptr)).empty());
    CHECK(psys_type_count(nullptr) == 0);
    CHECK(psys_type_name(nullptr, 0) == nullptr);
    CHECK(psys_time(nullptr) == 0);
    CHECK(psys_finished(nullptr) == 0);
    CHECK(psys_get_extern(nullptr, "a", nullptr) == -1);
    CHECK(std::string(psys_error_message(nullptr)).empty());
    psys_error_free(nullptr);
    psys_system_free(nullptr);
    psys_options_init(nullptr);

    System sys;
    REQUIRE(take(psys_compile_string(kDots, nullptr, nullptr, &sys.s)) == "");
    CHECK(take(psys_get_draw(sys.s, 7, &d)) == "psys_get_draw: there is no object type 7 (the system has 2)");
    CHECK(take(psys_get_draw(sys.s, 0, nullptr)).find("NULL") != std::string::npos);
    CHECK(take(psys_set_extern(sys.s, nullptr, &one, 1)).find("NULL") != std::string::npos);
    CHECK(take(psys_set_extern(sys.s, "speed", nullptr, 1)).find("NULL") != std::string::npos);

    psys_options o = options("vulkan");
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &out)).find("there is no backend `vulkan`") != std::string::npos);
    o = options("llvm", "sloppy");
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &out)).find("fast or exact") != std::string::npos);
    o = options("llvm");
    o.capacity = 0;
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &out)).find("capacity") != std::string::npos);
    o = options("llvm");
    o.capacity = SIZE_MAX;  // once "a capacity of 18446744073709551616 needs …"
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &out)) ==
          "psys_compile_string: the capacity is 1 to 4294967295 objects a type, not 18446744073709551615");
    o = options("llvm");
    o.threads = 257;  // TBB's limit: once taken
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &out)) == "psys_compile_string: threads is 0 (every core) to 256, not 257");
    CHECK(take(psys_compile_file("no/such.psys", nullptr, &out)).rfind("psys: error: cannot read `no/such.psys`", 0) == 0);
    CHECK(out == nullptr);
}

TEST_CASE("a reload keeps the running objects, and one that does not compile changes nothing and says why") {
    System sys;
    REQUIRE(take(psys_compile_string(kDots, "dots.psys", nullptr, &sys.s)) == "");
    for (int f = 0; f < 30; ++f) REQUIRE(take(psys_step(sys.s, 1.0 / 60)) == "");
    CHECK(take(psys_reload(sys.s, nullptr)).find("compiled from a string") != std::string::npos);
    std::string edited = kBeadsText;
    edited.replace(edited.find("point(pos, tint, 2)"), 19, "point(pos, tint, 3)");
    REQUIRE(take(psys_reload(sys.s, edited.c_str())) == "");
    std::vector<psys_point> p = points(sys.s, 0);
    REQUIRE(p.size() == 30);  // the same dots, drawn by the new program
    CHECK(p[0].size == 3);
    CHECK(p[0].id == 1);
    psys_error* e = psys_reload(sys.s, "object dot {");
    REQUIRE(e);
    CHECK(psys_error_diagnostic_count(e) >= 1);
    psys_error_free(e);
    REQUIRE(take(psys_step(sys.s, 1.0 / 60)) == "");
    CHECK(points(sys.s, 0).size() == 31);
    CHECK(psys_step_count(sys.s) == 31);
}

TEST_CASE("a system ends: finished once everything has died") {
    System sys;
    REQUIRE(take(psys_compile_string("object a { point(vec3(0), red, 1); kill when age > 0.1; }\nspawn a;\n", nullptr,
                                     nullptr, &sys.s)) == "");
    CHECK(psys_finished(sys.s) == 0);
    for (int f = 0; f < 20; ++f) REQUIRE(take(psys_step(sys.s, 1.0 / 60)) == "");
    CHECK(psys_finished(sys.s) == 1);
}

TEST_CASE("on the glsl backend the draw columns are GL buffers: nothing comes back to the host") {
    System sys;
    psys_options o = options("glsl");
    std::string path = kSamples + "/fountain.psys";
    psys_error* e = psys_compile_file(path.c_str(), &o, &sys.s);
    if (e && std::string(psys_error_message(e)).find("cannot start") != std::string::npos) {
        MESSAGE("no OpenGL 4.5 here: " << psys_error_message(e));
        psys_error_free(e);
        return;
    }
    REQUIRE(take(e) == "");
    for (int f = 0; f < 30; ++f) REQUIRE(take(psys_step(sys.s, 1.0 / 60)) == "");
    int drop = psys_type_index(sys.s, "drop");
    REQUIRE(drop >= 0);
    psys_draw d;
    REQUIRE(take(psys_get_draw(sys.s, static_cast<size_t>(drop), &d)) == "");
    CHECK(d.rows > 0);
    CHECK(d.visible.gl_buffer != 0);
    CHECK(d.visible.data == nullptr);
    CHECK(d.position[0].gl_buffer != 0);
    CHECK(points(sys.s, static_cast<size_t>(drop)).size() == 500);
}

namespace {

// An AOT build's description around IR text alone, as `psysc build` writes it but with no
// compiled kernels.
std::string irOf(const char* source) {
    psys::SourceManager sources;
    psys::DiagnosticEngine diags(sources);
    psys::CompileOptions options;
    auto module = psys::compileText("x.psys", source, sources, diags, options);
    REQUIRE(module);
    return psys::ir::print(*module);
}

}  // namespace

TEST_CASE("an ahead-of-time build's IR runs on the interpreter, and a build that cannot run says why") {
    std::string ir = irOf(kDots);
    psys_aot_cpu any{"x86-64", "", 0, nullptr};  // a CPU every machine of the triple is: no kernels
    psys_aot aot{PSYS_AOT_ABI, 1, "dots", ir.c_str(), 1, &any, nullptr, "none"};
    System fromAot, compiled;
    psys_options o = options("interp");
    REQUIRE(take(psys_open_aot(&aot, &o, &fromAot.s)) == "");
    REQUIRE(take(psys_compile_string(kDots, "x.psys", &o, &compiled.s)) == "");
    for (int f = 0; f < 30; ++f) {
        REQUIRE(take(psys_step(fromAot.s, 1.0 / 60)) == "");
        REQUIRE(take(psys_step(compiled.s, 1.0 / 60)) == "");
    }
    std::vector<psys_point> p = points(fromAot.s, 0), q = points(compiled.s, 0);
    REQUIRE(p.size() == 30);
    REQUIRE(p.size() == q.size());
    CHECK(std::memcmp(p.data(), q.data(), p.size() * sizeof(psys_point)) == 0);
    CHECK(take(psys_reload(fromAot.s, kDots)).find("does not reload") != std::string::npos);

    psys_system* out = nullptr;
    // No code for its kernels: the compiled backend refuses it, naming what is missing.
    CHECK(take(psys_open_aot(&aot, nullptr, &out)).find("has no code for a kernel of `") != std::string::npos);
    CHECK(out == nullptr);
    // Built for CPUs this one is not: refused, saying what each needs that it lacks.
    psys_aot_cpu future[] = {{"future", "avx512fp16,avx10.2", 0, nullptr}, {"later", "sse4.2,avx10.2", 0, nullptr}};
    psys_aot elsewhere = aot;
    elsewhere.cpus = future;
    elsewhere.cpu_count = 2;
    CHECK(psys_aot_choose_cpu(&elsewhere) == nullptr);
    CHECK(psys_aot_choose_cpu(&aot) == &any);
    CHECK(take(psys_open_aot(&elsewhere, nullptr, &out)) ==
          "psys_open_aot: this CPU runs none of the build's kernels: it was built for future (lacking avx512fp16 "
          "avx10.2), later (lacking avx10.2); build it again with psysc build --cpu naming this machine's CPU (or a "
          "generic one: x86-64-v2), or run its IR with options.backend = \"interp\"");
    CHECK(out == nullptr);
    CHECK(take(psys_open_aot(&elsewhere, &o, &out)).empty());  // its IR still runs on the interpreter
    psys_system_free(out);
    out = nullptr;
    psys_aot old = aot;
    old.abi = 99;
    CHECK(take(psys_open_aot(&old, &o, &out)).find("format is 99") != std::string::npos);
    psys_aot broken = aot;
    broken.ir = "object {";
    CHECK(take(psys_open_aot(&broken, &o, &out)).find("does not read back") != std::string::npos);
    CHECK(take(psys_open_aot(nullptr, &o, &out)) == "psys_open_aot: the build is NULL");
    o = options("vulkan");
    CHECK(take(psys_open_aot(&aot, &o, &out)).find("no backend `vulkan`") != std::string::npos);
}

TEST_CASE("reserve takes room ahead, refuses more than the capacity or an unknown type, and changes no result") {
    psys_options o = options("interp", "exact");
    o.capacity = 5000;
    System a, b;
    REQUIRE(take(psys_compile_string(kDots, "beads.psys", &o, &a.s)).empty());
    REQUIRE(take(psys_compile_string(kDots, "beads.psys", &o, &b.s)).empty());
    CHECK(take(psys_reserve(b.s, 0, 5000)).empty());
    CHECK(take(psys_reserve(b.s, 0, 5001)) == "psys_reserve: bead holds at most 5000 objects (its @capacity, else the "
                                               "options' capacity), not 5001");
    CHECK(take(psys_reserve(b.s, 7, 1)).find("psys_reserve: there is no object type 7") == 0);
    CHECK(take(psys_reserve(nullptr, 0, 1)).find("psys_reserve") == 0);
    for (psys_system* s : {a.s, b.s}) {
        const float args[] = {0, 0, 0, 400};
        REQUIRE(take(psys_fire(s, "burst", args, 4)).empty());
        for (int i = 0; i < 30; ++i) REQUIRE(take(psys_step(s, 1.0 / 60)).empty());
    }
    std::vector<psys_point> pa = points(a.s, 0), pb = points(b.s, 0);
    REQUIRE(pa.size() == pb.size());
    CHECK(std::memcmp(pa.data(), pb.data(), pa.size() * sizeof(psys_point)) == 0);
}

TEST_CASE("options carry their size: unset, unknown or a later header's refused in words") {
    System s;
    psys_options o = options("interp");
    o.size = 0;
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &s.s)) ==
          "psys_compile_string: psys_options.size is 0: psys_options_init(&options) sets it before the fields are changed");
    o.size = sizeof(psys_options) + 8;
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &s.s)).find("from a later header than this library's") !=
          std::string::npos);
    CHECK(s.s == nullptr);
    // A size no header's options have (half a field: an uninitialised size) is refused.
    o.size = offsetof(psys_options, jit_cache) + 4;
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &s.s)).find("the size of no header's options") !=
          std::string::npos);
    CHECK(s.s == nullptr);
    // Init writes no more than the host's struct (here: a later header's, 8 bytes longer,
    // zeroed past what this library knows), and says its size, which is then refused.
    unsigned char later[sizeof(psys_options) + 8];
    std::memset(later, 0xab, sizeof later);
    psys_options_init_size(reinterpret_cast<psys_options*>(later), sizeof later);
    CHECK(later[sizeof(psys_options)] == 0);
    psys_options known;
    std::memcpy(&known, later, sizeof known);
    CHECK(known.size == sizeof later);
    CHECK(std::string(known.backend) == "llvm");
    o = options("interp");
    CHECK(take(psys_compile_string(kDots, nullptr, &o, &s.s)).empty());
    CHECK(s.s != nullptr);
}

namespace {
std::vector<std::string> logged;
void keepLog(void* user, psys_severity severity, const char* message) {
    static_cast<std::vector<std::string>*>(user)->push_back(std::to_string(severity) + " " + message);
}
}  // namespace

TEST_CASE("the JIT's cache folder and the library's folders are options, and what the library says goes to the host's log") {
    namespace fs = std::filesystem;
    fs::path dir = fs::temp_directory_path() / ("psys-capi-options-" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir / "lib" / "std");
    std::ofstream(dir / "lib" / "std" / "mine.psys") << "const far = 40;\n";
    const std::string source = "import \"std/mine.psys\";\nobject a { point(vec3(far), white, 1); }\nspawn a;\n";
    const std::string libs = "/nonexistent:" + (dir / "lib").string();
    {
        System s;
        psys_options o = options("llvm");
        std::string cache = (dir / "cache").string();
        o.jit_cache = cache.c_str();
        o.library_path = libs.c_str();
        REQUIRE(take(psys_compile_string(source.c_str(), "mine_user.psys", &o, &s.s)).empty());
        REQUIRE(take(psys_step(s.s, 1.0 / 60)).empty());
        std::vector<psys_point> p = points(s.s, 0);
        REQUIRE(p.size() == 1);
        CHECK(p[0].position[0] == 40);
        size_t objects = 0;
        for (const auto& e : fs::directory_iterator(dir / "cache")) objects += e.path().extension() == ".o";
        CHECK(objects > 0);  // the kernels kept where the host said
    }
    {
        System s;  // without the folder, the import is not found
        psys_options o = options("interp");
        CHECK(take(psys_compile_string(source.c_str(), "mine_user.psys", &o, &s.s)).find("std/mine.psys") !=
              std::string::npos);
    }
    {
        psys_set_log(keepLog, &logged);
        System s;
        psys_options o = options("llvm");
        o.jit_cache = "/proc/psys-cannot-be-made";
        REQUIRE(take(psys_compile_string(kDots, nullptr, &o, &s.s)).empty());
        REQUIRE(take(psys_step(s.s, 1.0 / 60)).empty());
        psys_set_log(nullptr, nullptr);
        REQUIRE(logged.size() == 1);  // said once, as a warning, to the host's log and not to stderr
        CHECK(logged[0].find("1 the JIT's cache `/proc/psys-cannot-be-made` cannot be made") == 0);
    }
    fs::remove_all(dir);
}

TEST_CASE("a trigger's parameters are described as the program declares them: a point is a point, not a vec3") {
    System s;
    psys_options o = options("interp");
    REQUIRE(take(psys_compile_file((kSamples + "/swamp.psys").c_str(), &o, &s.s)).empty());
    std::map<std::string, std::string> types;
    psys_input in;
    for (size_t i = 0; psys_trigger_info(s.s, i, &in) == 0; ++i) types[in.name] = in.type;
    CHECK(types["fireball"] == "point, vec3");
    CHECK(types["swarm"] == "point");
}

TEST_CASE("a diagnostic's line and column are where its message's caret points") {
    System s;
    psys_options o = options("interp");
    // The operands of `+` disagree: the message and caret point at the `+`, not at `vec3`.
    psys_error* e = psys_compile_string("object a { point(vec3(1) + vec4(1), white, 1); }\nspawn a;\n", "caret.psys", &o, &s.s);
    REQUIRE(e != nullptr);
    psys_diagnostic d;
    REQUIRE(psys_error_diagnostic(e, 0, &d) == 0);
    std::string message = psys_error_message(e);
    CHECK(message.find("caret.psys:1:" + std::to_string(d.column) + ":") != std::string::npos);
    CHECK(d.column == 26);  // the `+`
    CHECK(d.end_column > d.column);
    psys_error_free(e);
}

TEST_CASE("reset goes back to the start and runs the same again, and prewarm runs ahead in equal steps, drawing nothing") {
    for (const char* backend : {"interp", "llvm"}) {
        CAPTURE(backend);
        psys_options o = options(backend, "exact");
        System s, fresh;
        REQUIRE(take(psys_compile_file((kSamples + "/fire.psys").c_str(), &o, &s.s)).empty());
        REQUIRE(take(psys_compile_file((kSamples + "/fire.psys").c_str(), &o, &fresh.s)).empty());
        const float rate = 2000;
        REQUIRE(take(psys_set_extern(s.s, "rate", &rate, 1)).empty());
        REQUIRE(take(psys_set_extern(fresh.s, "rate", &rate, 1)).empty());
        for (int i = 0; i < 40; ++i) REQUIRE(take(psys_step(s.s, 1.0 / 60)).empty());
        REQUIRE(take(psys_reset(s.s)).empty());
        CHECK(psys_time(s.s) == 0);
        CHECK(psys_step_count(s.s) == 0);
        CHECK(points(s.s, 0).empty());
        float kept[4];
        CHECK(psys_get_extern(s.s, "rate", kept) == 1);
        CHECK(kept[0] == rate);  // the host's value stays
        for (psys_system* each : {s.s, fresh.s})
            for (int i = 0; i < 30; ++i) REQUIRE(take(psys_step(each, 1.0 / 60)).empty());
        std::vector<psys_point> a = points(s.s, 0), b = points(fresh.s, 0);
        REQUIRE(a.size() == b.size());
        REQUIRE(!a.empty());
        CHECK(std::memcmp(a.data(), b.data(), a.size() * sizeof(psys_point)) == 0);

        REQUIRE(take(psys_reset(s.s)).empty());
        REQUIRE(take(psys_prewarm(s.s, 2.05, 0.1)).empty());
        CHECK(psys_time(s.s) == doctest::Approx(2.05));
        CHECK(psys_step_count(s.s) == 21);  // 2.05 s in 21 equal steps, none longer than 0.1 s
        psys_type_stats st;
        REQUIRE(take(psys_get_type_stats(s.s, 0, &st)).empty());
        CHECK(st.live > 1000);
        CHECK(take(psys_prewarm(s.s, -1, 0.1)).find("a finite, non-negative number of seconds, not -1") !=
              std::string::npos);
        CHECK(take(psys_prewarm(s.s, 1, 0)).find("a finite, positive number of seconds, not 0") != std::string::npos);
        CHECK(psys_step_count(s.s) == 21);  // refused: nothing moved
        CHECK(take(psys_reset(nullptr)).find("psys_reset") == 0);
    }
}
