#include "codegen_llvm/library_symbols.h"

#include <llvm/ExecutionEngine/Orc/Shared/OrcError.h>

namespace psys::codegen_llvm {

namespace {

// `error` with a duplicate definition taken as success.
llvm::Error unlessDuplicate(llvm::Error error, bool* duplicate = nullptr) {
    return llvm::handleErrors(std::move(error), [&](const llvm::orc::DuplicateDefinition&) {
        if (duplicate) *duplicate = true;
    });
}

}  // namespace

llvm::Error defineMissing(llvm::orc::JITDylib& jd, llvm::orc::SymbolMap symbols) {
    // One define for the batch (the common case); one a symbol when some were there.
    bool duplicate = false;
    if (llvm::Error error = unlessDuplicate(jd.define(llvm::orc::absoluteSymbols(symbols)), &duplicate)) return error;
    if (!duplicate) return llvm::Error::success();
    for (auto& [name, definition] : symbols) {
        llvm::orc::SymbolMap one{{name, definition}};
        if (llvm::Error error = unlessDuplicate(jd.define(llvm::orc::absoluteSymbols(std::move(one))))) return error;
    }
    return llvm::Error::success();
}

llvm::Expected<std::unique_ptr<llvm::orc::DynamicLibrarySearchGenerator>> librarySymbols(const char* library,
                                                                                         char globalPrefix) {
    return llvm::orc::DynamicLibrarySearchGenerator::Load(library, globalPrefix, {}, defineMissing);
}

}  // namespace psys::codegen_llvm
