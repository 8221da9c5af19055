#include "codegen_llvm/jit_engine.h"

#include <algorithm>
#include <functional>
#include <fstream>
#include <filesystem>
#include <cstdlib>
#include <atomic>
#include <cstdio>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>

#include <llvm/Analysis/TargetLibraryInfo.h>
#include <llvm/ExecutionEngine/Orc/CompileUtils.h>
#include <llvm/ExecutionEngine/Orc/ExecutionUtils.h>
#include <llvm/ExecutionEngine/Orc/ExecutorProcessControl.h>
#include <llvm/ExecutionEngine/Orc/JITTargetMachineBuilder.h>
#include <unistd.h>

#include "core/log.h"
#include "jit_build_id.h"  // PSYS_JIT_BUILD_ID (generated: codegen_llvm/CMakeLists.txt)

#include <llvm/Config/llvm-config.h>
#include <llvm/ExecutionEngine/JITLink/JITLink.h>
#include <llvm/Object/ObjectFile.h>
#include <llvm/ExecutionEngine/Orc/LLJIT.h>
#include <llvm/ExecutionEngine/Orc/ObjectLinkingLayer.h>
#include <llvm/ExecutionEngine/Orc/ThreadSafeModule.h>
#include <llvm/IR/DiagnosticInfo.h>
#include <llvm/IR/DiagnosticPrinter.h>
#include <llvm/IR/Verifier.h>
#include <llvm/Passes/PassBuilder.h>
#include <llvm/Support/TargetSelect.h>
#include <llvm/Target/TargetMachine.h>
#include <llvm/TargetParser/Host.h>

#include "codegen_llvm/compile_threads.h"
#include "codegen_llvm/library_symbols.h"
#include "codegen_llvm/link_observer.h"
#include "codegen_llvm/optimize.h"
#include "codegen_llvm/perf_map.h"
#include "ir/hash.h"

namespace psys::codegen_llvm {

// Named, not anonymous: JitEngine::Impl holds an ObjectCache, and a member of an
// internal type in a type with linkage is an error (-Wsubobject-linkage) wherever this
// file is not the main file (the unity build includes it).
namespace jit_detail {

// Keeps what the loop vectorizer says about each loop; every other diagnostic goes to
// LLVM's default printing (none is expected).
struct RemarkCollector : llvm::DiagnosticHandler {
    std::vector<rt::BackendReport::Remark>* out;
    std::mutex* mutex;  // modules are optimized on several threads
    RemarkCollector(std::vector<rt::BackendReport::Remark>* remarks, std::mutex* m) : out(remarks), mutex(m) {}
    bool isPassedOptRemarkEnabled(llvm::StringRef pass) const override { return pass == "loop-vectorize"; }
    bool isMissedOptRemarkEnabled(llvm::StringRef pass) const override { return pass == "loop-vectorize"; }
    bool isAnalysisRemarkEnabled(llvm::StringRef pass) const override { return pass == "loop-vectorize"; }
    bool isAnyRemarkEnabled() const override { return true; }
    bool handleDiagnostics(const llvm::DiagnosticInfo& info) override {
        auto* remark = llvm::dyn_cast<llvm::DiagnosticInfoOptimizationBase>(&info);
        if (!remark) return false;
        if (remark->getPassName() != "loop-vectorize") return true;
        if (!remark->isPassed() && !remark->isMissed()) return true;  // analyses explain misses
        std::lock_guard lock(*mutex);
        out->push_back({remark->getFunction().getName().str(), remark->isPassed(), remark->getMsg()});
        return true;
    }
};

// Compiled objects on disk, so that a second run of a program starts without waiting for
// LLVM: one file per module, named by a hash of the module's text before optimization,
// the CPU and its features, the maths mode and LLVM's version (all that decides the
// machine code). PSYS_JIT_CACHE names the folder, or turns it off ("0"); by default
// $XDG_CACHE_HOME/psys/jit or ~/.cache/psys/jit. A file is written whole (to a temporary
// name, then renamed), so a run never reads half an object; one that cannot be written
// is simply not cached.
class ObjectCache {
public:
    // The folder `chosen` names ("" : none), else the environment's.
    static std::optional<ObjectCache> from(const std::optional<std::string>& chosen) {
        if (!chosen) return fromEnvironment();
        if (chosen->empty()) return std::nullopt;
        ObjectCache cache;
        cache.folder_ = *chosen;
        cache.prune();
        return cache;
    }
    static std::optional<ObjectCache> fromEnvironment() {
        const char* setting = std::getenv("PSYS_JIT_CACHE");
        std::filesystem::path folder;
        if (setting && *setting) {
            if (std::string(setting) == "0") return std::nullopt;
            folder = setting;
        } else if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg) {
            folder = std::filesystem::path(xdg) / "psys" / "jit";
        } else if (const char* home = std::getenv("HOME"); home && *home) {
            folder = std::filesystem::path(home) / ".cache" / "psys" / "jit";
        } else {
            return std::nullopt;
        }
        ObjectCache cache;
        cache.folder_ = folder;
        cache.prune();
        return cache;
    }
    // At most kKept objects: past that, the least recently used go (a load touches its
    // file), down to three quarters. Run once per JIT, so edits do not fill the disk.
    static constexpr size_t kKept = 4096;
    void prune() const {
        std::error_code error;
        std::vector<std::pair<std::filesystem::file_time_type, std::filesystem::path>> objects;
        for (auto it = std::filesystem::directory_iterator(folder_, error); !error && it != std::filesystem::directory_iterator();
             it.increment(error))
            if (it->path().extension() == ".o") objects.push_back({it->last_write_time(error), it->path()});
        if (objects.size() <= kKept) return;
        std::sort(objects.begin(), objects.end());
        for (size_t i = 0; i < objects.size() - kKept * 3 / 4; ++i) {
            std::filesystem::path object = objects[i].second;
            std::filesystem::remove(object, error);
            std::filesystem::remove(object.replace_extension(".remarks"), error);
        }
    }
    // The key of a module: its text and what else decides its machine code.
    static std::string key(const llvm::Module& module, const std::string& machine) {
        std::string text;
        llvm::raw_string_ostream out(text);
        module.print(out, nullptr);
        // This backend's sources stand for how modules are optimized and compiled (their
        // hash, jit_build_id.h, made by the build): after an edit of them no object an
        // older build made is read; a build of the same sources reads them all.
        return ir::Hasher()
            .add(text)
            .add(machine)
            .add(std::string_view(LLVM_VERSION_STRING))
            .add(std::string_view(PSYS_JIT_BUILD_ID))
            .finish()
            .hex();
    }
    // The object stored under `key`, if there is one and it reads as an object file (a
    // damaged one is removed, and the module compiled again).
    std::unique_ptr<llvm::MemoryBuffer> load(const std::string& key) const {
        std::filesystem::path file = folder_ / (key + ".o");
        auto buffer = llvm::MemoryBuffer::getFile(file.string());
        if (!buffer) return nullptr;
        auto object = llvm::object::ObjectFile::createObjectFile((*buffer)->getMemBufferRef());
        std::error_code error;
        if (!object) {
            llvm::consumeError(object.takeError());
            std::filesystem::remove(file, error);
            return nullptr;
        }
        std::filesystem::last_write_time(file, std::filesystem::file_time_type::clock::now(), error);  // used
        return std::move(*buffer);
    }
    // The object, and beside it what the vectorizer said about the module's loops (a
    // cached module is not optimized again, so its remarks come from here).
    void store(const std::string& key, const llvm::MemoryBuffer& object, const std::string& remarks) const {
        if (key.size() != 32) return;  // not a module keyed for the cache
        std::error_code error;
        std::filesystem::create_directories(folder_, error);
        if (error) {  // said once a cache: the run goes on, compiling what it cannot keep
            if (!warned_->exchange(true))
                core::log(core::LogLevel::Warning, "the JIT's cache `" + folder_.string() + "` cannot be made (" +
                                                       error.message() + "): compiled kernels are not kept");
            return;
        }
        write(key + ".remarks", remarks.data(), remarks.size());  // first: an object never lacks its remarks
        write(key + ".o", object.getBufferStart(), object.getBufferSize());
    }
    std::string remarks(const std::string& key) const {
        std::ifstream in(folder_ / (key + ".remarks"), std::ios::binary);
        return {std::istreambuf_iterator<char>(in), {}};
    }
    const std::filesystem::path& folder() const { return folder_; }

private:
    void write(const std::string& name, const char* bytes, size_t size) const {
        std::error_code error;
        std::filesystem::path partial = folder_ / (name + "." + std::to_string(::getpid()) + ".part");
        {
            std::ofstream out(partial, std::ios::binary);
            out.write(bytes, static_cast<std::streamsize>(size));
            if (!out) {
                std::filesystem::remove(partial, error);
                return;
            }
        }
        std::filesystem::rename(partial, folder_ / name, error);
        if (error) std::filesystem::remove(partial, error);
    }
    std::filesystem::path folder_;
    // Whether store said it cannot make the folder (once: compile threads store at once).
    std::shared_ptr<std::atomic<bool>> warned_ = std::make_shared<std::atomic<bool>>(false);
};

// Machine code for a module, with compile time linear in its size (optimize.h, "Code
// generation"), read from the disk cache where it is there.
class SizedCompiler : public llvm::orc::IRCompileLayer::IRCompiler {
public:
    using Remarks = std::function<std::string(const llvm::Module&)>;
    SizedCompiler(llvm::orc::JITTargetMachineBuilder builder, const ObjectCache* cache, Remarks remarks)
        : IRCompiler(llvm::orc::irManglingOptionsFromTargetOptions(builder.getOptions())), builder_(std::move(builder)),
          cache_(cache), remarks_(std::move(remarks)) {}

    llvm::Expected<std::unique_ptr<llvm::MemoryBuffer>> operator()(llvm::Module& module) override {
        llvm::orc::JITTargetMachineBuilder builder = builder_;
        if (prepareForCodegen(module)) builder.setCodeGenOptLevel(llvm::CodeGenOptLevel::None);
        auto machine = builder.createTargetMachine();
        if (!machine) return machine.takeError();
        auto object = llvm::orc::SimpleCompiler(**machine)(module);
        if (object && cache_) cache_->store(module.getModuleIdentifier(), **object, remarks_(module));
        return object;
    }

private:
    llvm::orc::JITTargetMachineBuilder builder_;
    const ObjectCache* cache_;
    Remarks remarks_;
};

}  // namespace jit_detail

using namespace jit_detail;

// Records the external symbols each linked graph refers to: which library functions the
// compiled code calls (the vector maths it was meant to use, say).
class CallRecorder : public LinkObserver {
public:
    CallRecorder(std::set<std::string>* calls, std::mutex* mutex) : calls_(calls), mutex_(mutex) {}

protected:
    void linked(llvm::jitlink::LinkGraph& graph) override {
        std::lock_guard lock(*mutex_);
        for (llvm::jitlink::Symbol* symbol : graph.external_symbols())
            if (symbol->hasName() && !symbol->getName().starts_with("_GLOBAL_OFFSET_TABLE_"))
                calls_->insert(symbol->getName().str());
    }

private:
    std::set<std::string>* calls_;
    std::mutex* mutex_;
};

struct JitEngine::Impl {
    MathMode mode;
    std::optional<ObjectCache> cache;
    std::string machine;          // the CPU, its features and the maths mode: part of a cache key
    std::atomic<size_t> fromDisk = 0;
    std::mutex callsMutex;
    std::set<std::string> calls;
    bool avx512 = false;  // the host has AVX-512F: 16-lane loops, and their vector maths
    std::unique_ptr<llvm::orc::LLJIT> jit;
    std::optional<llvm::orc::JITTargetMachineBuilder> host;
    std::string cpu;
    std::mutex remarksMutex;
    std::vector<rt::BackendReport::Remark> remarks;

    // The remarks about `module`'s loops, one a line: loop, vectorized (0 or 1), message.
    std::string remarksOf(const llvm::Module& module) {
        std::set<std::string> functions;
        for (const llvm::Function& f : module) functions.insert(f.getName().str());
        std::lock_guard lock(remarksMutex);
        std::string out;
        for (const auto& r : remarks)
            if (functions.count(r.loop)) out += r.loop + "\t" + (r.vectorized ? "1" : "0") + "\t" + r.message + "\n";
        return out;
    }
    void addRemarks(const std::string& text) {
        std::lock_guard lock(remarksMutex);
        size_t at = 0;
        while (at < text.size()) {
            size_t end = text.find('\n', at), tab1 = text.find('\t', at);
            if (end == std::string::npos || tab1 == std::string::npos || tab1 + 3 > end) break;
            remarks.push_back({text.substr(at, tab1 - at), text[tab1 + 1] == '1', text.substr(tab1 + 3, end - tab1 - 3)});
            at = end + 1;
        }
    }

    // Runs on the JIT's compile threads: a target machine of its own for the cost model.
    void optimize(llvm::Module& module) {
        // The module may be in a context of the compile thread's by now: the remarks are
        // collected from whichever context it is in.
        module.getContext().setDiagnosticHandler(std::make_unique<RemarkCollector>(&remarks, &remarksMutex));
        auto made = llvm::orc::JITTargetMachineBuilder(*host).createTargetMachine();
        if (!made) throw std::runtime_error(llvm::toString(made.takeError()));
        optimizeModule(module, **made, mode, avx512);
    }
};

JitEngine::JitEngine(MathMode mode, std::optional<std::string> cache) : impl_(std::make_unique<Impl>()) {
    impl_->mode = mode;
    impl_->avx512 = llvm::sys::getHostCPUFeatures().lookup("avx512f");
    impl_->cache = ObjectCache::from(cache);
    llvm::InitializeNativeTarget();
    llvm::InitializeNativeTargetAsmPrinter();
    auto host = llvm::orc::JITTargetMachineBuilder::detectHost();
    if (!host) throw std::runtime_error(llvm::toString(host.takeError()));
    host->setCodeGenOptLevel(llvm::CodeGenOptLevel::Aggressive);
    impl_->cpu = host->getCPU();
    impl_->host = *host;
    impl_->machine = impl_->cpu + " " + host->getFeatures().getString() + (mode == MathMode::Fast ? " fast" : " exact");
    // Compile threads of our own (codegen_llvm/compile_threads.h): LLVM 19's own free a
    // task after shutdown() may have returned.
    auto control = llvm::orc::SelfExecutorProcessControl::Create(
        nullptr, std::make_unique<CompileThreads>(std::max(1u, std::thread::hardware_concurrency())));
    if (!control) throw std::runtime_error(llvm::toString(control.takeError()));
    auto jit = llvm::orc::LLJITBuilder()
                   .setJITTargetMachineBuilder(*host)
                   .setExecutorProcessControl(std::move(*control))
                   .setCompileFunctionCreator([cache = impl_->cache ? &*impl_->cache : nullptr, impl = impl_.get()](
                                                  llvm::orc::JITTargetMachineBuilder builder)
                                                  -> llvm::Expected<std::unique_ptr<llvm::orc::IRCompileLayer::IRCompiler>> {
                       return std::make_unique<SizedCompiler>(std::move(builder), cache,
                                                              [impl](const llvm::Module& m) { return impl->remarksOf(m); });
                   })
                   .setSupportConcurrentCompilation(true)
                   .create();
    if (!jit) throw std::runtime_error(llvm::toString(jit.takeError()));
    impl_->jit = std::move(*jit);
    if (auto* linker = llvm::dyn_cast<llvm::orc::ObjectLinkingLayer>(&impl_->jit->getObjLinkingLayer()))
        linker->addPlugin(std::make_unique<CallRecorder>(&impl_->calls, &impl_->callsMutex));
    if (perfMapRequested()) {
        std::string error;
        if (!addPerfMap(*impl_->jit, error)) core::log(core::LogLevel::Warning, "PSYS_PERF_MAP: " + error);
    }
    // The session's errors (LLVM prints "JIT session error: …" on standard error) through
    // the library's log (core/log.h): a host's sink gets them.
    impl_->jit->getExecutionSession().setErrorReporter([](llvm::Error error) {
        core::log(core::LogLevel::Error, "JIT session error: " + llvm::toString(std::move(error)));
    });
    impl_->jit->getIRTransformLayer().setTransform(
        [impl = impl_.get()](llvm::orc::ThreadSafeModule module, llvm::orc::MaterializationResponsibility&)
            -> llvm::Expected<llvm::orc::ThreadSafeModule> {
            module.withModuleDo([impl](llvm::Module& m) { impl->optimize(m); });
            return module;
        });
    // libm's functions come from this process, as the interpreter's do; libmvec's vector
    // functions from glibc's libmvec.
    const char prefix = impl_->jit->getDataLayout().getGlobalPrefix();
    auto process = librarySymbols(nullptr, prefix);
    if (!process) throw std::runtime_error(llvm::toString(process.takeError()));
    impl_->jit->getMainJITDylib().addGenerator(std::move(*process));
    if (mode == MathMode::Fast) {
        auto vectorMath = librarySymbols("libmvec.so.1", prefix);
        if (!vectorMath) throw std::runtime_error("glibc's vector math library: " + llvm::toString(vectorMath.takeError()));
        impl_->jit->getMainJITDylib().addGenerator(std::move(*vectorMath));
    }
}

// The compile threads may still be running tasks when the engine goes: a module of an
// `add` that failed, or the tail of one whose lookup has returned (LLVM 19 completes a
// query in a task of its own, so `add` can return while the thread that emitted the last
// module still tears its link down). LLJIT's end of session removes the dylibs first and
// waits for the threads after: the thread then finds its tracker defunct and frees into a
// dylib being cleared (psys_bench's compile loop on a loaded machine: a session error in 3
// runs of 120, once heap corruption in CI; 0 of 160 since). So the dispatcher is shut
// down first, which waits for every task to have run and been freed (CompileThreads),
// then the JIT goes, before Impl's members.
JitEngine::~JitEngine() {
    impl_->jit->getExecutionSession().getExecutorProcessControl().getDispatcher().shutdown();
    impl_->jit.reset();
}

std::string JitEngine::cpu() const { return impl_->cpu; }

// Floats in the host's widest vector register.
unsigned JitEngine::floatLanes() const {
    llvm::StringMap<bool> features = llvm::sys::getHostCPUFeatures();
    if (features.lookup("avx512f")) return 16;
    if (features.lookup("avx")) return 8;
    return 4;
}

std::unique_ptr<llvm::LLVMContext> JitEngine::newContext() const {
    auto context = std::make_unique<llvm::LLVMContext>();
    return context;
}

std::unique_ptr<llvm::Module> JitEngine::newModule(llvm::LLVMContext& context) const {
    auto module = std::make_unique<llvm::Module>("psys", context);
    module->setDataLayout(impl_->jit->getDataLayout());
    module->setTargetTriple(impl_->jit->getTargetTriple().str());
    return module;
}

std::vector<rt::BackendReport::Remark> JitEngine::remarks() const {
    std::lock_guard lock(impl_->remarksMutex);
    return impl_->remarks;
}

size_t JitEngine::fromDisk() const { return impl_->fromDisk; }

std::vector<std::string> JitEngine::calls() const {
    std::lock_guard lock(impl_->callsMutex);
    return {impl_->calls.begin(), impl_->calls.end()};
}

std::vector<void*> JitEngine::add(std::vector<Unit> units) {
    llvm::orc::SymbolLookupSet symbols;
    std::vector<llvm::orc::SymbolStringPtr> names;
    for (Unit& unit : units) {
        std::string problems;
        llvm::raw_string_ostream stream(problems);
        if (llvm::verifyModule(*unit.module, &stream))
            throw std::runtime_error("the LLVM backend built invalid IR: " + problems);
        std::unique_ptr<llvm::MemoryBuffer> cached;
        if (impl_->cache) {
            std::string key = ObjectCache::key(*unit.module, impl_->machine);
            cached = impl_->cache->load(key);
            unit.module->setModuleIdentifier(key);  // SizedCompiler stores the object under it
        }
        if (cached) {
            ++impl_->fromDisk;
            impl_->addRemarks(impl_->cache->remarks(unit.module->getModuleIdentifier()));
            if (auto err = impl_->jit->addObjectFile(std::move(cached)))
                throw std::runtime_error(llvm::toString(std::move(err)));
        } else if (auto err = impl_->jit->addIRModule(
                       llvm::orc::ThreadSafeModule(std::move(unit.module), std::move(unit.context)))) {
            throw std::runtime_error(llvm::toString(std::move(err)));
        }
        names.push_back(impl_->jit->mangleAndIntern(unit.name));
        symbols.add(names.back());
    }
    // One lookup for all: the modules are optimized and compiled on every compile thread.
    auto& session = impl_->jit->getExecutionSession();
    auto found = session.lookup({{&impl_->jit->getMainJITDylib(), llvm::orc::JITDylibLookupFlags::MatchAllSymbols}},
                                std::move(symbols));
    if (!found) throw std::runtime_error(llvm::toString(found.takeError()));
    std::vector<void*> addresses;
    for (const auto& name : names) addresses.push_back(found->at(name).getAddress().toPtr<void*>());
    return addresses;
}

}  // namespace psys::codegen_llvm
