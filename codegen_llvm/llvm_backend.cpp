#include "codegen_llvm/llvm_backend.h"

#include <chrono>
#include <map>
#include <stdexcept>

#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/Intrinsics.h>
#include <llvm/IR/LLVMContext.h>
#include <llvm/IR/Module.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Support/TargetSelect.h>

#include "rt/rng.h"

namespace psys::codegen_llvm {

using namespace ir;

namespace {

// The per-object calling convention:
//   void kernel(const Value* params, const Value* state, const Value* externs,
//               const Value* uniforms, const Value* parents, const float* scalars,
//               const uint32_t* keys, Value* yields)
// scalars: age, dt, time, first; keys: seed, object id, draw, child draw; parents: the
// values of the kernel's parent reads, gathered by the caller in instruction order.
using KernelFn = void (*)(const rt::Value*, const rt::Value*, const rt::Value*, const rt::Value*, const rt::Value*,
                          const float*, const uint32_t*, rt::Value*);

class KernelCompiler {
public:
    KernelCompiler(llvm::LLVMContext& ctx, llvm::Module& module, const Kernel& kernel)
        : ctx_(ctx), module_(module), kernel_(kernel), b_(ctx) {}

    void compile(const std::string& name) {
        auto* ptr = llvm::PointerType::getUnqual(ctx_);
        auto* fnType = llvm::FunctionType::get(b_.getVoidTy(), {ptr, ptr, ptr, ptr, ptr, ptr, ptr, ptr}, false);
        fn_ = llvm::Function::Create(fnType, llvm::Function::ExternalLinkage, name, module_);
        for (auto& arg : fn_->args()) arg.addAttr(llvm::Attribute::NoAlias);
        b_.SetInsertPoint(llvm::BasicBlock::Create(ctx_, "entry", fn_));
        valueType_ = llvm::StructType::get(ctx_, {llvm::ArrayType::get(b_.getFloatTy(), 4), b_.getInt32Ty()});
        int parentIndex = 0;
        values_.resize(kernel_.size());
        for (ValueId v = 0; v < kernel_.size(); ++v) values_[v] = emit(kernel_.at(v), parentIndex);
        llvm::Value* yields = fn_->getArg(7);
        for (size_t i = 0; i < kernel_.yields.size(); ++i) {
            ValueId v = kernel_.yields[i].value;
            store(yields, static_cast<int>(i), values_[v], kernel_.at(v).type);
        }
        b_.CreateRetVoid();
    }

private:
    llvm::Type* typeOf(Type t) {
        if (t.isBool()) return b_.getInt1Ty();
        if (t.kind == Type::Kind::U32) return b_.getInt32Ty();
        if (t.width == 1) return b_.getFloatTy();
        return llvm::FixedVectorType::get(b_.getFloatTy(), t.width);
    }

    // Loads element `index` of a Value array as type `t`.
    llvm::Value* load(llvm::Value* array, int index, Type t) {
        llvm::Value* base = b_.CreateConstGEP2_32(valueType_, array, static_cast<unsigned>(index), 0);
        if (t.kind == Type::Kind::U32) {
            llvm::Value* u = b_.CreateConstGEP2_32(valueType_, array, static_cast<unsigned>(index), 1);
            return b_.CreateAlignedLoad(b_.getInt32Ty(), u, llvm::Align(4));
        }
        if (t.isBool()) {
            llvm::Value* f = b_.CreateAlignedLoad(b_.getFloatTy(), base, llvm::Align(4));
            return b_.CreateFCmpUNE(f, llvm::ConstantFP::get(b_.getFloatTy(), 0.0));
        }
        return b_.CreateAlignedLoad(typeOf(t), base, llvm::Align(4));
    }

    void store(llvm::Value* array, int index, llvm::Value* v, Type t) {
        llvm::Value* base = b_.CreateConstGEP2_32(valueType_, array, static_cast<unsigned>(index), 0);
        // Clear the Value first: lanes past the type's width are zero, as the interpreter's.
        b_.CreateAlignedStore(llvm::Constant::getNullValue(valueType_),
                              b_.CreateConstGEP1_32(valueType_, array, static_cast<unsigned>(index)), llvm::Align(4));
        if (t.kind == Type::Kind::U32) {
            b_.CreateAlignedStore(v, b_.CreateConstGEP2_32(valueType_, array, static_cast<unsigned>(index), 1), llvm::Align(4));
        } else if (t.isBool()) {
            b_.CreateAlignedStore(b_.CreateUIToFP(v, b_.getFloatTy()), base, llvm::Align(4));
        } else {
            b_.CreateAlignedStore(v, base, llvm::Align(4));
        }
    }

    llvm::Value* scalarArg(int arg, int index, llvm::Type* type) {
        llvm::Value* p = b_.CreateConstGEP1_32(type, fn_->getArg(static_cast<unsigned>(arg)), static_cast<unsigned>(index));
        return b_.CreateAlignedLoad(type, p, llvm::Align(4));
    }

    llvm::Value* constant(const Inst& i) {
        if (i.type.isBool()) return b_.getInt1(i.constant[0] != 0);
        if (i.type.width == 1) return llvm::ConstantFP::get(b_.getFloatTy(), i.constant[0]);
        std::vector<llvm::Constant*> lanes;
        for (int l = 0; l < i.type.width; ++l)
            lanes.push_back(llvm::ConstantFP::get(b_.getFloatTy(), i.constant[static_cast<size_t>(l)]));
        return llvm::ConstantVector::get(lanes);
    }

    llvm::Value* floatConst(Type t, float x) {
        llvm::Value* c = llvm::ConstantFP::get(b_.getFloatTy(), x);
        return t.width == 1 ? c : b_.CreateVectorSplat(t.width, c);
    }

    llvm::Value* intrinsic(llvm::Intrinsic::ID id, llvm::Value* x) {
        return b_.CreateUnaryIntrinsic(id, x);
    }

    // A libm function (float → float, or two floats), applied lane by lane: the same
    // functions the interpreter calls.
    llvm::Value* libm(const char* name, Type t, llvm::Value* x, llvm::Value* y = nullptr) {
        std::vector<llvm::Type*> params(y ? 2 : 1, b_.getFloatTy());
        llvm::FunctionCallee f =
            module_.getOrInsertFunction(name, llvm::FunctionType::get(b_.getFloatTy(), params, false));
        if (t.width == 1) return y ? b_.CreateCall(f, {x, y}) : b_.CreateCall(f, {x});
        llvm::Value* out = llvm::PoisonValue::get(typeOf(t));
        for (int l = 0; l < t.width; ++l) {
            llvm::Value* a = b_.CreateExtractElement(x, static_cast<uint64_t>(l));
            llvm::Value* r = y ? b_.CreateCall(f, {a, b_.CreateExtractElement(y, static_cast<uint64_t>(l))}) : b_.CreateCall(f, {a});
            out = b_.CreateInsertElement(out, r, static_cast<uint64_t>(l));
        }
        return out;
    }

    llvm::Value* pcg(llvm::Value* v) {
        llvm::Value* state = b_.CreateAdd(b_.CreateMul(v, b_.getInt32(747796405u)), b_.getInt32(2891336453u));
        llvm::Value* shift = b_.CreateAdd(b_.CreateLShr(state, b_.getInt32(28)), b_.getInt32(4));
        llvm::Value* word = b_.CreateMul(b_.CreateXor(b_.CreateLShr(state, shift), state), b_.getInt32(277803737u));
        return b_.CreateXor(b_.CreateLShr(word, b_.getInt32(22)), word);
    }

    llvm::Value* random(const Inst& i, llvm::Value* object, llvm::Value* draw) {
        llvm::Value* seed = scalarArg(6, 0, b_.getInt32Ty());
        llvm::Value* out = i.type.width == 1 ? nullptr : static_cast<llvm::Value*>(llvm::PoisonValue::get(typeOf(i.type)));
        llvm::Value* single = nullptr;
        for (int l = 0; l < i.type.width; ++l) {
            // drawBits(seed, object, site, draw, component), as rt/rng.h
            llvm::Value* h = pcg(b_.CreateXor(b_.getInt32(static_cast<uint32_t>(l)), pcg(draw)));
            h = pcg(b_.CreateXor(h, b_.getInt32(static_cast<uint32_t>(i.attr) * 0x9E3779B9u)));
            h = pcg(b_.CreateXor(h, object));
            h = pcg(b_.CreateXor(h, seed));
            llvm::Value* u = b_.CreateFMul(b_.CreateUIToFP(b_.CreateLShr(h, b_.getInt32(8)), b_.getFloatTy()),
                                           llvm::ConstantFP::get(b_.getFloatTy(), 1.0 / 16777216.0));
            if (i.op == Op::NRand)
                u = b_.CreateFSub(b_.CreateFMul(u, llvm::ConstantFP::get(b_.getFloatTy(), 2.0)),
                                  llvm::ConstantFP::get(b_.getFloatTy(), 1.0));
            if (i.type.width == 1) single = u;
            else out = b_.CreateInsertElement(out, u, static_cast<uint64_t>(l));
        }
        return i.type.width == 1 ? single : out;
    }

    llvm::Value* emit(const Inst& i, int& parentIndex) {
        auto op = [&](size_t n) { return values_[i.operands[n]]; };
        auto opType = [&](size_t n) { return kernel_.at(i.operands[n]).type; };
        Type t = i.type;
        switch (i.op) {
            case Op::Const: return constant(i);
            case Op::Param: case Op::TriggerParam: return load(fn_->getArg(0), i.attr, t);
            case Op::StateRead: return load(fn_->getArg(1), i.attr, t);
            case Op::Extern: return load(fn_->getArg(2), i.attr, t);
            case Op::Uniform: return load(fn_->getArg(3), i.attr, t);
            case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: return load(fn_->getArg(4), parentIndex++, t);
            case Op::Age: return scalarArg(5, 0, b_.getFloatTy());
            case Op::Dt: return scalarArg(5, 1, b_.getFloatTy());
            case Op::Time: return scalarArg(5, 2, b_.getFloatTy());
            case Op::First: return b_.CreateFCmpUNE(scalarArg(5, 3, b_.getFloatTy()), llvm::ConstantFP::get(b_.getFloatTy(), 0.0));
            case Op::ObjectId: return scalarArg(6, 1, b_.getInt32Ty());
            case Op::DrawIndex: return scalarArg(6, i.attr == 1 ? 3 : 2, b_.getInt32Ty());
            case Op::Add: return b_.CreateFAdd(op(0), op(1));
            case Op::Sub: return b_.CreateFSub(op(0), op(1));
            case Op::Mul: return b_.CreateFMul(op(0), op(1));
            case Op::Div: return b_.CreateFDiv(op(0), op(1));
            case Op::Mod:  // x - y * floor(x / y)
                return b_.CreateFSub(op(0), b_.CreateFMul(op(1), intrinsic(llvm::Intrinsic::floor, b_.CreateFDiv(op(0), op(1)))));
            case Op::Neg: return b_.CreateFNeg(op(0));
            case Op::Min: return b_.CreateSelect(b_.CreateFCmpOLT(op(1), op(0)), op(1), op(0));
            case Op::Max: return b_.CreateSelect(b_.CreateFCmpOLT(op(0), op(1)), op(1), op(0));
            case Op::Step: return b_.CreateSelect(b_.CreateFCmpOLT(op(1), op(0)), floatConst(t, 0), floatConst(t, 1));
            case Op::Atan2: return libm("atan2f", t, op(0), op(1));
            case Op::Pow: return libm("powf", t, op(0), op(1));
            case Op::Sin: return libm("sinf", t, op(0));
            case Op::Cos: return libm("cosf", t, op(0));
            case Op::Tan: return libm("tanf", t, op(0));
            case Op::Asin: return libm("asinf", t, op(0));
            case Op::Acos: return libm("acosf", t, op(0));
            case Op::Atan: return libm("atanf", t, op(0));
            case Op::Exp: return libm("expf", t, op(0));
            case Op::Log: return libm("logf", t, op(0));
            case Op::Sqrt: return intrinsic(llvm::Intrinsic::sqrt, op(0));
            case Op::Abs: return intrinsic(llvm::Intrinsic::fabs, op(0));
            case Op::Floor: return intrinsic(llvm::Intrinsic::floor, op(0));
            case Op::Ceil: return intrinsic(llvm::Intrinsic::ceil, op(0));
            case Op::Round: return intrinsic(llvm::Intrinsic::nearbyint, op(0));
            case Op::Fract: return b_.CreateFSub(op(0), intrinsic(llvm::Intrinsic::floor, op(0)));
            case Op::Sign: {
                llvm::Value* positive = b_.CreateFCmpOGT(op(0), floatConst(t, 0));
                llvm::Value* negative = b_.CreateFCmpOLT(op(0), floatConst(t, 0));
                return b_.CreateSelect(positive, floatConst(t, 1), b_.CreateSelect(negative, floatConst(t, -1), floatConst(t, 0)));
            }
            case Op::Lt: return b_.CreateFCmpOLT(op(0), op(1));
            case Op::Le: return b_.CreateFCmpOLE(op(0), op(1));
            case Op::Gt: return b_.CreateFCmpOGT(op(0), op(1));
            case Op::Ge: return b_.CreateFCmpOGE(op(0), op(1));
            case Op::Eq: case Op::Ne: {
                Type ot = opType(0);
                llvm::Value* equal;
                if (!ot.isFloat()) {
                    equal = b_.CreateICmpEQ(op(0), op(1));
                } else if (ot.width == 1) {
                    equal = b_.CreateFCmpOEQ(op(0), op(1));
                } else {
                    equal = b_.CreateAndReduce(b_.CreateFCmpOEQ(op(0), op(1)));
                }
                return i.op == Op::Eq ? equal : b_.CreateNot(equal);
            }
            case Op::And: return b_.CreateAnd(op(0), op(1));
            case Op::Or: return b_.CreateOr(op(0), op(1));
            case Op::Not: return b_.CreateNot(op(0));
            case Op::Select: return b_.CreateSelect(op(0), op(1), op(2));
            case Op::Splat: return b_.CreateVectorSplat(t.width, op(0));
            case Op::Compose: {
                llvm::Value* out = llvm::PoisonValue::get(typeOf(t));
                uint64_t lane = 0;
                for (size_t n = 0; n < i.operands.size(); ++n) {
                    Type pt = opType(n);
                    if (pt.width == 1) {
                        out = b_.CreateInsertElement(out, op(n), lane++);
                    } else {
                        for (int l = 0; l < pt.width; ++l)
                            out = b_.CreateInsertElement(out, b_.CreateExtractElement(op(n), static_cast<uint64_t>(l)), lane++);
                    }
                }
                return out;
            }
            case Op::Extract: return b_.CreateExtractElement(op(0), static_cast<uint64_t>(i.attr));
            case Op::Shuffle: {
                std::vector<int> mask(i.lanes.begin(), i.lanes.end());
                if (mask.size() == 1) return b_.CreateExtractElement(op(0), static_cast<uint64_t>(mask[0]));
                return b_.CreateShuffleVector(op(0), mask);
            }
            case Op::Dot: {  // ((0 + x0·y0) + x1·y1) + …, the interpreter's order
                llvm::Value* product = b_.CreateFMul(op(0), op(1));
                llvm::Value* sum = llvm::ConstantFP::get(b_.getFloatTy(), 0.0);
                for (int l = 0; l < opType(0).width; ++l)
                    sum = b_.CreateFAdd(sum, b_.CreateExtractElement(product, static_cast<uint64_t>(l)));
                return sum;
            }
            case Op::Rand: case Op::NRand: return random(i, op(0), op(1));
            default:
                throw std::runtime_error("the LLVM backend cannot compile `" + std::string(opInfo(i.op).name) + "`");
        }
    }

    llvm::LLVMContext& ctx_;
    llvm::Module& module_;
    const Kernel& kernel_;
    llvm::IRBuilder<> b_;
    llvm::Function* fn_ = nullptr;
    llvm::StructType* valueType_ = nullptr;
    std::vector<llvm::Value*> values_;
};

}  // namespace

struct LlvmBackend::Impl {
    std::unique_ptr<llvm::orc::LLJIT> jit;
    std::map<const Kernel*, KernelFn> compiled;
    double compileSeconds = 0;
    int counter = 0;
    std::vector<rt::Value> parents;

    KernelFn compile(const Kernel& kernel) {
        auto start = std::chrono::steady_clock::now();
        auto ctx = std::make_unique<llvm::LLVMContext>();
        auto module = std::make_unique<llvm::Module>("psys", *ctx);
        std::string name = "kernel" + std::to_string(counter++);
        KernelCompiler(*ctx, *module, kernel).compile(name);
        if (llvm::verifyModule(*module, &llvm::errs())) throw std::runtime_error("the LLVM backend built invalid IR");
        if (auto err = jit->addIRModule(llvm::orc::ThreadSafeModule(std::move(module), std::move(ctx))))
            throw std::runtime_error(llvm::toString(std::move(err)));
        auto symbol = jit->lookup(name);
        if (!symbol) throw std::runtime_error(llvm::toString(symbol.takeError()));
        compileSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        return symbol->toPtr<KernelFn>();
    }
};

LlvmBackend::LlvmBackend() : impl_(std::make_unique<Impl>()) {
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
    auto jit = llvm::orc::LLJITBuilder().create();
    if (!jit) throw std::runtime_error(llvm::toString(jit.takeError()));
    impl_->jit = std::move(*jit);
    // libm's functions come from this process, as the interpreter's do.
    auto generator = llvm::orc::DynamicLibrarySearchGenerator::GetForCurrentProcess(
        impl_->jit->getDataLayout().getGlobalPrefix());
    if (!generator) throw std::runtime_error(llvm::toString(generator.takeError()));
    impl_->jit->getMainJITDylib().addGenerator(std::move(*generator));
}

LlvmBackend::~LlvmBackend() = default;

size_t LlvmBackend::compiledKernels() const { return impl_->compiled.size(); }
double LlvmBackend::compileSeconds() const { return impl_->compileSeconds; }

void LlvmBackend::run(const Kernel& kernel, const rt::KernelInputs& in, std::vector<rt::Value>& yields) {
    auto it = impl_->compiled.find(&kernel);
    if (it == impl_->compiled.end()) it = impl_->compiled.emplace(&kernel, impl_->compile(kernel)).first;
    // Parent reads are gathered here, in instruction order.
    auto& parents = impl_->parents;
    parents.clear();
    for (const Inst& i : kernel.insts()) {
        if (i.op == Op::ParentExport) parents.push_back(in.parentExport(i.attr2, i.attr));
        else if (i.op == Op::ParentAlive) parents.push_back(rt::Value::boolean(in.parentAlive(i.attr2)));
        else if (i.op == Op::ParentAge) parents.push_back(rt::Value::scalar(in.parentAge(i.attr2)));
    }
    float scalars[4] = {in.age, in.dt, in.time, in.first ? 1.0f : 0.0f};
    uint32_t keys[4] = {in.seed, in.objectId, in.draw, in.childDraw};
    yields.resize(kernel.yields.size());
    it->second(in.params, in.state, in.externs, in.uniforms, parents.data(), scalars, keys, yields.data());
}

}  // namespace psys::codegen_llvm
