#include "codegen_llvm/aot_object.h"

#include <algorithm>
#include <set>

#include <fmt/format.h>
#include <stdexcept>

#include <llvm/ADT/SmallVector.h>
#include <llvm/IR/Constants.h>
#include <llvm/IR/LegacyPassManager.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Linker/Linker.h>
#include <llvm/MC/MCSubtargetInfo.h>
#include <llvm/MC/TargetRegistry.h>
#include <llvm/TargetParser/Triple.h>
#include <llvm/Object/ArchiveWriter.h>
#include <llvm/Object/ObjectFile.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Support/raw_ostream.h>
#include <llvm/Target/TargetMachine.h>
#include <llvm/TargetParser/Host.h>

#include "codegen_llvm/kernel_functions.h"
#include "codegen_llvm/optimize.h"
#include "native/compiled_backend.h"

namespace psys::codegen_llvm {

namespace {

std::unique_ptr<llvm::TargetMachine> targetMachine(const AotTarget& target, std::string& triple, std::string& cpu) {
    const std::string wanted = target.cpus.empty() ? std::string() : target.cpus.front();
    llvm::InitializeAllTargetInfos();
    llvm::InitializeAllTargets();
    llvm::InitializeAllTargetMCs();
    llvm::InitializeAllAsmPrinters();
    std::string host = llvm::sys::getProcessTriple();  // as the JIT's (JITTargetMachineBuilder::detectHost)
    triple = target.triple.empty() ? host : target.triple;
    std::string features;
    bool native = wanted == "native";  // as compilers spell the host's CPU (-march=native)
    if (native && llvm::Triple::normalize(triple) != llvm::Triple::normalize(host))
        throw std::runtime_error("`native` is this machine's CPU, and `" + triple + "` is not this machine (" + host + ")");
    if (!wanted.empty() && !native) {
        cpu = wanted;
    } else if (triple == host) {  // the host's CPU and every feature it has
        cpu = llvm::sys::getHostCPUName().str();
        for (const auto& [name, on] : llvm::sys::getHostCPUFeatures())
            features += (features.empty() ? "" : ",") + std::string(on ? "+" : "-") + name.str();
    } else {
        cpu = "generic";
    }
    std::string error;
    const llvm::Target* found = llvm::TargetRegistry::lookupTarget(triple, error);
    if (!found) throw std::runtime_error("target `" + triple + "`: " + error);
    std::unique_ptr<llvm::MCSubtargetInfo> known(found->createMCSubtargetInfo(triple, "", ""));
    if (!known || !known->isCPUStringValid(cpu)) throw std::runtime_error("`" + cpu + "` is not a CPU of " + triple);
    llvm::TargetOptions options;
    std::unique_ptr<llvm::TargetMachine> machine(found->createTargetMachine(
        triple, cpu, features, options, llvm::Reloc::PIC_, std::nullopt, llvm::CodeGenOptLevel::Aggressive));
    if (!machine) throw std::runtime_error("LLVM cannot compile for `" + triple + "` (" + cpu + ")");
    return machine;
}

// A constant global of `module` (made by the module: GCC's -Wmismatched-new-delete takes a
// `new GlobalVariable` in this file for a mismatched allocation at -O1).
llvm::GlobalVariable* global(llvm::Module& module, llvm::Constant* value, llvm::GlobalValue::LinkageTypes linkage,
                             const std::string& name) {
    auto* g = llvm::cast<llvm::GlobalVariable>(module.getOrInsertGlobal(name, value->getType()));
    g->setInitializer(value);
    g->setConstant(true);
    g->setLinkage(linkage);
    return g;
}

llvm::Constant* text(llvm::Module& module, const std::string& value, const std::string& name) {
    llvm::Constant* data = llvm::ConstantDataArray::getString(module.getContext(), value, true);
    llvm::GlobalVariable* g = global(module, data, llvm::GlobalValue::PrivateLinkage, name);
    g->setUnnamedAddr(llvm::GlobalValue::UnnamedAddr::Global);
    return g;
}

}  // namespace

namespace {

// One module's machine code, generated as the JIT generates it (optimize.h).
std::string emitObject(llvm::Module& module, llvm::TargetMachine& machine, llvm::TargetMachine& large) {
    llvm::TargetMachine& chosen = prepareForCodegen(module) ? large : machine;
    llvm::SmallVector<char, 0> buffer;
    llvm::raw_svector_ostream object(buffer);
    llvm::legacy::PassManager passes;
    if (chosen.addPassesToEmitFile(passes, object, nullptr, llvm::CodeGenFileType::ObjectFile))
        throw std::runtime_error("LLVM cannot write an object file for " + chosen.getTargetTriple().str());
    passes.run(module);
    return std::string(buffer.begin(), buffer.end());
}

void verify(const llvm::Module& module) {
    std::string problems;
    llvm::raw_string_ostream stream(problems);
    if (llvm::verifyModule(module, &stream)) throw std::runtime_error("the LLVM backend built invalid IR: " + problems);
}

// The undefined symbols of an object: what it needs from outside.
void undefinedSymbols(const std::string& bytes, std::set<std::string>& out) {
    auto file = llvm::object::ObjectFile::createObjectFile(llvm::MemoryBufferRef(llvm::StringRef(bytes), "kernel"));
    if (!file) throw std::runtime_error(llvm::toString(file.takeError()));
    for (const llvm::object::SymbolRef& s : (*file)->symbols()) {
        auto flags = s.getFlags();
        auto name = s.getName();
        if (flags && name && (*flags & llvm::object::SymbolRef::SF_Undefined) && !name->empty())
            out.insert(name->str());
        if (!flags) llvm::consumeError(flags.takeError());
        if (!name) llvm::consumeError(name.takeError());
    }
}

}  // namespace

const char* const kCheckedFeatures[] = {
    "sse3",     "ssse3",      "sse4.1",     "sse4.2",     "popcnt",       "avx",          "avx2",       "fma",
    "bmi",      "bmi2",       "aes",        "pclmul",     "gfni",         "vpclmulqdq",   "avx512f",    "avx512dq",
    "avx512cd", "avx512bw",   "avx512vl",   "avx512vnni", "avx512bf16",   "avx512vbmi",   "avx512vbmi2",
    "avx512ifma", "avx512bitalg", "avx512vpopcntdq", nullptr};

namespace {

// One CPU of a build: its target machines (the large functions' without optimization, as
// the JIT's), the features its code may use, and its kernels' rows of the table. Each
// launch shape's code, once per key, is in a module of its own as the JIT compiles it (the
// same code, bit for bit), hidden (two builds link into one host side by side).
struct CpuKernels {
    std::string name, features;
    std::unique_ptr<llvm::TargetMachine> machine, large;
    std::vector<llvm::Constant*> rows;
};

CpuKernels machinesFor(const AotTarget& target, const std::string& cpu, std::string& triple) {
    CpuKernels out;
    AotTarget one{target.triple, {cpu}};
    out.machine = targetMachine(one, triple, out.name);
    out.large = targetMachine(one, triple, out.name);
    out.large->setOptLevel(llvm::CodeGenOptLevel::None);
    const llvm::MCSubtargetInfo& subtarget = *out.machine->getMCSubtargetInfo();
    if (out.machine->getTargetTriple().isX86())
        for (const char* const* f = kCheckedFeatures; *f; ++f)
            if (subtarget.checkFeatures(std::string("+") + *f)) out.features += (out.features.empty() ? "" : ",") + std::string(*f);
    return out;
}

}  // namespace

AotObject buildAotObject(const ir::Module& module, const std::string& irText, const std::string& glsl, MathMode mode,
                         const AotTarget& target, const std::string& symbol) {
    AotObject out;
    std::vector<CpuKernels> cpus;
    for (const std::string& cpu : target.cpus.empty() ? std::vector<std::string>{""} : target.cpus)
        cpus.push_back(machinesFor(target, cpu, out.triple));
    // The most capable first (the most features; else as given): psys_open_aot runs the
    // first the machine can.
    std::stable_sort(cpus.begin(), cpus.end(), [](const CpuKernels& a, const CpuKernels& b) {
        return std::count(a.features.begin(), a.features.end(), ',') + !a.features.empty() >
               std::count(b.features.begin(), b.features.end(), ',') + !b.features.empty();
    });
    llvm::LLVMContext context;
    llvm::TargetMachine& first = *cpus.front().machine;
    auto newModule = [&](const std::string& name) {
        auto m = std::make_unique<llvm::Module>(name, context);
        m->setDataLayout(first.createDataLayout());
        m->setTargetTriple(out.triple);
        return m;
    };
    auto table = newModule(symbol);
    llvm::Type* i32 = llvm::Type::getInt32Ty(context);
    llvm::Type* i64 = llvm::Type::getInt64Ty(context);
    llvm::Type* ptr = llvm::PointerType::get(context, 0);
    auto* kernelType = llvm::StructType::get(context, {i64, i64, ptr});
    auto* cpuType = llvm::StructType::get(context, {ptr, ptr, i64, ptr});
    std::set<std::string> calls;
    std::vector<llvm::Constant*> cpuRows;
    std::unique_ptr<llvm::Module> largeKernels;  // (none, mostly)
    for (size_t c = 0; c < cpus.size(); ++c) {
        CpuKernels& cpu = cpus[c];
        llvm::TargetMachine& machine = *cpu.machine;
        // Floats a vector register holds, as the JIT's floatLanes() says for the host.
        const llvm::MCSubtargetInfo& subtarget = *machine.getMCSubtargetInfo();
        bool x86 = machine.getTargetTriple().isX86();
        bool avx512 = x86 && subtarget.checkFeatures("+avx512f");
        unsigned lanes = avx512 ? 16 : x86 && subtarget.checkFeatures("+avx") ? 8 : 4;
        std::set<std::pair<uint64_t, uint64_t>> seen;
        const std::string prefix = cpus.size() == 1 ? symbol : fmt::format("{}.cpu{}", symbol, c);
        for (const native::Request& r : native::requests(mode == MathMode::Exact, module)) {
            if (!seen.insert({r.key.low, r.key.high}).second) continue;
            std::string name = prefix + "." + functionName(r, static_cast<int>(cpu.rows.size()));
            auto kernel = newModule(name);
            buildFunction(*kernel, mode, lanes, r, name);
            verify(*kernel);
            optimizeModule(*kernel, machine, mode, avx512);
            // Into the table's module, local to it, each function compiled for its CPU (its
            // attributes) — but a kernel too large for the optimizing code generator, which
            // goes into an object of its own made as the JIT makes it (CodeGenOptLevel::
            // None: the register allocator is the machine's, not a function's), its symbol
            // hidden.
            const bool large = prepareForCodegen(*kernel);
            for (llvm::Function& f : *kernel) {
                if (f.isDeclaration()) continue;
                f.addFnAttr("target-cpu", machine.getTargetCPU());
                f.addFnAttr("target-features", machine.getTargetFeatureString());
            }
            if (large && !largeKernels) largeKernels = newModule(symbol + ".large");
            llvm::Module& into = large ? *largeKernels : *table;
            llvm::FunctionType* type = kernel->getFunction(name)->getFunctionType();
            if (llvm::Linker::linkModules(into, std::move(kernel)))
                throw std::runtime_error("LLVM could not link kernel " + name + " into the build's object");
            llvm::Function* declared = table->getFunction(name);
            if (large) {
                into.getFunction(name)->setVisibility(llvm::GlobalValue::HiddenVisibility);
                declared = llvm::Function::Create(type, llvm::GlobalValue::ExternalLinkage, name, *table);
                declared->setVisibility(llvm::GlobalValue::HiddenVisibility);
            } else {
                declared->setLinkage(llvm::GlobalValue::InternalLinkage);
            }
            cpu.rows.push_back(llvm::ConstantStruct::get(
                kernelType, {llvm::ConstantInt::get(i64, r.key.low), llvm::ConstantInt::get(i64, r.key.high), declared}));
        }
        auto* tableType = llvm::ArrayType::get(kernelType, cpu.rows.size());
        llvm::GlobalVariable* kernels = global(*table, llvm::ConstantArray::get(tableType, cpu.rows),
                                               llvm::GlobalValue::PrivateLinkage, prefix + ".kernels");
        cpuRows.push_back(llvm::ConstantStruct::get(
            cpuType, {text(*table, cpu.name, prefix + ".cpu"), text(*table, cpu.features, prefix + ".features"),
                      llvm::ConstantInt::get(i64, cpu.rows.size()), kernels}));
        out.cpus.push_back(cpu.name);
        out.kernels += cpu.rows.size();
    }
    llvm::GlobalVariable* cpuTable = global(*table, llvm::ConstantArray::get(llvm::ArrayType::get(cpuType, cpuRows.size()), cpuRows),
                                            llvm::GlobalValue::PrivateLinkage, symbol + ".cpus");
    // psys_aot: abi, exact, name, ir, cpu_count, cpus, glsl, target.
    auto* aotType = llvm::StructType::get(context, {i32, i32, ptr, ptr, i64, ptr, ptr, ptr});
    llvm::Constant* shaders = glsl.empty() ? llvm::ConstantPointerNull::get(llvm::PointerType::get(context, 0))
                                           : text(*table, glsl, symbol + ".glsl");
    llvm::Constant* aot = llvm::ConstantStruct::get(
        aotType, {llvm::ConstantInt::get(i32, native::kAotAbi), llvm::ConstantInt::get(i32, mode == MathMode::Exact ? 1 : 0),
                  text(*table, symbol, symbol + ".name"), text(*table, irText, symbol + ".ir"),
                  llvm::ConstantInt::get(i64, cpuRows.size()), cpuTable, shaders,
                  text(*table, out.triple, symbol + ".target")});
    global(*table, aot, llvm::GlobalValue::ExternalLinkage, symbol);
    // (Every function's own machine: its attributes. Its blocks were split with it.)
    for (llvm::Function& f : *table)
        if (!f.isDeclaration() && f.getLinkage() != llvm::GlobalValue::InternalLinkage)
            f.setLinkage(llvm::GlobalValue::InternalLinkage);
    verify(*table);
    std::vector<std::pair<std::string, std::string>> objects;  // member name, bytes
    objects.push_back({"system.o", emitObject(*table, first, first)});
    if (largeKernels) {
        verify(*largeKernels);
        objects.push_back({"large.o", emitObject(*largeKernels, first, *cpus.front().large)});
    }
    for (const auto& [name, bytes] : objects) undefinedSymbols(bytes, calls);
    for (const std::string& c : calls)
        if (!c.starts_with(symbol + ".")) out.calls.push_back(c);

    // One archive: system.o's one global symbol is the psys_aot (kernels and tables are
    // local to it: two builds linked into one host share no name), and large.o, where a
    // build has one, holds the kernels too large for it, hidden.
    std::vector<llvm::NewArchiveMember> members;
    for (auto& [name, bytes] : objects) {
        llvm::NewArchiveMember member(llvm::MemoryBufferRef(bytes, name));
        member.MemberName = name;
        members.push_back(std::move(member));
    }
    std::string archive;
    llvm::raw_string_ostream stream(archive);
    if (llvm::Error e = llvm::writeArchiveToStream(stream, members, llvm::SymtabWritingMode::NormalSymtab,
                                                   llvm::object::Archive::K_GNU, true, false))
        throw std::runtime_error(llvm::toString(std::move(e)));
    stream.flush();
    out.bytes = std::move(archive);
    return out;
}

}  // namespace psys::codegen_llvm
