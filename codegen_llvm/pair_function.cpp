// A neighbour group's walk and pair kernel for one object (rt::PairFunction): the
// run-time hands over the buckets of the 27 cells around the object; this code walks
// their places, tests each one's distance exactly as the run-time's walk does (no
// contraction into a fused multiply-add, whatever the maths: the neighbours are the same
// on every backend) and keeps the neighbours' places, then computes each neighbour's
// terms and combines them into the folds in the grid's order, as core/fold.h's combine
// does (the interpreter's result in exact maths). Compiled for the machine, as the update
// loops are.
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
    //           const rt::PairWalk* walk, const Value* externs, float* acc)
    auto* fn = llvm::Function::Create(llvm::FunctionType::get(b.getVoidTy(), {ptr, ptr, i32, ptr, ptr, ptr}, false),
                                      llvm::Function::ExternalLinkage, name, module);
    for (unsigned a : {0u, 1u, 3u, 4u, 5u}) fn->getArg(a)->addAttr(llvm::Attribute::NoAlias);
    llvm::Value *self = fn->getArg(0), *other = fn->getArg(1), *selfRow = fn->getArg(2), *walk = fn->getArg(3);
    llvm::Value *externs = fn->getArg(4), *acc = fn->getArg(5);
    auto* entry = llvm::BasicBlock::Create(ctx, "entry", fn);
    auto* bucketHead = llvm::BasicBlock::Create(ctx, "bucket", fn);
    auto* placeHead = llvm::BasicBlock::Create(ctx, "place", fn);
    auto* bucketLatch = llvm::BasicBlock::Create(ctx, "next.bucket", fn);
    auto* found = llvm::BasicBlock::Create(ctx, "found", fn);
    auto* body = llvm::BasicBlock::Create(ctx, "neighbour", fn);
    auto* exit = llvm::BasicBlock::Create(ctx, "exit", fn);
    b.SetInsertPoint(entry);
    // rt::PairWalk's fields
    llvm::StructType* walkType =
        llvm::StructType::get(ctx, {ptr, ptr, ptr, ptr, ptr, ptr, ptr, i32, i32, f32, f32, f32, f32});
    auto field = [&](unsigned f, llvm::Type* t) {
        return b.CreateAlignedLoad(t, b.CreateStructGEP(walkType, walk, f), llvm::Align(t == ptr ? 8 : 4));
    };
    llvm::Value *buckets = field(0, ptr), *start = field(1, ptr), *gx = field(2, ptr), *gy = field(3, ptr);
    llvm::Value *gz = field(4, ptr), *rows = field(5, ptr), *scratch = field(6, ptr), *count = field(7, i32);
    llvm::Value *skip = field(8, i32), *px = field(9, f32), *py = field(10, f32), *pz = field(11, f32);
    llvm::Value* radius2 = field(12, f32);

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
    b.CreateCondBr(b.CreateICmpUGT(count, b.getInt32(0)), bucketHead, found);

    // The walk: every place of every bucket, its place kept in `scratch` where within the
    // radius and not this object — without a branch per place (a third of them are kept:
    // a branch would often be mispredicted).
    b.SetInsertPoint(bucketHead);
    llvm::PHINode* k = b.CreatePHI(i32, 2, "k");
    llvm::PHINode* keptBefore = b.CreatePHI(i32, 2, "kept");
    llvm::Value* bucket = b.CreateAlignedLoad(i32, b.CreateGEP(i32, buckets, k), llvm::Align(4));
    llvm::Value* first = b.CreateAlignedLoad(i32, b.CreateGEP(i32, start, bucket), llvm::Align(4));
    llvm::Value* last = b.CreateAlignedLoad(i32, b.CreateGEP(i32, start, b.CreateAdd(bucket, b.getInt32(1))), llvm::Align(4));
    b.CreateCondBr(b.CreateICmpULT(first, last), placeHead, bucketLatch);

    b.SetInsertPoint(placeHead);
    llvm::PHINode* j = b.CreatePHI(i32, 2, "j");
    llvm::PHINode* kept = b.CreatePHI(i32, 2, "kept.place");
    auto placed = [&](llvm::Value* column) { return b.CreateAlignedLoad(f32, b.CreateGEP(f32, column, j), llvm::Align(4)); };
    llvm::Value* dx = b.CreateFSub(placed(gx), px);
    llvm::Value* dy = b.CreateFSub(placed(gy), py);
    llvm::Value* dz = b.CreateFSub(placed(gz), pz);
    llvm::Value* d2 = b.CreateFAdd(b.CreateFAdd(b.CreateFMul(dx, dx), b.CreateFMul(dy, dy)), b.CreateFMul(dz, dz));
    llvm::Value* itself = b.CreateICmpEQ(b.CreateAlignedLoad(i32, b.CreateGEP(i32, rows, j), llvm::Align(4)), skip);
    llvm::Value* keep = b.CreateAnd(b.CreateFCmpOLE(d2, radius2), b.CreateNot(itself));
    b.CreateAlignedStore(j, b.CreateGEP(i32, scratch, kept), llvm::Align(4));
    llvm::Value* keptAfter = b.CreateAdd(kept, b.CreateZExt(keep, i32));
    llvm::Value* j1 = b.CreateAdd(j, b.getInt32(1));
    b.CreateCondBr(b.CreateICmpULT(j1, last), placeHead, bucketLatch);
    j->addIncoming(first, bucketHead);
    j->addIncoming(j1, placeHead);
    kept->addIncoming(keptBefore, bucketHead);
    kept->addIncoming(keptAfter, placeHead);

    b.SetInsertPoint(bucketLatch);
    llvm::PHINode* keptBucket = b.CreatePHI(i32, 2, "kept.bucket");
    keptBucket->addIncoming(keptBefore, bucketHead);
    keptBucket->addIncoming(keptAfter, placeHead);
    llvm::Value* k1 = b.CreateAdd(k, b.getInt32(1));
    b.CreateCondBr(b.CreateICmpULT(k1, count), bucketHead, found);
    k->addIncoming(b.getInt32(0), entry);
    k->addIncoming(k1, bucketLatch);
    keptBefore->addIncoming(b.getInt32(0), entry);
    keptBefore->addIncoming(keptBucket, bucketLatch);

    // Then each neighbour's terms, in the walk's order.
    b.SetInsertPoint(found);
    llvm::PHINode* neighbours = b.CreatePHI(i32, 2, "neighbours");
    neighbours->addIncoming(b.getInt32(0), entry);
    neighbours->addIncoming(keptBucket, bucketLatch);
    b.CreateCondBr(b.CreateICmpUGT(neighbours, b.getInt32(0)), body, exit);

    b.SetInsertPoint(body);
    llvm::PHINode* n = b.CreatePHI(i32, 2, "n");
    n->addIncoming(b.getInt32(0), found);
    std::vector<llvm::PHINode*> sums;
    for (unsigned c = 0; c < width; ++c) {
        sums.push_back(b.CreatePHI(f32, 2));
        sums.back()->addIncoming(initial[c], found);
    }
    llvm::Value* row = b.CreateAlignedLoad(i32, b.CreateGEP(i32, scratch, n), llvm::Align(4));  // (a place)
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
    llvm::Value* n1 = b.CreateAdd(n, b.getInt32(1));
    llvm::BasicBlock* latch = b.GetInsertBlock();
    n->addIncoming(n1, latch);
    for (unsigned c = 0; c < width; ++c) sums[c]->addIncoming(next[c], latch);
    b.CreateCondBr(b.CreateICmpULT(n1, neighbours), body, exit);

    b.SetInsertPoint(exit);
    std::vector<llvm::PHINode*> outs;  // (a block's phis before anything else)
    for (unsigned c = 0; c < width; ++c) {
        outs.push_back(b.CreatePHI(f32, 2));
        outs.back()->addIncoming(initial[c], found);
        outs.back()->addIncoming(next[c], latch);
    }
    for (unsigned c = 0; c < width; ++c) b.CreateAlignedStore(outs[c], b.CreateConstGEP1_32(f32, acc, c), llvm::Align(4));
    b.CreateRetVoid();
}

}  // namespace psys::codegen_llvm
