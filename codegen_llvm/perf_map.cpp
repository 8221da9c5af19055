// The perf map writer (codegen_llvm/perf_map.h): a plugin of ORC's JITLink layer that,
// after a graph is fixed up at its final addresses (LinkObserver), appends each defined
// callable symbol with its address and size. Lines are written whole under a lock: modules link on
// several compile threads at once.
#include "codegen_llvm/perf_map.h"

#include <algorithm>
#include <cstdio>
#include <vector>
#include <cstdlib>
#include <mutex>

#include <unistd.h>

#include <llvm/ExecutionEngine/Orc/LLJIT.h>

#include "codegen_llvm/link_observer.h"

namespace psys::codegen_llvm {

namespace {

class PerfMapPlugin : public LinkObserver {
public:
    explicit PerfMapPlugin(std::FILE* file) : file_(file) {}
    ~PerfMapPlugin() override { std::fclose(file_); }

protected:
    void linked(llvm::jitlink::LinkGraph& graph) override { write(graph); }

private:
    // A module's exported function is a named symbol; the internal functions it calls (a
    // kernel's `.loop`) lose their symbols in linking, so the code of a block that no
    // named symbol covers is written as `<the block's function>.loop`.
    void write(llvm::jitlink::LinkGraph& graph) {
        std::lock_guard lock(mutex_);
        for (llvm::jitlink::Block* block : graph.blocks()) {
            const auto prot = static_cast<unsigned>(block->getSection().getMemProt());
            if (!(prot & static_cast<unsigned>(llvm::orc::MemProt::Exec))) continue;
            std::vector<llvm::jitlink::Symbol*> named;
            for (llvm::jitlink::Symbol* symbol : graph.defined_symbols())
                if (&symbol->getBlock() == block && symbol->isCallable() && symbol->hasName() && symbol->getSize() > 0)
                    named.push_back(symbol);
            if (named.empty()) continue;
            std::sort(named.begin(), named.end(),
                      [](auto* a, auto* b) { return a->getAddress() < b->getAddress(); });
            uint64_t at = block->getAddress().getValue(), end = at + block->getSize();
            const std::string owner = named.front()->getName().str();
            auto line = [&](uint64_t from, uint64_t to, const std::string& name) {
                if (to > from) std::fprintf(file_, "%llx %llx %s\n", static_cast<unsigned long long>(from),
                                            static_cast<unsigned long long>(to - from), name.c_str());
            };
            for (llvm::jitlink::Symbol* symbol : named) {
                uint64_t start = symbol->getAddress().getValue();
                if (start >= at + kPadding) line(at, start, owner + ".loop");
                line(start, start + symbol->getSize(), symbol->getName().str());
                at = std::max(at, start + symbol->getSize());
            }
            if (end >= at + kPadding) line(at, end, owner + ".loop");
        }
        std::fflush(file_);
    }

    static constexpr uint64_t kPadding = 16;  // alignment between functions, not code
    std::FILE* file_;
    std::mutex mutex_;
};

}  // namespace

bool perfMapRequested() {
    const char* value = std::getenv("PSYS_PERF_MAP");
    return value && *value && std::string(value) != "0";
}

bool addPerfMap(llvm::orc::LLJIT& jit, std::string& error, std::string path) {
    auto* layer = llvm::dyn_cast<llvm::orc::ObjectLinkingLayer>(&jit.getObjLinkingLayer());
    if (!layer) {
        error = "the JIT does not link with JITLink: no function sizes for a perf map";
        return false;
    }
    if (path.empty()) path = "/tmp/perf-" + std::to_string(::getpid()) + ".map";
    std::FILE* file = std::fopen(path.c_str(), "a");
    if (!file) {
        error = "cannot open " + path + " for the perf map";
        return false;
    }
    layer->addPlugin(std::make_unique<PerfMapPlugin>(file));
    return true;
}

}  // namespace psys::codegen_llvm
