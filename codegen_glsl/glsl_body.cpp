#include "codegen_glsl/glsl_body.h"

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "core/hash.h"
#include "rt/clock.h"

namespace psys::codegen_glsl {

using namespace ir;

std::string glslType(Type type) {
    if (type.isBool()) return "bool";
    if (type.kind == Type::Kind::U32) return "uint";
    return type.width == 1 ? "float" : fmt::format("vec{}", type.width);
}

std::string floatLiteral(float x) {
    if (!std::isfinite(x)) return fmt::format("uintBitsToFloat(0x{:08x}u)", std::bit_cast<uint32_t>(x));
    // The shortest decimal that reads back to the same float.
    for (int digits = 1; digits <= 9; ++digits) {
        char text[64];
        std::snprintf(text, sizeof text, "%.*g", digits, static_cast<double>(x));
        if (std::strtof(text, nullptr) != x) continue;
        std::string s = text;
        if (s.find_first_of(".e") == std::string::npos) s += ".0";
        return s;
    }
    return fmt::format("uintBitsToFloat(0x{:08x}u)", std::bit_cast<uint32_t>(x));
}

std::string Statements::let(const std::string& type, const std::string& expression, bool precise) {
    return define(prefix_ + std::to_string(next_++), type, expression, precise);
}

std::string Statements::define(const std::string& name, const std::string& type, const std::string& expression,
                               bool precise) {
    line((precise ? "precise " : "") + type + " " + name + " = " + expression + ";");
    return name;
}

namespace {

// core/hash.h's operations as GLSL statements: the hash is emitted from its one definition.
struct GlslAlgebra {
    using Int = std::string;
    using Float = std::string;
    Statements& out;
    Int constant(uint32_t x) const { return fmt::format("{}u", x); }
    Float floatConstant(float x) const { return floatLiteral(x); }
    Int add(const Int& x, const Int& y) { return out.let("uint", x + " + " + y); }
    Int mul(const Int& x, const Int& y) { return out.let("uint", x + " * " + y); }
    Int bitXor(const Int& x, const Int& y) { return out.let("uint", x + " ^ " + y); }
    Int shiftRight(const Int& x, const Int& y) { return out.let("uint", x + " >> " + y); }
    Int bitAnd(const Int& x, const Int& y) { return out.let("uint", x + " & " + y); }
    Float toFloat(const Int& x) { return out.let("float", "float(" + x + ")", true); }
    Float fmul(const Float& x, const Float& y) { return out.let("float", x + " * " + y, true); }
    Float fsub(const Float& x, const Float& y) { return out.let("float", x + " - " + y, true); }
    Int wholeToInt(const Float& x) {  // (NaN fails both comparisons: the low end)
        return out.let("uint", fmt::format("uint(int({0} >= -2147483648.0 ? ({0} <= 2147483520.0 ? {0} : 2147483520.0) "
                                           ": -2147483648.0))", x));
    }
};

// rt/clock.h's time rule over GLSL doubles.
struct GlslTimeAlgebra {
    using Double = std::string;
    using Float = std::string;
    Statements& out;
    Double minus(const Double& a, const Double& b) { return out.let("double", a + " - " + b, true); }
    // Rounded to nearest as C rounds it, whatever the GL's conversion does (psys_narrow).
    Float narrow(const Double& x) { return out.let("float", "psys_narrow(" + x + ")", true); }
};

const char* kLane = "xyzw";

class BodyEmitter {
public:
    BodyEmitter(Statements& out, const Kernel& kernel, const std::string& seed, const LeafReader& leaf,
                const std::string& prefix)
        : out_(out), kernel_(kernel), seed_(seed), leaf_(leaf), prefix_(prefix) {}

    std::vector<std::string> emit() {
        int parentOrdinal = 0;
        for (ValueId v = 0; v < kernel_.size(); ++v) {
            const Inst& inst = kernel_.at(v);
            std::string expression;
            if (isConstant(inst.op)) expression = constant(inst);
            else if (isInput(inst.op)) expression = leaf_(inst, isGathered(inst.op) ? parentOrdinal++ : -1);
            else if (isRandom(inst.op)) expression = random(inst);
            else if (inst.op == Op::Hash) expression = lattice(inst);
            else expression = pure(inst);
            names_.push_back(out_.define(prefix_ + std::to_string(v), glslType(inst.type), expression, inst.type.isFloat()));
        }
        return names_;
    }

private:
    const std::string& x(const Inst& inst, size_t operand) const { return names_.at(inst.operands.at(operand)); }
    int width(const Inst& inst) const { return inst.type.width; }
    std::string vec(const Inst& inst, const std::string& scalar) const {
        return width(inst) == 1 ? scalar : fmt::format("vec{}({})", width(inst), scalar);
    }
    std::string component(const std::string& value, int lanes, int lane) const {
        return lanes == 1 ? value : value + "." + kLane[lane];
    }

    // A zero is the opaque psys_zero (the preamble says why), -0 its negation.
    static std::string kernelFloat(float x) {
        if (x != 0) return floatLiteral(x);
        return std::signbit(x) ? "(-psys_zero)" : "psys_zero";
    }

    static std::string constant(const Inst& inst) {
        if (inst.type.isBool()) return inst.constant[0] != 0 ? "true" : "false";
        if (inst.type.kind == Type::Kind::U32) return fmt::format("{}u", static_cast<uint32_t>(inst.constant[0]));
        if (inst.type.width == 1) return kernelFloat(inst.constant[0]);
        std::string s = fmt::format("vec{}(", inst.type.width);
        for (int c = 0; c < inst.type.width; ++c) s += (c ? ", " : "") + kernelFloat(inst.constant[static_cast<size_t>(c)]);
        return s + ")";
    }

    // A helper of the preamble (psys_pow, …) applied lane by lane.
    std::string perLane(const Inst& inst, const char* helper) const {
        int w = width(inst);
        std::string lanes;
        for (int l = 0; l < w; ++l) {
            lanes += l ? ", " : "";
            lanes += std::string(helper) + "(" + component(x(inst, 0), w, l);
            for (size_t o = 1; o < inst.operands.size(); ++o) lanes += ", " + component(x(inst, o), w, l);
            lanes += ")";
        }
        return w == 1 ? lanes : fmt::format("vec{}({})", w, lanes);
    }

    // `a < b ? pick : other`, lane by lane for vectors (a NaN compares false: `other`).
    std::string choose(const Inst& inst, const std::string& a, const std::string& b, const std::string& pick,
                       const std::string& other) const {
        if (width(inst) == 1) return fmt::format("({} < {} ? {} : {})", a, b, pick, other);
        return fmt::format("mix({}, {}, lessThan({}, {}))", other, pick, a, b);
    }

    // An op core/ops.h spells for GLSL (OpSpelling): a GLSL function takes vectors as
    // floats; a `psys_` helper of the preamble is applied lane by lane.
    std::string spelled(const Inst& inst, std::string_view name) const {
        if (name.starts_with("psys_")) return perLane(inst, std::string(name).c_str());
        std::string call = std::string(name) + "(";
        for (size_t o = 0; o < inst.operands.size(); ++o) call += (o ? ", " : "") + x(inst, o);
        return call + ")";
    }

    std::string pure(const Inst& inst) const {
        auto a = [&](size_t i) { return x(inst, i); };
        if (const core::OpSpelling& s = opInfo(inst.op).spelling; s.mapped()) return spelled(inst, s.glsl);
        switch (inst.op) {
            case Op::Add: return a(0) + " + " + a(1);
            case Op::Sub: return a(0) + " - " + a(1);
            case Op::Mul: return a(0) + " * " + a(1);
            case Op::Div: return perLane(inst, "psys_div");
            case Op::Mod: return fmt::format("{0} - {1} * floor({2})", a(0), a(1), perLane(inst, "psys_div"));
            case Op::Neg: return "-" + a(0);
            case Op::Min: return perLane(inst, "psys_min");
            case Op::Max: return perLane(inst, "psys_max");
            case Op::Step: return choose(inst, a(1), a(0), vec(inst, "0.0"), vec(inst, "1.0"));  // y < x ? 0 : 1
            case Op::Sign: return perLane(inst, "psys_sign");
            case Op::Fract: return a(0) + " - floor(" + a(0) + ")";
            case Op::Lt: return a(0) + " < " + a(1);
            case Op::Le: return a(0) + " <= " + a(1);
            case Op::Gt: return a(0) + " > " + a(1);
            case Op::Ge: return a(0) + " >= " + a(1);
            case Op::Eq: return a(0) + " == " + a(1);
            case Op::Ne: return a(0) + " != " + a(1);
            case Op::And: return a(0) + " && " + a(1);
            case Op::Or: return a(0) + " || " + a(1);
            case Op::Not: return "!" + a(0);
            case Op::Select: return fmt::format("{} ? {} : {}", a(0), a(1), a(2));
            case Op::Splat: return vec(inst, a(0));
            case Op::Compose: {
                std::string s = fmt::format("vec{}(", width(inst));
                for (size_t o = 0; o < inst.operands.size(); ++o) s += (o ? ", " : "") + a(o);
                return s + ")";
            }
            case Op::Extract: {
                int w = kernel_.at(inst.operands[0]).type.width;
                return component(a(0), w, inst.attr);
            }
            case Op::Shuffle: {
                int w = kernel_.at(inst.operands[0]).type.width;
                if (w == 1) return vec(inst, a(0));
                std::string s = a(0) + ".";
                for (uint8_t l : inst.lanes) s += kLane[l];
                return s;
            }
            case Op::Dot: {  // ((0 + x0·y0) + x1·y1) + …, as core's evaluation sums
                int w = kernel_.at(inst.operands[0]).type.width;
                std::string s = "0.0";
                for (int l = 0; l < w; ++l)
                    s = fmt::format("({} + {} * {})", s, component(a(0), w, l), component(a(1), w, l));
                return s;
            }
            case Op::Instance: throw std::runtime_error(std::string(core::kNoInstances));
            default: throw std::runtime_error(unexpectedOp(inst, "the GLSL backend"));
        }
    }

    std::string random(const Inst& inst) {
        GlslAlgebra algebra{out_};
        std::string drawHash = core::pcgHash(algebra, x(inst, 1));
        std::string lanes;
        for (int l = 0; l < width(inst); ++l) {
            lanes += l ? ", " : "";
            lanes += core::drawLaneFromDraw(algebra, inst.op, seed_, x(inst, 0), static_cast<uint32_t>(inst.attr),
                                            drawHash, static_cast<uint32_t>(l));
        }
        return width(inst) == 1 ? lanes : fmt::format("vec{}({})", width(inst), lanes);
    }

    // hash(x): core/hash.h's lattice hash, lane by lane.
    std::string lattice(const Inst& inst) {
        GlslAlgebra algebra{out_};
        std::array<std::string, 4> x;
        int w = width(inst);
        for (int l = 0; l < w; ++l) x[static_cast<size_t>(l)] = component(this->x(inst, 0), w, l);
        std::string lanes;
        for (int l = 0; l < w; ++l)
            lanes += (l ? ", " : "") + core::latticeLane(algebra, x, w, static_cast<uint32_t>(l));
        return w == 1 ? lanes : fmt::format("vec{}({})", w, lanes);
    }

    Statements& out_;
    const Kernel& kernel_;
    const std::string& seed_;
    const LeafReader& leaf_;
    const std::string& prefix_;
    std::vector<std::string> names_;
};

}  // namespace

std::vector<std::string> emitBody(Statements& out, const Kernel& kernel, const std::string& seed,
                                  const LeafReader& leaf, const std::string& prefix) {
    return BodyEmitter(out, kernel, seed, leaf, prefix).emit();
}

std::string emitAge(Statements& out, const std::string& now, const std::string& created) {
    GlslTimeAlgebra algebra{out};
    return rt::ageAt(algebra, now, created);
}

std::string emitCell(Statements& out, const std::string& p, const std::string& inverse) {
    GlslAlgebra algebra{out};
    return algebra.wholeToInt(out.let("float", "floor(" + p + " * " + inverse + ")", true));
}

std::string emitCellBucket(Statements& out, const std::string& x, const std::string& y, const std::string& z,
                           const std::string& mask) {
    GlslAlgebra algebra{out};
    return core::cellBucket(algebra, x, y, z, mask);
}

}  // namespace psys::codegen_glsl
