// Turns the instructions of one IR kernel into GLSL 4.50 statements.
//
// Every IR value becomes one local variable (`v12`): bool, uint, float or vecN. Float
// values are declared `precise`, so the GLSL compiler neither fuses a multiply and an add
// nor reorders arithmetic: + − × ÷ give the interpreter's bits. Where GLSL leaves a
// result undefined or differs from core/lanes.h (min and max with a NaN, sign of NaN, pow
// of a negative or zero base), the statement spells out lanes.h's rule instead of calling
// the built-in. The random draws are core/hash.h instantiated over GLSL text
// (GlslAlgebra), the age rule is rt/clock.h's over GLSL doubles: neither is restated.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "ir/ir.h"

namespace psys::codegen_glsl {

// The GLSL type of an IR type: bool, uint, float, vec2 … vec4.
std::string glslType(ir::Type type);
// A float literal GLSL reads back to the same bits (inf and NaN through uintBitsToFloat).
std::string floatLiteral(float x);

// Statements appended to a text, with fresh temporaries: what the hash and time algebras
// write into.
class Statements {
public:
    explicit Statements(std::string prefix) : prefix_(std::move(prefix)) {}
    // Declares a fresh temporary `type tN = expression;` and returns its name.
    std::string let(const std::string& type, const std::string& expression, bool precise = false);
    // Declares `type name = expression;` and returns the name.
    std::string define(const std::string& name, const std::string& type, const std::string& expression,
                       bool precise = false);
    void line(const std::string& text) { text_ += "    " + text + "\n"; }
    void append(const std::string& statements) { text_ += statements; }
    const std::string& text() const { return text_; }
    const std::string& prefix() const { return prefix_; }

private:
    std::string prefix_;
    std::string text_;
    int next_ = 0;
};

// The expression of an instruction that reads the world (parameters, state, externs,
// uniforms, age, dt, time, first, ids, draws, parent reads), as GLSL of the
// instruction's type. `parentOrdinal` counts the kernel's parent reads in instruction
// order.
using LeafReader = std::function<std::string(const ir::Inst& inst, int parentOrdinal)>;

// Emits `kernel` into `out`; returns the variable of every value: `prefix` and its IR
// number (v12 is %12). `seed` is a uint expression keying the random numbers.
std::vector<std::string> emitBody(Statements& out, const ir::Kernel& kernel, const std::string& seed,
                                  const LeafReader& leaf, const std::string& prefix = "v");

// A neighbour grid's cell coordinate of a position component (uint: the whole number's
// bits) and the bucket of a cell (core/hash.h cellBucket), as the host computes them.
std::string emitCell(Statements& out, const std::string& p, const std::string& inverse);
std::string emitCellBucket(Statements& out, const std::string& x, const std::string& y, const std::string& z,
                           const std::string& mask);

// `float(now − created)` by rt/clock.h's rule, for two double expressions.
std::string emitAge(Statements& out, const std::string& now, const std::string& created);

}  // namespace psys::codegen_glsl
