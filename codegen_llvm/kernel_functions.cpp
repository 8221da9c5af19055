#include "codegen_llvm/kernel_functions.h"

#include <array>

#include <map>
#include <stdexcept>

#include <llvm/IR/IRBuilder.h>
#include <llvm/IR/MDBuilder.h>

#include "codegen_llvm/lane_emitter.h"

namespace psys::codegen_llvm {

using namespace ir;
using rt::ColumnLayout;

namespace {

// rt/clock.h's time algebra on LLVM values: the age rule is emitted from its definition.
struct TimeAlgebra {
    llvm::IRBuilder<>& b;
    using Double = llvm::Value*;
    using Float = llvm::Value*;
    llvm::Value* minus(llvm::Value* x, llvm::Value* y) { return b.CreateFSub(x, y); }
    llvm::Value* narrow(llvm::Value* x) { return b.CreateFPTrunc(x, b.getFloatTy()); }
};

// The parts of both function shapes: Value arrays, lanes to and from memory.
class FunctionBuilder {
protected:
    FunctionBuilder(llvm::Module& module, MathMode mode)
        : ctx_(module.getContext()), module_(module), mode_(mode), b_(ctx_) {
        valueType_ = llvm::StructType::get(ctx_, {llvm::ArrayType::get(b_.getFloatTy(), 4), b_.getInt32Ty()});
    }

    // The lanes of element `index` of a Value array.
    Lanes loadValue(llvm::Value* array, int index, Type t) {
        auto i = static_cast<unsigned>(index);
        if (t.kind == Type::Kind::U32)
            return {b_.CreateAlignedLoad(b_.getInt32Ty(), b_.CreateConstGEP2_32(valueType_, array, i, 1), llvm::Align(4))};
        Lanes out;
        for (int l = 0; l < t.width; ++l) {
            llvm::Value* p = b_.CreateGEP(valueType_, array, {b_.getInt32(i), b_.getInt32(0), b_.getInt32(static_cast<unsigned>(l))});
            out.push_back(fromFloat(b_.CreateAlignedLoad(b_.getFloatTy(), p, llvm::Align(4)), t));
        }
        return out;
    }

    // Memory holds floats; bools are 0 or 1, u32 values their bits.
    llvm::Value* fromFloat(llvm::Value* x, Type t) {
        if (t.isBool()) return b_.CreateFCmpUNE(x, llvm::ConstantFP::get(b_.getFloatTy(), 0.0));
        if (t.kind == Type::Kind::U32) return b_.CreateBitCast(x, b_.getInt32Ty());
        return x;
    }
    llvm::Value* toFloat(llvm::Value* x, Type t) {
        if (t.isBool()) return b_.CreateUIToFP(x, b_.getFloatTy());
        if (t.kind == Type::Kind::U32) return b_.CreateBitCast(x, b_.getFloatTy());
        return x;
    }
    llvm::Value* age(llvm::Value* now, llvm::Value* created) {
        TimeAlgebra a{b_};
        return rt::ageAt(a, now, created);
    }

    llvm::LLVMContext& ctx_;
    llvm::Module& module_;
    MathMode mode_;
    llvm::IRBuilder<> b_;
    llvm::StructType* valueType_;
};

// A kernel as a loop over rows [begin, end) of a column table. The entry function reads
// the table and calls the loop with one noalias pointer per column, which is what lets the
// loop vectorize without run-time alias checks.
class RowsFunctionBuilder : FunctionBuilder {
public:
    RowsFunctionBuilder(llvm::Module& module, MathMode mode, unsigned lanes)
        : FunctionBuilder(module, mode), lanes_(lanes) {}

    void build(const Object& object, const Kernel& kernel, const Kernel* uniformKernel, rt::Clock::Source now,
               rt::Clock::Source dt, const std::string& name) {
        const ColumnLayout layout = rt::columnLayout(object, kernel);
        perRowNow_ = now == rt::Clock::Source::PerRow;
        perRowDt_ = dt == rt::Clock::Source::PerRow;
        dtSinceCreated_ = dt == rt::Clock::Source::SinceCreated;
        uniformKernel_ = rt::Clock::perRow(now, dt) ? uniformKernel : nullptr;
        // The columns the kernel touches, in first-use order.
        std::map<int, unsigned> argOf;
        std::vector<int> columns;
        auto use = [&](int column) {
            if (argOf.emplace(column, static_cast<unsigned>(kFixedArgs + columns.size())).second) columns.push_back(column);
        };
        use(ColumnLayout::kCreated);
        if (perRowNow_) use(ColumnLayout::kNow);
        if (perRowDt_) use(ColumnLayout::kDt);
        for (const Inst& i : kernel.insts()) {
            auto lanes = [&](int first) { for (int l = 0; l < i.type.width; ++l) use(first + l); };
            if (i.op == Op::Param) lanes(layout.paramOffset.at(static_cast<size_t>(i.attr)));
            if (i.op == Op::StateRead) lanes(layout.stateOffset.at(static_cast<size_t>(i.attr)));
            if (i.op == Op::ObjectId) use(ColumnLayout::kIds);
        }
        for (const auto& p : layout.parentColumns)
            for (int l = 0; l < p.width; ++l) use(p.offset + l);
        if (kernel.kind == KernelKind::Render)  // it marks what it draws (markDrawn): every render column
            for (int c = 0; c < layout.renderColumns; ++c)
                if (!layout.constant(c)) use(layout.drawnFrom(c));
        for (const Yield& y : kernel.yields) {
            int width = kernel.at(y.value).type.width;
            auto lanes = [&](int first) { for (int l = 0; l < width; ++l) use(first + l); };
            switch (y.kind) {
                case YieldKind::StateNext: lanes(layout.stateOffset.at(static_cast<size_t>(y.index))); break;
                case YieldKind::Export: lanes(layout.exportOffset.at(static_cast<size_t>(y.index))); break;
                case YieldKind::Kill: use(ColumnLayout::kKill); break;
                case YieldKind::EmitRate: use(layout.emitRate(y.index)); break;
                case YieldKind::EmitCount: use(layout.emitCount(y.index)); break;
                case YieldKind::Visible: case YieldKind::Position: case YieldKind::Color: case YieldKind::Size:
                case YieldKind::Rotation: case YieldKind::Frame: case YieldKind::End: case YieldKind::Trail:
                    if (!layout.fromState(y))
                        for (int l = 0; l < width; ++l)
                            if (int c = ColumnLayout::renderColumn(y.kind, y.index) + l; !layout.constant(c)) use(layout.render + c);
                    break;
                default: break;
            }
        }

        auto* ptr = llvm::PointerType::getUnqual(ctx_);
        llvm::Type* i64 = b_.getInt64Ty();
        llvm::Type* i32 = b_.getInt32Ty();
        std::vector<llvm::Type*> entryParams = {ptr, ptr, i64, i64, ptr, ptr, b_.getDoubleTy(), b_.getFloatTy(), i32, i32, i32};
        // The loop: the entry's parameters but the table, then the columns.
        std::vector<llvm::Type*> loopParams(entryParams.begin() + 1, entryParams.end());
        loopParams.resize(kFixedArgs + columns.size(), ptr);
        counts_ = llvm::StructType::get(ctx_, {i64, i64});
        auto* loopType = llvm::FunctionType::get(counts_, loopParams, false);
        loop_ = llvm::Function::Create(loopType, llvm::Function::InternalLinkage, name + ".loop", module_);
        loop_->addFnAttr(llvm::Attribute::NoInline);
        // A column copied as it is (a render position that is the state's) stays in the
        // fused loop: left alone, loop-idiom recognition splits it out into a memcpy per
        // column per chunk, a second pass over memory (measured: the fountain's drawing
        // spent three times its loop's time in memcpy).
        for (const char* builtin : {"no-builtin-memcpy", "no-builtin-memmove", "no-builtin-memset"})
            loop_->addFnAttr(builtin);
        for (unsigned a = 0; a < loop_->arg_size(); ++a)
            if (loopParams[a]->isPointerTy()) loop_->getArg(a)->addAttr(llvm::Attribute::NoAlias);
        buildLoop(kernel, layout, argOf);

        auto* entryType = llvm::FunctionType::get(counts_, entryParams, false);
        auto* entry = llvm::Function::Create(entryType, llvm::Function::ExternalLinkage, name, module_);
        b_.SetInsertPoint(llvm::BasicBlock::Create(ctx_, "entry", entry));
        std::vector<llvm::Value*> args;
        for (unsigned a = 1; a < entry->arg_size(); ++a) args.push_back(entry->getArg(a));
        for (int column : columns) {
            llvm::Value* slot = b_.CreateConstGEP1_32(ptr, entry->getArg(0), static_cast<unsigned>(column));
            args.push_back(b_.CreateAlignedLoad(ptr, slot, llvm::Align(8)));
        }
        b_.CreateRet(b_.CreateCall(loop_, args));
    }

private:
    // The loop's fixed parameters.
    static constexpr unsigned kMask = 0, kBegin = 1, kEnd = 2, kExterns = 3, kUniforms = 4, kNow = 5, kDt = 6,
                              kFirst = 7, kSeed = 8, kDraw = 9, kFixedArgs = 10;

    llvm::Value* columnAt(const std::map<int, unsigned>& argOf, int column, llvm::Type* type) {
        return b_.CreateInBoundsGEP(type, loop_->getArg(argOf.at(column)), row_);
    }

    void buildLoop(const Kernel& kernel, const ColumnLayout& layout, const std::map<int, unsigned>& argOf) {
        llvm::BasicBlock* entry = llvm::BasicBlock::Create(ctx_, "entry", loop_);
        llvm::BasicBlock* body = llvm::BasicBlock::Create(ctx_, "row", loop_);
        llvm::BasicBlock* exit = llvm::BasicBlock::Create(ctx_, "exit", loop_);
        b_.SetInsertPoint(entry);
        llvm::Value* begin = loop_->getArg(kBegin);
        llvm::Value* end = loop_->getArg(kEnd);
        b_.CreateCondBr(b_.CreateICmpSLT(begin, end), body, exit);

        b_.SetInsertPoint(body);
        llvm::PHINode* row = b_.CreatePHI(b_.getInt64Ty(), 2, "r");
        row->addIncoming(begin, entry);
        llvm::PHINode* killedSoFar = b_.CreatePHI(b_.getInt64Ty(), 2, "killed");
        killedSoFar->addIncoming(b_.getInt64(0), entry);
        llvm::PHINode* unstableSoFar = b_.CreatePHI(b_.getInt64Ty(), 2, "unstable");
        unstableSoFar->addIncoming(b_.getInt64(0), entry);
        row_ = row;
        llvm::Type* f32 = b_.getFloatTy();
        llvm::Type* f64 = b_.getDoubleTy();
        auto loadFloat = [&](int column) { return b_.CreateAlignedLoad(f32, columnAt(argOf, column, f32), llvm::Align(4)); };
        // This row's clock (rt/clock.h).
        llvm::Value* created = b_.CreateAlignedLoad(f64, columnAt(argOf, ColumnLayout::kCreated, f64), llvm::Align(8));
        llvm::Value* now = perRowNow_ ? b_.CreateAlignedLoad(f64, columnAt(argOf, ColumnLayout::kNow, f64), llvm::Align(8))
                                      : static_cast<llvm::Value*>(loop_->getArg(kNow));
        llvm::Value* rowAge = nullptr;
        llvm::Value* dt = perRowDt_ ? loadFloat(ColumnLayout::kDt)
                          : dtSinceCreated_ ? (rowAge = age(now, created))
                                            : static_cast<llvm::Value*>(loop_->getArg(kDt));
        std::map<int, Lanes> uniforms;
        llvm::Value* seed = loop_->getArg(kSeed);
        auto leaf = [&](const Inst& i, int parent) -> Lanes {
            auto lanes = [&](int first) {
                Lanes out;
                for (int l = 0; l < i.type.width; ++l) out.push_back(fromFloat(loadFloat(first + l), i.type));
                return out;
            };
            switch (i.op) {
                case Op::Param: return lanes(layout.paramOffset.at(static_cast<size_t>(i.attr)));
                case Op::StateRead: return lanes(layout.stateOffset.at(static_cast<size_t>(i.attr)));
                case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: case Op::Fold:
                    return lanes(layout.parentColumns.at(static_cast<size_t>(parent)).offset);
                case Op::Extern: return loadValue(loop_->getArg(kExterns), i.attr, i.type);
                case Op::Uniform:
                    if (uniformKernel_) return uniforms.at(i.attr);
                    return loadValue(loop_->getArg(kUniforms), i.attr, i.type);
                case Op::Age:
                    if (!rowAge) rowAge = age(now, created);
                    return {rowAge};
                case Op::Dt: return {dt};
                case Op::Time: return {b_.CreateFPTrunc(now, f32)};
                case Op::First: return {b_.CreateICmpNE(loop_->getArg(kFirst), b_.getInt32(0))};
                case Op::ObjectId:
                    return {b_.CreateAlignedLoad(b_.getInt32Ty(), columnAt(argOf, ColumnLayout::kIds, b_.getInt32Ty()), llvm::Align(4))};
                case Op::DrawIndex: return {i.attr == 1 ? b_.getInt32(0) : static_cast<llvm::Value*>(loop_->getArg(kDraw))};
                default: throw std::runtime_error("a loop kernel cannot read `" + std::string(opInfo(i.op).name) + "`");
            }
        };
        if (uniformKernel_) {  // this row's uniform values, at its own clock
            auto values = emitKernelBody(b_, module_, *uniformKernel_, mode_, seed, loop_->getArg(kExterns), leaf);
            for (const Yield& y : uniformKernel_->yields) uniforms[y.index] = values[y.value];
        }
        auto values = emitKernelBody(b_, module_, kernel, mode_, seed, loop_->getArg(kExterns), leaf);

        auto [killedNow, unstableNow] = storeYields(kernel, layout, argOf, values, killedSoFar, unstableSoFar);
        llvm::Value* next = b_.CreateAdd(row_, b_.getInt64(1), "", true, true);
        row->addIncoming(next, b_.GetInsertBlock());
        killedSoFar->addIncoming(killedNow, b_.GetInsertBlock());
        unstableSoFar->addIncoming(unstableNow, b_.GetInsertBlock());
        llvm::BranchInst* latch = b_.CreateCondBr(b_.CreateICmpSLT(next, end), body, exit);
        // A whole register of floats per operation. Left alone, the vectorizer sizes the
        // loop by its widest type (the double creation times: 4 on AVX2) and runs the
        // float work at half width; measured on the fountain at 10M, 8 lanes update 20%
        // more particles per second than 4.
        // Loops that run over few rows are left scalar: vectorizing costs compile time.
        llvm::Metadata* width[] = {
            llvm::MDString::get(ctx_, lanes_ ? "llvm.loop.vectorize.width" : "llvm.loop.vectorize.enable"),
            lanes_ ? llvm::ConstantAsMetadata::get(b_.getInt32(lanes_)) : llvm::ConstantAsMetadata::get(b_.getFalse())};
        llvm::Metadata* loopProperties[] = {nullptr, llvm::MDNode::get(ctx_, width)};
        llvm::MDNode* loopId = llvm::MDNode::getDistinct(ctx_, loopProperties);
        loopId->replaceOperandWith(0, loopId);
        latch->setMetadata(llvm::LLVMContext::MD_loop, loopId);
        b_.SetInsertPoint(exit);
        llvm::PHINode* killed = b_.CreatePHI(b_.getInt64Ty(), 2, "killed.total");
        killed->addIncoming(b_.getInt64(0), entry);
        killed->addIncoming(killedNow, latch->getParent());
        llvm::PHINode* unstable = b_.CreatePHI(b_.getInt64Ty(), 2, "unstable.total");
        unstable->addIncoming(b_.getInt64(0), entry);
        unstable->addIncoming(unstableNow, latch->getParent());
        llvm::Value* counts = b_.CreateInsertValue(llvm::PoisonValue::get(counts_), killed, {0});
        b_.CreateRet(b_.CreateInsertValue(counts, unstable, {1}));
    }

    // The yields of a row: masked rows keep their state and exports, and never die.
    // Returns the counts of rows killed and of unstable rows so far, this one included.
    std::pair<llvm::Value*, llvm::Value*> storeYields(const Kernel& kernel, const ColumnLayout& layout,
                                                      const std::map<int, unsigned>& argOf,
                                                      const std::vector<Lanes>& values, llvm::Value* killedSoFar,
                                                      llvm::Value* unstableSoFar) {
        llvm::Type* f32 = b_.getFloatTy();
        llvm::Value* mask = b_.CreateICmpNE(
            b_.CreateAlignedLoad(b_.getInt8Ty(), b_.CreateInBoundsGEP(b_.getInt8Ty(), loop_->getArg(kMask), row_), llvm::Align(1)),
            b_.getInt8(0));
        auto maskedStore = [&](int column, llvm::Value* value) {
            llvm::Value* old = b_.CreateAlignedLoad(f32, columnAt(argOf, column, f32), llvm::Align(4));
            b_.CreateAlignedStore(b_.CreateSelect(mask, value, old), columnAt(argOf, column, f32), llvm::Align(4));
        };
        llvm::Value* killed = killedSoFar;
        llvm::Value* unstable = unstableSoFar;
        std::vector<llvm::Value*> render(static_cast<size_t>(layout.renderColumns), nullptr);  // the render values, by render column
        for (const Yield& y : kernel.yields) {
            Type t = kernel.at(y.value).type;
            const Lanes& v = values[y.value];
            switch (y.kind) {
                case YieldKind::StateNext:
                    for (int l = 0; l < t.width; ++l)
                        maskedStore(layout.stateOffset.at(static_cast<size_t>(y.index)) + l, toFloat(v[static_cast<size_t>(l)], t));
                    break;
                case YieldKind::Export:
                    for (int l = 0; l < t.width; ++l)
                        maskedStore(layout.exportOffset.at(static_cast<size_t>(y.index)) + l, toFloat(v[static_cast<size_t>(l)], t));
                    break;
                case YieldKind::Kill: {
                    llvm::Value* dies = b_.CreateAnd(mask, v[0]);
                    b_.CreateAlignedStore(b_.CreateZExt(dies, b_.getInt8Ty()),
                                          columnAt(argOf, ColumnLayout::kKill, b_.getInt8Ty()), llvm::Align(1));
                    killed = b_.CreateAdd(killed, b_.CreateZExt(dies, b_.getInt64Ty()));
                    break;
                }
                case YieldKind::Unstable:
                    unstable = b_.CreateAdd(unstable, b_.CreateZExt(b_.CreateAnd(mask, v[0]), b_.getInt64Ty()));
                    break;
                case YieldKind::EmitRate: case YieldKind::EmitCount: {
                    int column = y.kind == YieldKind::EmitRate ? layout.emitRate(y.index) : layout.emitCount(y.index);
                    b_.CreateAlignedStore(toFloat(v[0], t), columnAt(argOf, column, f32), llvm::Align(4));
                    break;
                }
                case YieldKind::Visible: case YieldKind::Position: case YieldKind::Color: case YieldKind::Size:
                case YieldKind::Rotation: case YieldKind::Frame: case YieldKind::End: case YieldKind::Trail:
                    for (int l = 0; l < t.width; ++l) {
                        int column = ColumnLayout::renderColumn(y.kind, y.index) + l;
                        render[column] = toFloat(v[static_cast<size_t>(l)], t);
                        // Else drawn from the state column itself, or a constant with no column.
                        if (!layout.fromState(y) && !layout.constant(column))
                            b_.CreateAlignedStore(render[column], columnAt(argOf, layout.render + column, f32),
                                                  llvm::Align(4));
                    }
                    break;
                default: break;
            }
        }
        if (kernel.kind == KernelKind::Render) return markDrawn(layout, argOf, mask, render, killed, unstable);
        return {killed, unstable};
    }

    // A render loop marks its rows drawn itself (Backend::marksDrawn; the rule of
    // rt/system_draw.cpp): visible = 1 where the row is in the mask, its point visible and
    // its position, colour and size all finite, else 0. Returns the counts so far of rows
    // drawn and of rows visible but not drawn for a NaN or an infinity.
    std::pair<llvm::Value*, llvm::Value*> markDrawn(const ColumnLayout& layout, const std::map<int, unsigned>& argOf,
                                                    llvm::Value* mask, std::vector<llvm::Value*>& render,
                                                    llvm::Value* drawnSoFar, llvm::Value* nonFiniteSoFar) {
        llvm::Type* f32 = b_.getFloatTy();
        for (int column = 0; column < layout.renderColumns; ++column)
            if (auto k = layout.constant(column))
                render[column] = llvm::ConstantFP::get(f32, *k);
            else if (!render[column])
                render[column] = b_.CreateAlignedLoad(f32, columnAt(argOf, layout.drawnFrom(column), f32), llvm::Align(4));
        llvm::Value* finite = b_.getTrue();
        llvm::Value* infinity = llvm::ConstantFP::getInfinity(f32);
        for (int column = ColumnLayout::kPosition; column < layout.renderColumns; ++column) {
            llvm::Value* magnitude = b_.CreateUnaryIntrinsic(llvm::Intrinsic::fabs, render[column]);
            finite = b_.CreateAnd(finite, b_.CreateFCmpONE(magnitude, infinity));  // false for NaN too
        }
        llvm::Value* shown = b_.CreateAnd(mask, b_.CreateFCmpUNE(render[ColumnLayout::kVisible], llvm::ConstantFP::get(f32, 0.0)));
        llvm::Value* drawn = b_.CreateAnd(shown, finite);
        b_.CreateAlignedStore(b_.CreateUIToFP(drawn, f32), columnAt(argOf, layout.render + ColumnLayout::kVisible, f32),
                              llvm::Align(4));
        llvm::Type* i64 = b_.getInt64Ty();
        return {b_.CreateAdd(drawnSoFar, b_.CreateZExt(drawn, i64)),
                b_.CreateAdd(nonFiniteSoFar, b_.CreateZExt(b_.CreateAnd(shown, b_.CreateNot(finite)), i64))};
    }

    llvm::Function* loop_ = nullptr;
    llvm::StructType* counts_ = nullptr;
    llvm::Value* row_ = nullptr;
    bool perRowNow_ = false, perRowDt_ = false, dtSinceCreated_ = false;
    const Kernel* uniformKernel_ = nullptr;
    unsigned lanes_;
};

// A spawn kernel over the `count` children one object emits at once: child k draws with
// draw.index #1 = firstChild + k and its arguments go to args[column][argsFirst + k]. The
// emitter's part of the kernel does not depend on k, and is hoisted out of the loop.
class ChildrenFunctionBuilder : FunctionBuilder {
public:
    ChildrenFunctionBuilder(llvm::Module& module, MathMode mode) : FunctionBuilder(module, mode) {}

    void build(const Object& object, const Kernel& spawn, const std::string& name) {
        const ColumnLayout layout = rt::columnLayout(object, spawn);
        auto* ptr = llvm::PointerType::getUnqual(ctx_);
        llvm::Type* i64 = b_.getInt64Ty();
        llvm::Type* i32 = b_.getInt32Ty();
        std::vector<llvm::Type*> params = {ptr, i64, ptr, ptr, b_.getDoubleTy(), b_.getFloatTy(), i32, i32, i32, i32, i64, ptr, i64};
        fn_ = llvm::Function::Create(llvm::FunctionType::get(b_.getVoidTy(), params, false), llvm::Function::ExternalLinkage,
                                     name, module_);
        for (unsigned a : {kTable, kParents, kExterns, kArgs}) fn_->getArg(a)->addAttr(llvm::Attribute::NoAlias);
        llvm::BasicBlock* entry = llvm::BasicBlock::Create(ctx_, "entry", fn_);
        llvm::BasicBlock* body = llvm::BasicBlock::Create(ctx_, "child", fn_);
        llvm::BasicBlock* exit = llvm::BasicBlock::Create(ctx_, "exit", fn_);
        b_.SetInsertPoint(entry);
        // Everything the kernel reads of the emitter, read once before the loop: inside it
        // only the children's arguments are written, so nothing stops vectorizing it.
        std::map<const Inst*, Lanes> emitter;
        int parentOrdinal = 0;
        for (const Inst& i : spawn.insts()) {
            if (!isInput(i.op) || (i.op == Op::DrawIndex && i.attr == 1)) continue;
            emitter[&i] = read(layout, i, isGathered(i.op) ? parentOrdinal++ : 0);
        }
        const rt::ArgumentColumns arguments = rt::argumentColumns(spawn);
        std::vector<llvm::Value*> argColumns;
        for (size_t c = 0; c < arguments.total; ++c)
            argColumns.push_back(b_.CreateAlignedLoad(
                ptr, b_.CreateConstGEP1_32(ptr, fn_->getArg(kArgs), static_cast<unsigned>(c)), llvm::Align(8)));
        llvm::Value* count = fn_->getArg(kCount);
        b_.CreateCondBr(b_.CreateICmpSGT(count, b_.getInt64(0)), body, exit);
        b_.SetInsertPoint(body);
        llvm::PHINode* k = b_.CreatePHI(i64, 2, "k");
        k->addIncoming(b_.getInt64(0), entry);
        llvm::Value* childDraw = b_.CreateAdd(fn_->getArg(kFirstChild), b_.CreateTrunc(k, i32));
        auto leaf = [&](const Inst& i, int) -> Lanes {
            if (i.op == Op::DrawIndex && i.attr == 1) return {childDraw};
            return emitter.at(&i);
        };
        auto values = emitKernelBody(b_, module_, spawn, mode_, fn_->getArg(kSeed), fn_->getArg(kExterns), leaf);
        llvm::Value* target = b_.CreateAdd(fn_->getArg(kArgsFirst), k);
        // The argument columns are distinct arrays: each store in a scope of its own,
        // declared not to alias the others', so the stores need no run-time overlap checks.
        llvm::MDBuilder md(ctx_);
        llvm::MDNode* domain = md.createAnonymousAliasScopeDomain("psys.args");
        std::vector<llvm::Metadata*> scopes;
        for (size_t c = 0; c < argColumns.size(); ++c) scopes.push_back(md.createAnonymousAliasScope(domain));
        for (const Yield& y : spawn.yields) {
            if (y.kind != YieldKind::EmitArg) continue;
            Type t = spawn.at(y.value).type;
            for (int l = 0; l < t.width; ++l) {
                size_t c = arguments.first[static_cast<size_t>(y.sub)] + static_cast<size_t>(l);
                llvm::StoreInst* store = b_.CreateAlignedStore(toFloat(values[y.value][static_cast<size_t>(l)], t),
                                                               b_.CreateInBoundsGEP(b_.getFloatTy(), argColumns[c], target),
                                                               llvm::Align(4));
                std::vector<llvm::Metadata*> others;
                for (size_t o = 0; o < scopes.size(); ++o)
                    if (o != c) others.push_back(scopes[o]);
                store->setMetadata(llvm::LLVMContext::MD_alias_scope, llvm::MDNode::get(ctx_, {scopes[c]}));
                store->setMetadata(llvm::LLVMContext::MD_noalias, llvm::MDNode::get(ctx_, others));
            }
        }
        llvm::Value* nextChild = b_.CreateAdd(k, b_.getInt64(1), "", true, true);
        k->addIncoming(nextChild, b_.GetInsertBlock());
        b_.CreateCondBr(b_.CreateICmpSLT(nextChild, count), body, exit);
        b_.SetInsertPoint(exit);
        b_.CreateRetVoid();
    }

private:
    static constexpr unsigned kTable = 0, kRow = 1, kParents = 2, kExterns = 3, kNow = 4, kDt = 5, kFirst = 6, kSeed = 7,
                              kDraw = 8, kFirstChild = 9, kCount = 10, kArgs = 11, kArgsFirst = 12;

    // The lanes of an input that does not depend on the child.
    Lanes read(const ColumnLayout& layout, const Inst& i, int parent) {
        auto lanes = [&](int first) {
            Lanes out;
            for (int l = 0; l < i.type.width; ++l)
                out.push_back(fromFloat(load(b_.getFloatTy(), first + l, fn_->getArg(kRow)), i.type));
            return out;
        };
        switch (i.op) {
            case Op::Param: return lanes(layout.paramOffset.at(static_cast<size_t>(i.attr)));
            case Op::StateRead: return lanes(layout.stateOffset.at(static_cast<size_t>(i.attr)));
            case Op::ParentExport: case Op::ParentAlive: case Op::ParentAge: case Op::Fold:
                return loadValue(fn_->getArg(kParents), parent, i.type);
            case Op::Extern: return loadValue(fn_->getArg(kExterns), i.attr, i.type);
            case Op::Age: return {age(fn_->getArg(kNow), load(b_.getDoubleTy(), ColumnLayout::kCreated, fn_->getArg(kRow)))};
            case Op::Dt: return {fn_->getArg(kDt)};
            case Op::Time: return {b_.CreateFPTrunc(fn_->getArg(kNow), b_.getFloatTy())};
            case Op::First: return {b_.CreateICmpNE(fn_->getArg(kFirst), b_.getInt32(0))};
            case Op::ObjectId: return {load(b_.getInt32Ty(), ColumnLayout::kIds, fn_->getArg(kRow))};
            case Op::DrawIndex: return {fn_->getArg(kDraw)};
            default: throw std::runtime_error("a spawn kernel cannot read `" + std::string(opInfo(i.op).name) + "`");
        }
    }

    // Element `row` of the table's column `column`.
    llvm::Value* load(llvm::Type* type, int column, llvm::Value* row) {
        auto* ptr = llvm::PointerType::getUnqual(ctx_);
        llvm::Value* slot = b_.CreateConstGEP1_32(ptr, fn_->getArg(kTable), static_cast<unsigned>(column));
        llvm::Value* base = b_.CreateAlignedLoad(ptr, slot, llvm::Align(8));
        return b_.CreateAlignedLoad(type, b_.CreateInBoundsGEP(type, base, row), llvm::Align(type->isDoubleTy() ? 8 : 4));
    }

    llvm::Function* fn_ = nullptr;
};

}  // namespace

void buildRowsFunction(llvm::Module& module, MathMode mode, unsigned lanes, const Object& object, const Kernel& kernel,
                       const Kernel* uniformKernel, rt::Clock::Source now, rt::Clock::Source dt, const std::string& name) {
    RowsFunctionBuilder(module, mode, lanes).build(object, kernel, uniformKernel, now, dt, name);
}

void buildChildrenFunction(llvm::Module& module, MathMode mode, const Object& object, const Kernel& spawn,
                           const std::string& name) {
    ChildrenFunctionBuilder(module, mode).build(object, spawn, name);
}

}  // namespace psys::codegen_llvm

namespace psys::codegen_llvm {

void buildFunction(llvm::Module& module, MathMode mode, unsigned lanes, const native::Request& r, const std::string& name) {
    const Kernel& k = *r.shape.kernel;
    if (k.kind == KernelKind::Pair)
        buildPairFunction(module, mode, *r.object, k, name);
    else if (r.shape.children)
        buildChildrenFunction(module, mode, *r.object, k, name);
    else
        buildRowsFunction(module, mode, r.vectorize ? lanes : 0, *r.object, k, r.uniformKernel, r.shape.now, r.shape.dt,
                          name);
}

std::string functionName(const native::Request& r, int counter) {
    std::string name = r.object->name + "." + kernelName(r.shape.kernel->kind);
    if (r.shape.children) name += ".children";
    else if (rt::Clock::perRow(r.shape.now, r.shape.dt)) name += ".created";
    return name + "." + std::to_string(counter);
}

}  // namespace psys::codegen_llvm
