#include "codegen_llvm/optimize.h"

#include <llvm/Analysis/TargetLibraryInfo.h>
#include <llvm/Passes/PassBuilder.h>

namespace psys::codegen_llvm {

namespace {

// LLVM's libmvec list stops at 8 lanes; with AVX-512 the loops run 16 floats a register
// (floatLanes), and a call without a 16-lane variant is made once per lane: the fire at
// 16 lanes spent 57% of its time in scalar expf. glibc has the 16-lane (AVX-512) variants
// of the same functions; these are they, for CPUs with AVX-512F.
llvm::ArrayRef<llvm::VecDesc> wideVectorMath() {
    static const auto sixteen = llvm::ElementCount::getFixed(16);
    static const llvm::VecDesc functions[] = {
        {"sinf", "_ZGVeN16v_sinf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"llvm.sin.f32", "_ZGVeN16v_sinf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"cosf", "_ZGVeN16v_cosf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"llvm.cos.f32", "_ZGVeN16v_cosf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"tanf", "_ZGVeN16v_tanf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"llvm.tan.f32", "_ZGVeN16v_tanf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"expf", "_ZGVeN16v_expf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"llvm.exp.f32", "_ZGVeN16v_expf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"logf", "_ZGVeN16v_logf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"llvm.log.f32", "_ZGVeN16v_logf", sixteen, false, "_ZGV_LLVM_N16v"},
        {"powf", "_ZGVeN16vv_powf", sixteen, false, "_ZGV_LLVM_N16vv"},
        {"llvm.pow.f32", "_ZGVeN16vv_powf", sixteen, false, "_ZGV_LLVM_N16vv"},
    };
    return functions;
}

}  // namespace

void optimizeModule(llvm::Module& module, llvm::TargetMachine& machine, MathMode mode, bool avx512) {
    llvm::LoopAnalysisManager lam;
    llvm::FunctionAnalysisManager fam;
    llvm::CGSCCAnalysisManager cgam;
    llvm::ModuleAnalysisManager mam;
    llvm::PipelineTuningOptions tuning;
    tuning.LoopVectorization = true;
    tuning.SLPVectorization = true;
    // Interleaving adds code (and compile time) for loops that are bound by memory.
    tuning.LoopInterleaving = false;
    llvm::PassBuilder builder(&machine, tuning);
    llvm::TargetLibraryInfoImpl library(llvm::Triple(module.getTargetTriple()));
    if (mode == MathMode::Fast && llvm::Triple(module.getTargetTriple()).isX86()) {  // glibc's x86 libmvec
        library.addVectorizableFunctionsFromVecLib(llvm::TargetLibraryInfoImpl::LIBMVEC_X86,
                                                   llvm::Triple(module.getTargetTriple()));
        if (avx512) library.addVectorizableFunctions(wideVectorMath());
    }
    fam.registerPass([&] { return llvm::TargetLibraryAnalysis(library); });
    builder.registerModuleAnalyses(mam);
    builder.registerCGSCCAnalyses(cgam);
    builder.registerFunctionAnalyses(fam);
    builder.registerLoopAnalyses(lam);
    builder.crossRegisterProxies(lam, fam, cgam, mam);
    builder.buildPerModuleDefaultPipeline(llvm::OptimizationLevel::O3).run(module, mam);
}

bool prepareForCodegen(llvm::Module& module) {
    size_t instructions = 0;
    for (llvm::Function& f : module) {
        instructions += f.getInstructionCount();
        std::vector<llvm::BasicBlock*> blocks;
        for (llvm::BasicBlock& b : f) blocks.push_back(&b);
        for (llvm::BasicBlock* b : blocks) {
            while (b->size() > 2 * kBlock) {
                auto at = b->getFirstInsertionPt();
                std::advance(at, kBlock);
                b = b->splitBasicBlock(at);
            }
        }
    }
    return instructions > kLargeModule;
}

}  // namespace psys::codegen_llvm
