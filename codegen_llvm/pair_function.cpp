// A neighbour group's pair kernel as a loop over one object's candidate neighbours
// (rt::PairFunction): the run-time walks the grid and hands over the candidates within
// the radius, in the grid's order; this loop computes each one's terms and combines them
// into the folds in that order, exactly as core/fold.h's combine does (the interpreter's
// result in exact maths).
#include <stdexcept>

#include <llvm/IR/IRBuilder.h>

#include "codegen_llvm/kernel_functions.h"
#include "codegen_llvm/lane_emitter.h"
#include "core/fold.h"

namespace psys::codegen_llvm {

using namespace ir;

void buildPairFunction(llvm::Module& module, MathMode mode, const Object& object, const Kernel& pair,
                       const std::string& name) {
    llvm::LLVMContext& ctx = module.getContext();
    llvm::IRBuilder<> b(ctx);
    llvm::Type* ptr = b.getPtrTy();
    llvm::Type* f32 = b.getFloatTy();
    llvm::Type* i32 = b.getInt32Ty();
    // void pair(const float* const* self, const float* const* other, uint32_t selfRow,
    //           const uint32_t* others, uint32_t count, const Value* externs, float* acc)
    auto* fn = llvm::Function::Create(llvm::FunctionType::get(b.getVoidTy(), {ptr, ptr, i32, ptr, i32, ptr, ptr}, false),
                                      llvm::Function::ExternalLinkage, name, module);
    for (unsigned a : {0u, 1u, 3u, 5u, 6u}) fn->getArg(a)->addAttr(llvm::Attribute::NoAlias);
    llvm::Value *self = fn->getArg(0), *other = fn->getArg(1), *selfRow = fn->getArg(2), *others = fn->getArg(3);
    llvm::Value *count = fn->getArg(4), *externs = fn->getArg(5), *acc = fn->getArg(6);
    auto* entry = llvm::BasicBlock::Create(ctx, "entry", fn);
    auto* body = llvm::BasicBlock::Create(ctx, "neighbour", fn);
    auto* exit = llvm::BasicBlock::Create(ctx, "exit", fn);
    b.SetInsertPoint(entry);

    // The folds' accumulators, in registers through the loop: the group's folds'
    // components in fold order (the layout of `acc`).
    struct Term {
        core::Reduce reduce;
        unsigned first;
    };
    std::vector<Term> terms;  // per yield
    std::vector<unsigned> firstOf(object.folds.size(), 0);
    unsigned width = 0;
    for (size_t f = 0; f < object.folds.size(); ++f) {
        if (object.folds[f].group != pair.site) continue;
        firstOf[f] = width;
        width += static_cast<unsigned>(object.folds[f].type.width);
    }
    for (const Yield& y : pair.yields) {
        const Fold& f = object.folds.at(static_cast<size_t>(y.index));
        terms.push_back({f.reduce, firstOf[static_cast<size_t>(y.index)]});
    }
    std::vector<llvm::Value*> initial;
    for (unsigned c = 0; c < width; ++c)
        initial.push_back(b.CreateAlignedLoad(f32, b.CreateConstGEP1_32(f32, acc, c), llvm::Align(4)));
    b.CreateCondBr(b.CreateICmpUGT(count, b.getInt32(0)), body, exit);

    b.SetInsertPoint(body);
    llvm::PHINode* k = b.CreatePHI(i32, 2, "k");
    k->addIncoming(b.getInt32(0), entry);
    std::vector<llvm::PHINode*> sums;
    for (unsigned c = 0; c < width; ++c) {
        sums.push_back(b.CreatePHI(f32, 2));
        sums.back()->addIncoming(initial[c], entry);
    }
    llvm::Value* row = b.CreateAlignedLoad(i32, b.CreateGEP(i32, others, k), llvm::Align(4));
    llvm::StructType* valueType = llvm::StructType::get(ctx, {llvm::ArrayType::get(f32, 4), i32});
    auto leaf = [&](const Inst& i, int) -> Lanes {
        Lanes out;
        if (i.op == Op::NeighbourExport) {
            llvm::Value* columns = i.attr2 == 1 ? other : self;
            llvm::Value* at = i.attr2 == 1 ? row : selfRow;
            for (int c = 0; c < i.type.width; ++c) {
                llvm::Value* column = b.CreateAlignedLoad(
                    ptr, b.CreateConstGEP1_32(ptr, columns, static_cast<unsigned>(4 * i.attr + c)), llvm::Align(8));
                llvm::Value* x = b.CreateAlignedLoad(f32, b.CreateGEP(f32, column, at), llvm::Align(4));
                // (columns hold floats: a bool is 0 or 1)
                out.push_back(i.type.isBool() ? b.CreateFCmpUNE(x, llvm::ConstantFP::get(f32, 0.0)) : x);
            }
            return out;
        }
        if (i.op == Op::Extern) {
            for (int c = 0; c < i.type.width; ++c)
                out.push_back(b.CreateAlignedLoad(
                    f32,
                    b.CreateGEP(valueType, externs, {b.getInt32(static_cast<unsigned>(i.attr)), b.getInt32(0),
                                                     b.getInt32(static_cast<unsigned>(c))}),
                    llvm::Align(4)));
            return out;
        }
        throw std::runtime_error(unexpectedOp(i, "the JIT's pair kernels"));
    };
    std::vector<Lanes> values = emitKernelBody(b, module, pair, mode, b.getInt32(0), nullptr, leaf);
    std::vector<llvm::Value*> next(sums.begin(), sums.end());
    for (size_t y = 0; y < pair.yields.size(); ++y) {
        const Lanes& term = values[pair.yields[y].value];
        for (size_t c = 0; c < term.size(); ++c) {
            unsigned at = terms[y].first + static_cast<unsigned>(c);
            llvm::Value* a = next[at];
            switch (terms[y].reduce) {  // core::combine
                case core::Reduce::Min: next[at] = b.CreateSelect(b.CreateFCmpOLT(term[c], a), term[c], a); break;
                case core::Reduce::Max: next[at] = b.CreateSelect(b.CreateFCmpOGT(term[c], a), term[c], a); break;
                default: next[at] = b.CreateFAdd(a, term[c]); break;
            }
        }
    }
    llvm::Value* k1 = b.CreateAdd(k, b.getInt32(1));
    llvm::BasicBlock* latch = b.GetInsertBlock();
    k->addIncoming(k1, latch);
    for (unsigned c = 0; c < width; ++c) sums[c]->addIncoming(next[c], latch);
    b.CreateCondBr(b.CreateICmpULT(k1, count), body, exit);

    b.SetInsertPoint(exit);
    std::vector<llvm::PHINode*> outs;  // (a block's phis before anything else)
    for (unsigned c = 0; c < width; ++c) {
        outs.push_back(b.CreatePHI(f32, 2));
        outs.back()->addIncoming(initial[c], entry);
        outs.back()->addIncoming(next[c], latch);
    }
    for (unsigned c = 0; c < width; ++c) b.CreateAlignedStore(outs[c], b.CreateConstGEP1_32(f32, acc, c), llvm::Align(4));
    b.CreateRetVoid();
}

}  // namespace psys::codegen_llvm
