#include "codegen_llvm/lane_emitter.h"

#include <array>
#include <stdexcept>
#include <string>

#include <llvm/IR/Intrinsics.h>

#include "core/hash.h"
#include "core/instances.h"

namespace psys::codegen_llvm {

using namespace ir;

llvm::Type* laneType(llvm::IRBuilder<>& b, Type t) {
    if (t.isBool()) return b.getInt1Ty();
    if (t.kind == Type::Kind::U32) return b.getInt32Ty();
    return b.getFloatTy();
}

namespace {

class BodyEmitter {
public:
    BodyEmitter(llvm::IRBuilder<>& b, llvm::Module& m, const Kernel& k, MathMode mode, llvm::Value* seed,
                llvm::Value* externs)
        : b_(b), module_(m), kernel_(k), mode_(mode), seed_(seed), externs_(externs) {}

    std::vector<Lanes> run(const LeafReader& leaf) {
        llvm::FastMathFlags flags;
        if (mode_ == MathMode::Fast) flags.setAllowContract(true);
        b_.setFastMathFlags(flags);
        int parentOrdinal = 0;
        values_.resize(kernel_.size());
        for (ValueId v = 0; v < kernel_.size(); ++v) {
            const Inst& i = kernel_.at(v);
            if (isInput(i.op)) {
                values_[v] = leaf(i, parentOrdinal);
                if (isGathered(i.op)) ++parentOrdinal;
            } else if (i.op == Op::Instance) {
                values_[v] = instance(i);
            } else {
                values_[v] = emit(i);
            }
        }
        b_.clearFastMathFlags();
        return std::move(values_);
    }

private:
    llvm::Value* f(float x) { return llvm::ConstantFP::get(b_.getFloatTy(), x); }

    // A record of the instance table after the externs (core/instances.h): its place
    // clamped as core::instanceSlot clamps it (NaN and negatives to the first, past the
    // count to the last), then a load a lane.
    Lanes instance(const Inst& i) {
        if (!externs_) throw std::runtime_error(unexpectedOp(i, "the JIT (here)"));
        llvm::Type* value = llvm::StructType::get(b_.getContext(), {llvm::ArrayType::get(b_.getFloatTy(), 4), b_.getInt32Ty()});
        auto at = [&](llvm::Value* slot, unsigned lane) {
            return b_.CreateGEP(value, externs_, {slot, b_.getInt32(0), b_.getInt32(lane)});
        };
        llvm::Value* start = b_.getInt32(static_cast<uint32_t>(i.attr2));
        llvm::Value* count = b_.CreateAlignedLoad(b_.getFloatTy(), at(start, 0), llvm::Align(4));
        llvm::Value* last = b_.CreateFPToUI(b_.CreateMaxNum(b_.CreateFSub(count, f(1)), f(0)), b_.getInt32Ty());
        llvm::Value* x = values_[i.operands[0]][0];
        llvm::Value* positive = b_.CreateFCmpOGT(x, f(0));  // false for NaN
        llvm::Value* beyond = b_.CreateFCmpOGE(x, b_.CreateUIToFP(b_.CreateAdd(last, b_.getInt32(1)), b_.getFloatTy()));
        llvm::Value* whole = b_.CreateFPToUI(b_.CreateSelect(positive, b_.CreateSelect(beyond, f(0), x), f(0)), b_.getInt32Ty());
        llvm::Value* index = b_.CreateSelect(beyond, last, whole);
        llvm::Value* stride = b_.getInt32(core::instanceRecordValues(static_cast<size_t>(i.attr2)));
        llvm::Value* slot =
            b_.CreateAdd(start, b_.CreateAdd(b_.getInt32(1 + static_cast<uint32_t>(i.attr)), b_.CreateMul(index, stride)));
        Lanes out;  // (as an extern's value: its type's lanes, a bool 0 or 1)
        for (unsigned l = 0; l < static_cast<unsigned>(i.type.width); ++l) {
            llvm::Value* lane = b_.CreateAlignedLoad(b_.getFloatTy(), at(slot, l), llvm::Align(4));
            out.push_back(i.type.isBool() ? b_.CreateFCmpUNE(lane, f(0)) : lane);
        }
        return out;
    }

    // One lane through a libm function: a plain call in exact mode (the interpreter's
    // function), an intrinsic the vectorizer can map onto libmvec in fast mode.
    llvm::Value* math(llvm::Intrinsic::ID id, const char* name, llvm::Value* x, llvm::Value* y = nullptr) {
        if (mode_ == MathMode::Fast && id != llvm::Intrinsic::not_intrinsic)
            return y ? b_.CreateBinaryIntrinsic(id, x, y) : b_.CreateUnaryIntrinsic(id, x);
        std::vector<llvm::Type*> params(y ? 2 : 1, b_.getFloatTy());
        llvm::FunctionCallee callee =
            module_.getOrInsertFunction(name, llvm::FunctionType::get(b_.getFloatTy(), params, false));
        llvm::CallInst* call = y ? b_.CreateCall(callee, {x, y}) : b_.CreateCall(callee, {x});
        if (mode_ == MathMode::Fast) {  // no errno is read: the call may move and widen
            call->setDoesNotAccessMemory();
            call->setDoesNotThrow();
            call->addFnAttr(llvm::Attribute::WillReturn);
        } else {  // the library's own result: LLVM would turn powf(x, 2) into x·x, which may round otherwise
            call->addFnAttr(llvm::Attribute::NoBuiltin);
        }
        return call;
    }

    // core/hash.h's algebra on LLVM values: the hash is emitted from its one definition.
    struct Integers {
        llvm::IRBuilder<>& b;
        using Int = llvm::Value*;
        using Float = llvm::Value*;
        Int constant(uint32_t x) { return b.getInt32(x); }
        Float floatConstant(float x) { return llvm::ConstantFP::get(b.getFloatTy(), x); }
        Int add(Int x, Int y) { return b.CreateAdd(x, y); }
        Int mul(Int x, Int y) { return b.CreateMul(x, y); }
        Int bitXor(Int x, Int y) { return b.CreateXor(x, y); }
        Int shiftRight(Int x, Int y) { return b.CreateLShr(x, y); }
        Float toFloat(Int x) { return b.CreateUIToFP(x, b.getFloatTy()); }
        Float fmul(Float x, Float y) { return b.CreateFMul(x, y); }
        Float fsub(Float x, Float y) { return b.CreateFSub(x, y); }
        Int wholeToInt(Float x) {  // (NaN fails both comparisons: the low end)
            llvm::Value* lo = llvm::ConstantFP::get(b.getFloatTy(), -2147483648.0);
            llvm::Value* hi = llvm::ConstantFP::get(b.getFloatTy(), 2147483520.0);
            llvm::Value* clamped = b.CreateSelect(b.CreateFCmpOGE(x, lo), b.CreateSelect(b.CreateFCmpOLE(x, hi), x, hi), lo);
            return b.CreateFPToSI(clamped, b.getInt32Ty());
        }
    };

    // hash(x): core/hash.h's lattice hash, lane by lane.
    Lanes lattice(const Inst& i) {
        Integers algebra{b_};
        std::array<llvm::Value*, 4> x{};
        for (int l = 0; l < i.type.width; ++l) x[static_cast<size_t>(l)] = values_[i.operands[0]][static_cast<size_t>(l)];
        Lanes out;
        for (int l = 0; l < i.type.width; ++l)
            out.push_back(core::latticeLane(algebra, x, i.type.width, static_cast<uint32_t>(l)));
        return out;
    }

    // rand / nrand, keyed by (object, draw), lane by lane.
    Lanes random(const Inst& i) {
        llvm::Value* object = values_[i.operands[0]][0];
        llvm::Value* draw = values_[i.operands[1]][0];
        Integers algebra{b_};
        llvm::Value* drawHash = core::pcgHash(algebra, draw);
        Lanes out;
        for (int l = 0; l < i.type.width; ++l)
            out.push_back(core::drawLaneFromDraw(algebra, i.op, seed_, object, static_cast<uint32_t>(i.attr), drawHash,
                                                 static_cast<uint32_t>(l)));
        return out;
    }

    template <typename F>
    Lanes map(const Inst& i, F lane) {
        Lanes out;
        for (int l = 0; l < i.type.width; ++l) out.push_back(lane(static_cast<size_t>(l)));
        return out;
    }

    // core/lanes.h's minimumNumber / maximumNumber: y when x is NaN, when y is beyond x, or
    // when they are equal and y is the zero of the right sign; else x.
    llvm::Value* minMax(llvm::Value* x, llvm::Value* y, bool min) {
        llvm::Value* beyond = min ? b_.CreateFCmpOLT(y, x) : b_.CreateFCmpOLT(x, y);
        llvm::Value* negative = b_.CreateICmpSLT(b_.CreateBitCast(y, b_.getInt32Ty()), b_.getInt32(0));
        llvm::Value* zeroSign = b_.CreateAnd(b_.CreateFCmpOEQ(y, x), min ? negative : b_.CreateNot(negative));
        llvm::Value* pickY = b_.CreateOr(b_.CreateOr(b_.CreateFCmpUNO(x, x), beyond), zeroSign);
        return b_.CreateSelect(pickY, y, x);
    }

    // An op core/ops.h spells for LLVM (OpSpelling): its libm function in exact maths, its
    // intrinsic in fast maths or where it has no libm function (IEEE-exact operations).
    Lanes spelled(const Inst& i, const core::OpSpelling& s) {
        llvm::Intrinsic::ID id = s.intrinsic.empty() ? llvm::Intrinsic::not_intrinsic
                                                     : llvm::Function::lookupIntrinsicID(llvm::StringRef(s.intrinsic.data(), s.intrinsic.size()));
        if (!s.intrinsic.empty() && id == llvm::Intrinsic::not_intrinsic && s.libm.empty())
            throw std::runtime_error("internal error: LLVM has no intrinsic `" + std::string(s.intrinsic) + "` for `" +
                                     std::string(opInfo(i.op).name) + "`");
        std::string libm(s.libm);
        return map(i, [&](size_t l) -> llvm::Value* {
            llvm::Value* x = values_[i.operands[0]][l];
            llvm::Value* y = i.operands.size() > 1 ? values_[i.operands[1]][l] : nullptr;
            if (libm.empty()) return y ? b_.CreateBinaryIntrinsic(id, x, y) : b_.CreateUnaryIntrinsic(id, x);
            return math(id, libm.c_str(), x, y);
        });
    }

    Lanes emit(const Inst& i) {
        auto x = [&](size_t n, size_t l) { return values_[i.operands[n]][l]; };
        auto width = [&](size_t n) { return kernel_.at(i.operands[n]).type.width; };
        if (const core::OpSpelling& s = opInfo(i.op).spelling; s.mapped()) return spelled(i, s);
        switch (i.op) {
            case Op::Const:
                return map(i, [&](size_t l) -> llvm::Value* {
                    if (i.type.isBool()) return b_.getInt1(i.constant[0] != 0);
                    return f(i.constant[l]);
                });
            case Op::Add: return map(i, [&](size_t l) { return b_.CreateFAdd(x(0, l), x(1, l)); });
            case Op::Sub: return map(i, [&](size_t l) { return b_.CreateFSub(x(0, l), x(1, l)); });
            case Op::Mul: return map(i, [&](size_t l) { return b_.CreateFMul(x(0, l), x(1, l)); });
            case Op::Div: return map(i, [&](size_t l) { return b_.CreateFDiv(x(0, l), x(1, l)); });
            case Op::Mod:  // x − y·floor(x / y)
                return map(i, [&](size_t l) {
                    llvm::Value* q = b_.CreateUnaryIntrinsic(llvm::Intrinsic::floor, b_.CreateFDiv(x(0, l), x(1, l)));
                    return b_.CreateFSub(x(0, l), b_.CreateFMul(x(1, l), q));
                });
            case Op::Neg: return map(i, [&](size_t l) { return b_.CreateFNeg(x(0, l)); });
            case Op::Min: return map(i, [&](size_t l) { return minMax(x(0, l), x(1, l), true); });
            case Op::Max: return map(i, [&](size_t l) { return minMax(x(0, l), x(1, l), false); });
            case Op::Step: return map(i, [&](size_t l) { return b_.CreateSelect(b_.CreateFCmpOLT(x(1, l), x(0, l)), f(0), f(1)); });
            case Op::Fract:
                return map(i, [&](size_t l) { return b_.CreateFSub(x(0, l), b_.CreateUnaryIntrinsic(llvm::Intrinsic::floor, x(0, l))); });
            case Op::Sign:
                return map(i, [&](size_t l) {
                    llvm::Value* negative = b_.CreateSelect(b_.CreateFCmpOLT(x(0, l), f(0)), f(-1), f(0));
                    return b_.CreateSelect(b_.CreateFCmpOGT(x(0, l), f(0)), f(1), negative);
                });
            case Op::Lt: return {b_.CreateFCmpOLT(x(0, 0), x(1, 0))};
            case Op::Le: return {b_.CreateFCmpOLE(x(0, 0), x(1, 0))};
            case Op::Gt: return {b_.CreateFCmpOGT(x(0, 0), x(1, 0))};
            case Op::Ge: return {b_.CreateFCmpOGE(x(0, 0), x(1, 0))};
            case Op::Eq: case Op::Ne: {
                Type t = kernel_.at(i.operands[0]).type;
                llvm::Value* equal = nullptr;
                for (int l = 0; l < (t.isFloat() ? t.width : 1); ++l) {
                    auto lane = static_cast<size_t>(l);
                    llvm::Value* e = t.isFloat() ? b_.CreateFCmpOEQ(x(0, lane), x(1, lane)) : b_.CreateICmpEQ(x(0, lane), x(1, lane));
                    equal = equal ? b_.CreateAnd(equal, e) : e;
                }
                return {i.op == Op::Eq ? equal : b_.CreateNot(equal)};
            }
            case Op::And: return {b_.CreateAnd(x(0, 0), x(1, 0))};
            case Op::Or: return {b_.CreateOr(x(0, 0), x(1, 0))};
            case Op::Not: return {b_.CreateNot(x(0, 0))};
            case Op::Select: return map(i, [&](size_t l) { return b_.CreateSelect(x(0, 0), x(1, l), x(2, l)); });
            case Op::Splat: return map(i, [&](size_t) { return x(0, 0); });
            case Op::Compose: {
                Lanes out;
                for (size_t n = 0; n < i.operands.size(); ++n)
                    for (int l = 0; l < width(n) && out.size() < 4; ++l) out.push_back(x(n, static_cast<size_t>(l)));
                return out;
            }
            case Op::Extract: return {x(0, static_cast<size_t>(i.attr))};
            case Op::Shuffle: {
                Lanes out;
                for (auto lane : i.lanes) out.push_back(x(0, static_cast<size_t>(lane)));
                return out;
            }
            case Op::Dot: {  // ((0 + x0·y0) + x1·y1) + …, the interpreter's order
                llvm::Value* sum = f(0);
                for (int l = 0; l < width(0); ++l)
                    sum = b_.CreateFAdd(sum, b_.CreateFMul(x(0, static_cast<size_t>(l)), x(1, static_cast<size_t>(l))));
                return {sum};
            }
            case Op::Rand: case Op::NRand: return random(i);
            case Op::Hash: return lattice(i);
            default:
                throw std::runtime_error(unexpectedOp(i, "the LLVM backend"));
        }
    }

    llvm::IRBuilder<>& b_;
    llvm::Module& module_;
    const Kernel& kernel_;
    MathMode mode_;
    llvm::Value* seed_;
    llvm::Value* externs_;
    std::vector<Lanes> values_;
};

}  // namespace

std::vector<Lanes> emitKernelBody(llvm::IRBuilder<>& builder, llvm::Module& module, const Kernel& kernel,
                                  MathMode mode, llvm::Value* seed, llvm::Value* externs, const LeafReader& leaf) {
    return BodyEmitter(builder, module, kernel, mode, seed, externs).run(leaf);
}

}  // namespace psys::codegen_llvm
