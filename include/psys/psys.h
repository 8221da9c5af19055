/* psys: particle systems compiled from .psys programs, embedded in a C or C++ host.
 *
 *   psys_options o;
 *   psys_options_init(&o);                       // the LLVM JIT, fast maths, seed 1
 *   psys_system* sys = NULL;
 *   psys_error* err = psys_compile_file("fountain.psys", &o, &sys);
 *   if (err) { fprintf(stderr, "%s", psys_error_message(err)); psys_error_free(err); return 1; }
 *   for (int frame = 0; frame < 600; ++frame) {
 *       psys_step(sys, 1.0 / 60);                // an error only for a bad dt
 *       psys_draw draw;
 *       psys_get_draw(sys, 0, &draw);            // columns of what type 0 draws
 *       ...
 *   }
 *   psys_system_free(sys);
 *
 * Errors. Every call that can fail returns a psys_error* (NULL: it succeeded) carrying a
 * message and, for a compilation, its diagnostics (file, line, column, text); the caller
 * frees it. Nothing is changed by a call that fails, and no call aborts the host on bad
 * input: a null handle, an unknown name, the wrong number of values, a NaN.
 *
 * Structures. psys_options starts with its size, which psys_options_init sets: a later
 * library reads an earlier header's options (the fields it lacks take their defaults), and
 * refuses a later header's. The other structs change only with the soname's version
 * (libpsys.so.0.MINOR before 1.0, libpsys.so.MAJOR after): a host built against this
 * header runs with any library of the same soname.
 *
 * Threads. A system is used by one thread at a time (any thread on the CPU backends; the
 * thread whose GL context it was made in on the glsl backend). Systems are independent.
 *
 * GL state. On the glsl backend a call that runs the system (psys_step, psys_fire,
 * psys_get_draw, psys_reload, ...) dispatches compute shaders in the current context: it
 * may leave another program and other buffers bound. A host binds its own after it.
 *
 * docs/embedding.md has the whole story and a complete example.
 */
#ifndef PSYS_PSYS_H
#define PSYS_PSYS_H

#include <stddef.h>
#include <stdint.h>

#if defined(__GNUC__)
#define PSYS_API __attribute__((visibility("default")))
#else
#define PSYS_API
#endif

#ifdef __cplusplus
extern "C" {
#endif

#define PSYS_VERSION_MAJOR 0
#define PSYS_VERSION_MINOR 3
#define PSYS_VERSION_PATCH 0

/* The library's version as "MAJOR.MINOR.PATCH" (the header's may differ: a host built
 * against one header and run with a later library of the same major version). */
PSYS_API const char* psys_version(void);

/* ---- Errors ------------------------------------------------------------------------- */

typedef struct psys_error psys_error;

typedef enum psys_severity {
    PSYS_SEVERITY_ERROR = 0,
    PSYS_SEVERITY_WARNING = 1,
    PSYS_SEVERITY_NOTE = 2,
    PSYS_SEVERITY_REMARK = 3
} psys_severity;

/* One diagnostic of a compilation. Its strings live as long as the error (or the system,
 * for psys_warning). line and column count from 1 (column in bytes): where the message's
 * `file:line:column` and caret point; 0 where the diagnostic has no place in a file (a
 * limit, the command line). */
typedef struct psys_diagnostic {
    psys_severity severity;
    const char* file;
    uint32_t line;
    uint32_t column;
    uint32_t end_line; /* where its range ends (exclusive column) */
    uint32_t end_column;
    const char* message;
} psys_diagnostic;

/* The whole message: for a compilation, the diagnostics as psysc prints them (with the
 * source lines); else one sentence. Never NULL for a non-null error. */
PSYS_API const char* psys_error_message(const psys_error* error);
/* A compilation's diagnostics (errors and warnings), 0 for other errors. */
PSYS_API size_t psys_error_diagnostic_count(const psys_error* error);
/* Fills *out with diagnostic `index`; returns 0, or -1 when there is none. */
PSYS_API int psys_error_diagnostic(const psys_error* error, size_t index, psys_diagnostic* out);
PSYS_API void psys_error_free(psys_error* error);

/* ---- Compiling a system ------------------------------------------------------------- */

typedef struct psys_system psys_system;

/* Where a system's particle memory comes from: its columns and its pools' arrays — what
 * grows with its objects (docs/embedding.md, "Allocator"). `allocate` returns `bytes`
 * aligned to `alignment` (a power of two, at most 64), or NULL when it has none (the call
 * that asked then fails with an error that says so); `release` takes back a block with
 * the size it was asked for. Both NULL (the default): the library's own, which takes
 * address space for each type's capacity at the start; with the host's, a pool takes
 * memory only as its objects need it (doubling, with a copy), or up front as
 * psys_reserve asks. It may be called from any of the threads a system's work runs on,
 * several at once (it is thread-safe), and it outlives the system.
 * A compilation's memory and a system's small bookkeeping come from the C++ heap. */
typedef struct psys_allocator {
    void* (*allocate)(void* user, size_t bytes, size_t alignment);
    void (*release)(void* user, void* memory, size_t bytes);
    void* user;
} psys_allocator;

typedef struct psys_options {
    /* sizeof(psys_options) in the header the host was built with: psys_options_init sets
     * it (0 is refused: the options were not initialised). */
    uint32_t size;
    /* "llvm" (the JIT: the default), "interp" (the reference interpreter) or "glsl"
     * (compute shaders on OpenGL 4.5: the GL context current on the calling thread, or a
     * headless one of its own when none is). */
    const char* backend;
    /* "fast" (the default) or "exact": the llvm backend's maths (exact: the interpreter's
     * bits). */
    const char* math;
    uint32_t seed;      /* of every random value: the same seed, the same run */
    size_t capacity;    /* objects per type, unless its @capacity says otherwise */
    unsigned threads;   /* for the CPU backends: 0 for every core; results do not depend on it */
    int optimize;       /* nonzero (the default): the optimizer's passes */
    /* The folder where the JIT keeps compiled kernels, so that a program's second start
     * compiles nothing: NULL (the default) for $PSYS_JIT_CACHE, else $XDG_CACHE_HOME/psys/jit
     * or ~/.cache/psys/jit; "" for none. */
    const char* jit_cache;
    /* Folders, ':'-separated, where `import "std/…"` looks first (each holds std/), before
     * $PSYS_LIBRARY and the installed share/psys: NULL (the default) for none. */
    const char* library_path;
    /* The host's allocator for particle memory: zero (the default) for the library's own. */
    psys_allocator allocator;
} psys_options;

/* The defaults above: llvm, fast, seed 1, 2^20 objects a type, every core, optimized, the
 * default cache, no library folders of the host's; and `size`, the host's sizeof (an
 * inline function, so that it is the host's header's: the library writes no more than
 * that, and reads what it knows of it). */
PSYS_API void psys_options_init_size(psys_options* options, size_t size);
static inline void psys_options_init(psys_options* options) { psys_options_init_size(options, sizeof *options); }

/* What the library has to say outside a call's result — a JIT session's error, a GL debug
 * message (PSYS_GL_DEBUG), a setting it could not honour — one line a call, without a
 * newline: to `log` from now on (any thread, one call at a time), or to standard error
 * (NULL: the default). Process-wide. */
typedef void (*psys_log_function)(void* user, psys_severity severity, const char* message);
PSYS_API void psys_set_log(psys_log_function log, void* user);

/* Compiles a program and starts a system (nothing is created before the first step or
 * trigger). On error *out is left NULL and the error has the diagnostics. `options` may
 * be NULL (the defaults). libpsys only: libpsys_runtime has no compiler. */
PSYS_API psys_error* psys_compile_file(const char* path, const psys_options* options, psys_system** out);
/* The same from text; `name` stands for its file in diagnostics (NULL: "<string>"). */
PSYS_API psys_error* psys_compile_string(const char* source, const char* name, const psys_options* options,
                                         psys_system** out);
/* NULL is ignored. On the glsl backend, call it with the system's GL context current. */
PSYS_API void psys_system_free(psys_system* system);

/* Compiles the system's file again (psys_compile_file's) or `source` (non-NULL: for a
 * string's system, or to try an edit) and, if it compiles, the new program takes over the
 * running objects by type name: ids, ages, state whose name and type still match (the
 * viewer's hot reload, docs/runtime.md). If it does not compile, the running system is
 * untouched and the error has the diagnostics. An ahead-of-time system does not reload. */
PSYS_API psys_error* psys_reload(psys_system* system, const char* source);

/* How many warnings the latest successful compilation (or reload) gave, and each. */
PSYS_API size_t psys_warning_count(const psys_system* system);
PSYS_API int psys_warning(const psys_system* system, size_t index, psys_diagnostic* out);

/* ---- Ahead of time ------------------------------------------------------------------ */

/* What `psysc build FILE -o NAME` writes into NAME.a, declared by NAME.h as NAME_aot: the
 * system's IR and its kernels' machine code for one CPU or several (`--cpu
 * x86-64-v3,znver4`), found by key. A host links the archive with libpsys_runtime (no
 * compiler, no LLVM) or with libpsys. */
#define PSYS_AOT_ABI 5 /* 5: a fold's walk of its grid compiled with its terms */
typedef struct psys_aot_kernel {
    uint64_t key_low, key_high;
    void* code;
} psys_aot_kernel;
/* The kernels compiled for one CPU. */
typedef struct psys_aot_cpu {
    const char* name;     /* as LLVM names it: "x86-64-v3", "znver4", "sapphirerapids" */
    const char* features; /* what its code may use that not every CPU of the triple has,
                             comma-separated ("avx,avx2,fma,…"): a CPU lacking one cannot run it */
    size_t kernel_count;
    const psys_aot_kernel* kernels;
} psys_aot_cpu;
typedef struct psys_aot {
    uint32_t abi;   /* PSYS_AOT_ABI when it was built */
    uint32_t exact; /* 1: exact maths (the interpreter's bits), 0: fast */
    const char* name;
    const char* ir; /* the system (psysc --emit=ir) */
    size_t cpu_count;
    const psys_aot_cpu* cpus; /* the most capable first: psys_open_aot runs the first this CPU can */
    const char* glsl;   /* its compute shaders (psysc --emit=glsl), for a host's own GL
                           pipeline; NULL when built with --no-glsl */
    const char* target; /* the triple the kernels were compiled for */
} psys_aot;

/* The CPU of `aot->cpus` whose kernels this machine runs (the first it can), or NULL when
 * it can run none (psys_open_aot then refuses, saying what each lacks). */
PSYS_API const psys_aot_cpu* psys_aot_choose_cpu(const psys_aot* aot);

/* Starts an ahead-of-time compiled system. options->backend: "llvm" (the default) or "aot"
 * run its compiled kernels (for the CPU psys_aot_choose_cpu chooses: none is an error that
 * names what this CPU lacks); "interp" and "glsl" run its IR there. Its maths is the
 * build's (options->math is not read). It does not reload: psys_reload says so. */
PSYS_API psys_error* psys_open_aot(const psys_aot* aot, const psys_options* options, psys_system** out);

/* ---- Running it --------------------------------------------------------------------- */

/* Advances every object by dt seconds: finite and not negative (0 moves nothing). */
PSYS_API psys_error* psys_step(psys_system* system, double dt);
/* Room for `rows` objects of `type` made now (at most its capacity: else an error), so
 * that steps with up to that many take nothing more: the pool's pages given at once, and
 * each chunk's list of deaths with room for the whole chunk (8 bytes a row more where a
 * type's deaths are listed as they happen). With it, a steady-state step allocates
 * nothing and faults no page however the pool's population wanders. Results do not
 * change. */
PSYS_API psys_error* psys_reserve(psys_system* system, size_t type, size_t rows);
/* Runs `seconds` ahead at once (a warm-up, as a game shows a fire already burning), in
 * equal steps of at most `longest_step` seconds (0.1 makes it cheap; the effect's own
 * accuracy decides how long a step it bears), drawing nothing. Errors: a negative or
 * non-finite time, a step not positive. */
PSYS_API psys_error* psys_prewarm(psys_system* system, double seconds, double longest_step);
/* Back to the start: time 0, no object, the counters at 0, the same seed (so the same run
 * again), the externs as last set; nothing is compiled again. On the glsl backend, with
 * the system's GL context current. */
PSYS_API psys_error* psys_reset(psys_system* system);
/* Pause and speed are the host's: a paused system is one not stepped, and a system at
 * speed k is stepped by k·dt (a step of 0 moves nothing). */
/* Seconds since the start, and steps taken. */
PSYS_API double psys_time(const psys_system* system);
PSYS_API uint64_t psys_step_count(const psys_system* system);
/* 1 when the system can produce nothing more of its own accord (started, nothing alive,
 * nothing waiting to be created), else 0. */
PSYS_API int psys_finished(const psys_system* system);

/* Sets an extern: `count` numbers, its width (1 for float and bool: 0 or 1, 3 for vec3
 * and point, 4 for color), finite and within its declared range. */
PSYS_API psys_error* psys_set_extern(psys_system* system, const char* name, const float* values, size_t count);
/* Its current value (the default until set) into values[0 .. width); returns its width,
 * or -1 when there is no such extern. */
PSYS_API int psys_get_extern(const psys_system* system, const char* name, float values[4]);
/* Fires a trigger with its arguments (`count` numbers: the widths of its parameters). */
PSYS_API psys_error* psys_fire(psys_system* system, const char* trigger, const float* args, size_t count);

/* ---- Instances ---------------------------------------------------------------------- */

/* An instanced program — one that reads `instance` (instance.pos, instance.x, …: docs/
 * language.md) — is an effect played many times at once: each play runs its `spawn`s
 * again, and what they create (and what that creates) belongs to that instance and reads
 * its transform. All instances share the effect's pools and one update a step; starting
 * one compiles nothing. The system's own instance (handle 0) plays when the system starts,
 * as a program that is not instanced does; kill it before the first step for a system
 * whose instances the host plays alone. Other programs refuse these calls (their
 * instances could not be told apart). Not on the glsl backend yet. docs/embedding.md,
 * "Instances". */
typedef uint64_t psys_instance;
typedef enum psys_life {
    PSYS_PLAYING = 0,  /* it emits */
    PSYS_STOPPED = 1,  /* psys_instance_stop: no more emission at a rate; what it made lives on */
    PSYS_KILLED = 2,   /* psys_instance_kill: its objects die at the next step, creating nothing */
    PSYS_FINISHED = 3  /* nothing of it is left (also a handle never given) */
} psys_life;

/* Plays the effect again: `transform` is a 4×4 affine matrix, 16 floats in columns
 * (OpenGL's and GLM's order, its last row 0 0 0 1), NULL for the identity. *out gets its
 * handle. Its `spawn`s run now, at the system's time. */
PSYS_API psys_error* psys_play(psys_system* system, const float* transform, psys_instance* out);
/* Moves an instance (the host may call it every frame): read from the next step on. */
PSYS_API psys_error* psys_instance_transform(psys_system* system, psys_instance instance, const float* transform);
PSYS_API psys_error* psys_instance_stop(psys_system* system, psys_instance instance);
PSYS_API psys_error* psys_instance_kill(psys_system* system, psys_instance instance);
/* psys_fire on one instance: what the trigger creates belongs to it. */
PSYS_API psys_error* psys_instance_fire(psys_system* system, psys_instance instance, const char* trigger,
                                        const float* args, size_t count);
/* An extern's value for one instance: in an instanced program each instance reads its
 * own, the effect's (psys_set_extern, which sets every instance's) until this sets it —
 * a played instance starts with the effect's. Checked as psys_set_extern checks it. */
PSYS_API psys_error* psys_instance_set_extern(psys_system* system, psys_instance instance, const char* name,
                                              const float* values, size_t count);
/* Its value for that instance into values[0 .. width); its width, or -1 when there is no
 * such extern or no such instance playing. */
PSYS_API int psys_instance_get_extern(const psys_system* system, psys_instance instance, const char* name,
                                      float values[4]);
/* An instance's speed: seconds of its own a second of the system's, from 0 to 100 (1 when
 * played). Its objects age, move and emit at its pace in the effect's one update; `time`
 * in equations stays the system's. Read from the next step on. */
PSYS_API psys_error* psys_instance_set_speed(psys_system* system, psys_instance instance, float speed);
/* Its speed, or -1 when no such instance is playing. */
PSYS_API float psys_instance_speed(const psys_system* system, psys_instance instance);
/* Pauses (paused != 0) or resumes an instance: paused, no time passes for its objects —
 * their updates run with dt 0: nothing ages, moves by an integral or emits at a rate (what
 * counts updates, as `prev`, still counts them; what reads `time` or the instance's
 * transform still follows them) — and what is fired at it (psys_instance_fire) is made
 * paused too; its speed is kept for its resumption. */
PSYS_API psys_error* psys_instance_pause(psys_system* system, psys_instance instance, int paused);
/* 1 while paused, 0 if not, -1 when no such instance is playing. */
PSYS_API int psys_instance_paused(const psys_system* system, psys_instance instance);
PSYS_API psys_life psys_instance_life(const psys_system* system, psys_instance instance);
/* Instances not finished, the system's own included while it lives. */
PSYS_API size_t psys_instance_count(const psys_system* system);
/* The instances that finished in the latest step (without asking each): up to `max` into
 * out; returns how many there are. */
PSYS_API size_t psys_finished_instances(const psys_system* system, psys_instance* out, size_t max);

/* ---- Events ------------------------------------------------------------------------- */

/* What a program tells the host (`notify "hit"(pos, speed);` in an object — in its body,
 * a `when` or `on death` — or a trigger: docs/language.md, "Events"), read after a step
 * as a list, without polling any type: each notification of the latest step (and of
 * triggers fired since) once, in a stable order, its values' components in order (`width`
 * floats an event; in an instanced program the instance's slot last). Any backend. */
PSYS_API size_t psys_event_count(const psys_system* system);
/* The name of event `index` (as the program spells it), NULL past the end. */
PSYS_API const char* psys_event_name(const psys_system* system, size_t index);
/* Up to `max` events into out (max × width floats); *count gets how many there are and
 * *width the floats of one (either may be NULL; out NULL with max 0 to ask). An unknown
 * name is an error that lists the program's events. */
PSYS_API psys_error* psys_read_events(psys_system* system, const char* name, float* out, size_t max, size_t* count,
                                      size_t* width);

/* ---- What it is made of ------------------------------------------------------------- */

/* Object types, in the program's order (parents before children): index 0 .. count-1. */
PSYS_API size_t psys_type_count(const psys_system* system);
/* NULL for an index past the end. */
PSYS_API const char* psys_type_name(const psys_system* system, size_t type);
/* -1 when there is no such type. */
PSYS_API int psys_type_index(const psys_system* system, const char* name);

/* An extern or a trigger: its name, and its values' widths in order (an extern has one;
 * a trigger one per parameter). `type` spells the type as the program does ("float",
 * "vec3", "color", "point", "bool"; for a trigger the parameters', comma-separated). */
typedef struct psys_input {
    const char* name;
    const char* type;
    size_t values; /* numbers it takes in all */
} psys_input;
PSYS_API size_t psys_extern_count(const psys_system* system);
PSYS_API int psys_extern_info(const psys_system* system, size_t index, psys_input* out);
PSYS_API size_t psys_trigger_count(const psys_system* system);
PSYS_API int psys_trigger_info(const psys_system* system, size_t index, psys_input* out);

/* ---- What it draws ------------------------------------------------------------------ */

/* One column of what a type draws: row r's value is data[r] (CPU backends: the system's
 * own memory, no copy, valid until the next call on the system), or lies in the GL
 * buffer `gl_buffer` at byte 4·r (the glsl backend: nothing is copied to the host), or
 * is `constant` for every row (data NULL and gl_buffer 0). */
typedef struct psys_column {
    const void* data;  /* float, or uint32_t for ids */
    unsigned gl_buffer;
    float constant;
} psys_column;

/* Row r is drawn when visible[r] is 1 (alive, its point visible, every value finite). */
typedef struct psys_draw {
    size_t rows;
    size_t drawn;   /* rows drawn; SIZE_MAX where a GPU has not counted them yet */
    psys_column visible;
    psys_column ids;
    psys_column position[3];
    psys_column color[4];
    psys_column size;
    psys_column rotation, frame; /* a sprite's */
    psys_column end[3];          /* a streak's other end */
    psys_column instance;        /* float: the instance a row belongs to (its slot, the
                                    handle's low 32 bits); the constant 0 unless instanced */
} psys_draw;

PSYS_API psys_error* psys_get_draw(psys_system* system, size_t type, psys_draw* out);

/* The drawn points of a type copied out, in row order, on any backend (a GPU's are read
 * back): at most `max` into out (NULL with max 0 to count them); *count gets how many
 * there are. */
typedef struct psys_point {
    uint32_t id;
    float position[3];
    float color[4];
    float size;
} psys_point;
PSYS_API psys_error* psys_read_points(psys_system* system, size_t type, psys_point* out, size_t max, size_t* count);

/* ---- Counters ----------------------------------------------------------------------- */

typedef struct psys_type_stats {
    size_t live;
    uint64_t created, killed;
    uint64_t dropped;  /* spawns refused at capacity */
    uint64_t unstable; /* updates past the integrator's stability limit */
} psys_type_stats;

typedef struct psys_stats {
    uint64_t steps;
    uint64_t rejected_steps;       /* NaN, infinite or negative dt */
    uint64_t rejected_externs;     /* NaN, infinite or out-of-range values set */
    uint64_t invalid_emissions;    /* NaN or negative rates (taken as 0) */
    uint64_t non_finite_points;    /* points not drawn: a value was NaN or infinite */
    double update_seconds, emit_seconds, create_seconds, draw_seconds, fold_seconds;
} psys_stats;

PSYS_API psys_error* psys_get_stats(const psys_system* system, psys_stats* out);
PSYS_API psys_error* psys_get_type_stats(const psys_system* system, size_t type, psys_type_stats* out);

#ifdef __cplusplus
}
#endif

#endif /* PSYS_PSYS_H */
