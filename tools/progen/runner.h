// A case run on the interpreter and on every other backend side by side, frame by frame,
// as a differential test: the same objects with the same ids drawn after every step, the
// same rows (status, generations, free stack) every tenth frame and at the end, the same
// counts — and values bit for bit where the backend rounds as the interpreter does (the
// JIT in exact maths), else within a tolerance (the GL's own sin, exp, pow …, fast
// maths' fused multiply-adds: docs/gpu.md).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "tools/progen/case.h"

namespace psys::progen {

struct Config {
    std::string label;
    std::string backend;  // interp, llvm or glsl
    bool exact = true;    // llvm: exact maths; false: fast, with the relaxed rewrites
    unsigned threads = 1;
    bool hostSide = true;  // glsl: small pools on the host, as psysc and the viewer run it
    bool rowsInMemory = false;  // SystemOptions::Rows::InMemory: emitters' rows too, their emissions by the memory
    bool bitwise() const { return backend != "glsl" && exact; }
};

// By name: interp, llvm-exact-1t, llvm-exact-2t, llvm-fast-2t, glsl (with its host side),
// glsl-device (every pool on the GPU; both keep rows in the GPU's memory wherever they can
// be, as the backend asks), interp-memory (the interpreter keeping them in its memory so:
// SystemOptions::Rows::InMemory). nullopt for an unknown one.
std::optional<Config> configNamed(const std::string& name);
std::vector<std::string> configNames();

struct Finding {
    std::string config;  // the backend that differs from the interpreter (or failed)
    // compile (the program does not compile: a generator's or compiler's fault), error (a
    // step, fire, set or play failed on one side only), ids, values, rows, counts, events
    // (notifications or finished instances), instances (handles), crash, timeout
    std::string kind;
    int frame = -1;
    std::string detail;
    std::string summary() const;
};

struct RunOptions {
    std::vector<Config> configs;
    bool compareFast = false;   // fast maths decides as exact maths does in this case
    double tolerance = 1e-3;    // relative to max(1, |value|)
};

// Runs `c`; the first difference found, or nullopt.
std::optional<Finding> runCase(const Case& c, const RunOptions& options);

}  // namespace psys::progen
