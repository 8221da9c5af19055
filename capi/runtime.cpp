// The C API (include/psys/psys.h) on a running system, however it was made (capi/handle.h):
// stepped, set, fired, drawn and read by a C host. Every entry point checks its arguments
// and turns what the layers below throw into an error value.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "capi/handle.h"
#include "core/log.h"

using psys::capi::guarded;
using psys::capi::makeError;
using psys::capi::nullArgument;
using psys::capi::orError;
namespace rt = psys::rt;


namespace {

// The project's version (CMakeLists.txt), which the header's must be.
constexpr const char* kVersion = PSYS_LIBRARY_VERSION;
static_assert(PSYS_VERSION_MAJOR == PSYS_LIBRARY_MAJOR && PSYS_VERSION_MINOR == PSYS_LIBRARY_MINOR &&
                  PSYS_VERSION_PATCH == PSYS_LIBRARY_PATCH,
              "include/psys/psys.h's version is the project's (CMakeLists.txt)");


psys_error* badType(const char* function, const psys_system* s, size_t type) {
    return makeError(fmt::format("{}: there is no object type {} (the system has {})", function, type,
                                 s->system().typeCount()));
}

psys_column column(const rt::Memory& memory, rt::Buffer b, float constant) {
    if (!b.valid()) return {nullptr, 0, constant};
    if (unsigned gl = memory.glBuffer(b)) return {nullptr, gl, 0};
    return {memory.view(b), 0, 0};
}

}  // namespace

void psys_system::describe() {
    const psys::ir::Module& m = system().module();
    externTypes.clear();
    for (const psys::ir::Extern& e : m.externs) externTypes.push_back(rt::languageName(e));
    eventNames = system().eventNames();
    triggerTypes.clear();
    for (const psys::ir::Trigger& t : m.triggers) {
        std::string types;
        for (const psys::ir::Param& p : t.hostParams()) types += (types.empty() ? "" : ", ") + rt::languageName(p);
        triggerTypes.push_back(types);
    }
}

namespace psys::capi {

psys_error* readOptions(const char* function, const psys_options* given, Options& out) {
    psys_options o;
    psys_options_init_size(&o, sizeof o);
    if (given) {
        // An earlier header's options are a prefix of these (the rest keep the defaults);
        // a later header's are not this library's to read.
        // The sizes headers have had: 0.2's, the first with a size, then 0.3's with the
        // allocator (a later one adds fields at the end, and this list its size).
        static constexpr uint32_t kPublished[] = {offsetof(psys_options, allocator), sizeof(psys_options)};
        if (given->size == 0)
            return makeError(fmt::format("{}: psys_options.size is 0: psys_options_init(&options) sets it before the "
                                         "fields are changed",
                                         function));
        if (given->size > sizeof(psys_options))
            return makeError(fmt::format("{}: the options are {} bytes, from a later header than this library's ({} "
                                         "bytes, version {}): build the host against this library's header",
                                         function, given->size, sizeof(psys_options), kVersion));
        if (std::find(std::begin(kPublished), std::end(kPublished), given->size) == std::end(kPublished))
            return makeError(fmt::format("{}: psys_options.size is {}, the size of no header's options: "
                                         "psys_options_init(&options) sets it",
                                         function, given->size));
        std::memcpy(&o, given, given->size);
    }
    out.backend = o.backend ? o.backend : "llvm";
    out.math = o.math ? o.math : "fast";
    if (o.capacity == 0 || o.capacity > 4294967295u)  // the language's own limit (@capacity)
        return makeError(fmt::format("{}: the capacity is 1 to 4294967295 objects a type, not {}", function, o.capacity));
    if (o.threads > rt::SystemOptions::kMostThreads)
        return makeError(fmt::format("{}: threads is 0 (every core) to {}, not {}", function,
                                     rt::SystemOptions::kMostThreads, o.threads));
    out.system.seed = o.seed;
    out.system.capacity = o.capacity;
    out.system.threads = o.threads;
    if (!o.allocator.allocate != !o.allocator.release)
        return makeError(fmt::format("{}: psys_options.allocator needs both allocate and release (or neither, for the "
                                     "library's own)",
                                     function));
    out.system.allocator = {o.allocator.allocate, o.allocator.release, o.allocator.user};
    out.optimize = o.optimize != 0;
    if (o.jit_cache) out.jitCache = o.jit_cache;
    if (o.library_path)
        for (std::string_view rest = o.library_path; !rest.empty();) {
            size_t colon = std::min(rest.find(':'), rest.size());
            if (colon > 0) out.libraryPath.emplace_back(rest.substr(0, colon));
            rest.remove_prefix(std::min(colon + 1, rest.size()));
        }
    return nullptr;
}

}  // namespace psys::capi

extern "C" {

const char* psys_version(void) { return kVersion; }

void psys_options_init_size(psys_options* given, size_t size) {
    if (!given || size < sizeof(uint32_t)) return;
    rt::SystemOptions defaults;
    psys_options o{sizeof(psys_options), "llvm", "fast", defaults.seed, defaults.capacity, defaults.threads, 1,
                   nullptr, nullptr, {}};
    // The host's struct: what this library knows of it (an earlier header's is a prefix),
    // the rest (a later header's fields) zero; `size` the host's, which says which it is.
    std::memset(static_cast<void*>(given), 0, size);
    std::memcpy(static_cast<void*>(given), &o, std::min(size, sizeof o));
    given->size = static_cast<uint32_t>(size);
}

void psys_set_log(psys_log_function log, void* user) {
    if (!log) {
        psys::core::setLogSink({});
        return;
    }
    psys::core::setLogSink([log, user](psys::core::LogLevel level, std::string_view message) {
        psys_severity severity = level == psys::core::LogLevel::Error     ? PSYS_SEVERITY_ERROR
                                 : level == psys::core::LogLevel::Warning ? PSYS_SEVERITY_WARNING
                                                                          : PSYS_SEVERITY_NOTE;
        std::string text(message);
        log(user, severity, text.c_str());
    });
}

void psys_system_free(psys_system* system) { delete system; }

psys_error* psys_reload(psys_system* s, const char* source) {
    if (!s) return nullArgument("psys_reload", "the system");
    return guarded("psys_reload", [&] { return s->reload(source); });
}

size_t psys_warning_count(const psys_system* s) { return s ? s->warnings.size() : 0; }

int psys_warning(const psys_system* s, size_t index, psys_diagnostic* out) {
    if (!s || !out || index >= s->warnings.size()) return -1;
    *out = s->warnings[index].view();
    return 0;
}

psys_error* psys_step(psys_system* s, double dt) {
    if (!s) return nullArgument("psys_step", "the system");
    return guarded("psys_step", [&] { return orError("psys_step", s->system().step(dt)); });
}

psys_error* psys_reserve(psys_system* s, size_t type, size_t rows) {
    if (!s) return nullArgument("psys_reserve", "the system");
    if (type >= s->system().typeCount()) return badType("psys_reserve", s, type);
    return guarded("psys_reserve", [&] { return orError("psys_reserve", s->system().reserve(type, rows)); });
}

psys_error* psys_prewarm(psys_system* s, double seconds, double longest_step) {
    if (!s) return nullArgument("psys_prewarm", "the system");
    return guarded("psys_prewarm", [&] { return orError("psys_prewarm", s->system().prewarm(seconds, longest_step)); });
}

psys_error* psys_reset(psys_system* s) {
    if (!s) return nullArgument("psys_reset", "the system");
    return guarded("psys_reset", [&]() -> psys_error* {
        s->system().reset();
        return nullptr;
    });
}

double psys_time(const psys_system* s) { return s ? s->system().time() : 0; }
uint64_t psys_step_count(const psys_system* s) { return s ? s->system().stepCount() : 0; }

int psys_finished(const psys_system* s) {
    if (!s) return 0;
    try {
        return s->system().finished() ? 1 : 0;
    } catch (...) {
        return 0;
    }
}

psys_error* psys_set_extern(psys_system* s, const char* name, const float* values, size_t count) {
    if (!s) return nullArgument("psys_set_extern", "the system");
    if (!name) return nullArgument("psys_set_extern", "the extern's name");
    if (!values && count) return nullArgument("psys_set_extern", "the values");
    return guarded("psys_set_extern", [&] {
        return orError("psys_set_extern", s->system().setExtern(name, std::span<const float>(values, count)));
    });
}

int psys_get_extern(const psys_system* s, const char* name, float values[4]) {
    if (!s || !name) return -1;
    int index = s->system().externHandle(name);
    if (index < 0) return -1;
    int width = s->system().module().externs[static_cast<size_t>(index)].type.width;
    if (values) {
        auto v = *s->system().externValue(name);
        for (int c = 0; c < width; ++c) values[c] = v.f[static_cast<size_t>(c)];
    }
    return width;
}

psys_error* psys_fire(psys_system* s, const char* trigger, const float* args, size_t count) {
    if (!s) return nullArgument("psys_fire", "the system");
    if (!trigger) return nullArgument("psys_fire", "the trigger's name");
    if (!args && count) return nullArgument("psys_fire", "the arguments");
    return guarded("psys_fire", [&] {
        return orError("psys_fire", s->system().fire(trigger, std::span<const float>(args, count)));
    });
}

size_t psys_type_count(const psys_system* s) { return s ? s->system().typeCount() : 0; }

const char* psys_type_name(const psys_system* s, size_t type) {
    if (!s || type >= s->system().typeCount()) return nullptr;
    return s->system().module().objects[type].name.c_str();
}

int psys_type_index(const psys_system* s, const char* name) { return s && name ? s->system().typeIndex(name) : -1; }

size_t psys_extern_count(const psys_system* s) { return s ? s->system().module().externs.size() : 0; }

int psys_extern_info(const psys_system* s, size_t index, psys_input* out) {
    if (!s || !out || index >= psys_extern_count(s)) return -1;
    const psys::ir::Extern& e = s->system().module().externs[index];
    *out = {e.name.c_str(), s->externTypes[index].c_str(), static_cast<size_t>(e.type.width)};
    return 0;
}

size_t psys_trigger_count(const psys_system* s) { return s ? s->system().module().triggers.size() : 0; }

int psys_trigger_info(const psys_system* s, size_t index, psys_input* out) {
    if (!s || !out || index >= psys_trigger_count(s)) return -1;
    const psys::ir::Trigger& t = s->system().module().triggers[index];
    size_t values = 0;
    for (const psys::ir::Param& p : t.hostParams()) values += static_cast<size_t>(p.type.width);
    *out = {t.name.c_str(), s->triggerTypes[index].c_str(), values};
    return 0;
}

psys_error* psys_get_draw(psys_system* s, size_t type, psys_draw* out) {
    if (!s) return nullArgument("psys_get_draw", "the system");
    if (!out) return nullArgument("psys_get_draw", "the place for the columns (out)");
    if (type >= s->system().typeCount()) return badType("psys_get_draw", s, type);
    return guarded("psys_get_draw", [&]() -> psys_error* {
        const rt::DrawColumns& c = s->system().draw(type);
        const rt::Memory& m = s->system().backend().memory();
        psys_draw d{};
        d.rows = c.rows;
        d.drawn = c.counted ? c.drawn : std::numeric_limits<size_t>::max();
        d.visible = column(m, c.visible, 0);
        d.ids = column(m, c.ids, 0);
        d.instance = column(m, c.instance, 0);
        const auto values = c.values();
        psys_column* into[rt::DrawColumns::kValues] = {&d.position[0], &d.position[1], &d.position[2], &d.color[0],
                                                       &d.color[1],    &d.color[2],    &d.color[3],    &d.size,
                                                       &d.rotation,    &d.frame,       &d.end[0],      &d.end[1],
                                                       &d.end[2]};
        for (size_t k = 0; k < values.size(); ++k) *into[k] = column(m, values[k], c.constant[k]);
        *out = d;
        return nullptr;
    });
}

psys_error* psys_read_points(psys_system* s, size_t type, psys_point* out, size_t max, size_t* count) {
    if (!s) return nullArgument("psys_read_points", "the system");
    if (!out && max) return nullArgument("psys_read_points", "the points (out)");
    if (type >= s->system().typeCount()) return badType("psys_read_points", s, type);
    return guarded("psys_read_points", [&]() -> psys_error* {
        std::vector<rt::RenderPoint> points = s->system().points(type);
        if (count) *count = points.size();
        for (size_t i = 0; i < points.size() && i < max; ++i) {
            const rt::RenderPoint& p = points[i];
            out[i] = {p.id, {p.position[0], p.position[1], p.position[2]}, {p.color[0], p.color[1], p.color[2], p.color[3]},
                      p.size};
        }
        return nullptr;
    });
}

psys_error* psys_get_stats(const psys_system* s, psys_stats* out) {
    if (!s) return nullArgument("psys_get_stats", "the system");
    if (!out) return nullArgument("psys_get_stats", "the place for the stats (out)");
    return guarded("psys_get_stats", [&]() -> psys_error* {
        rt::Stats& st = s->stats;
        s->system().stats(st);
        *out = {st.steps,          st.rejectedSteps,   st.nonFiniteExterns + st.outOfRangeExterns,
                st.invalidEmissions, st.nonFiniteRender, st.loopSeconds,
                st.emitSeconds,    st.createSeconds,   st.drawSeconds,
                st.foldSeconds};
        return nullptr;
    });
}

psys_error* psys_get_type_stats(const psys_system* s, size_t type, psys_type_stats* out) {
    if (!s) return nullArgument("psys_get_type_stats", "the system");
    if (!out) return nullArgument("psys_get_type_stats", "the place for the stats (out)");
    if (type >= s->system().typeCount()) return badType("psys_get_type_stats", s, type);
    return guarded("psys_get_type_stats", [&]() -> psys_error* {
        rt::Stats& st = s->stats;
        s->system().stats(st);
        const rt::TypeStats& t = st.types.at(type);
        *out = {t.live, t.created, t.killed, t.dropped, t.unstable};
        return nullptr;
    });
}

}  // extern "C"
