// How the JIT gives its code the functions of this process and of libmvec: ORC's
// DynamicLibrarySearchGenerator, with the definitions added by defineMissing.
//
// Why not the generator's own define: ORC (19) decides which symbols a lookup must
// generate before it takes the generator (ExecutionSession::OL_applyQueryPhase1), so
// two modules linked at once on two compile threads can both ask the process for
// `sinf`; the second `define` then fails its whole batch ("Duplicate definition of
// symbol 'sinf'") and the kernel does not link. A symbol another lookup defined in
// the meantime has the same address, so defineMissing skips it.
#pragma once

#include <memory>

#include <llvm/ExecutionEngine/Orc/Core.h>
#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>

namespace psys::codegen_llvm {

// Defines `symbols` in `jd`, all of those not defined there yet.
llvm::Error defineMissing(llvm::orc::JITDylib& jd, llvm::orc::SymbolMap symbols);

// The generator for `library` (null: this process) with defineMissing.
llvm::Expected<std::unique_ptr<llvm::orc::DynamicLibrarySearchGenerator>> librarySymbols(const char* library,
                                                                                         char globalPrefix);

}  // namespace psys::codegen_llvm
