// A JITLink plugin that looks at each graph once it is linked at its final addresses:
// what the perf map (perf_map.cpp) and the record of library calls (jit_engine.cpp) need.
// The rest of the plugin interface does nothing here.
#pragma once

#include <llvm/ExecutionEngine/JITLink/JITLink.h>
#include <llvm/ExecutionEngine/Orc/ObjectLinkingLayer.h>

namespace psys::codegen_llvm {

class LinkObserver : public llvm::orc::ObjectLinkingLayer::Plugin {
public:
    void modifyPassConfig(llvm::orc::MaterializationResponsibility&, llvm::jitlink::LinkGraph&,
                          llvm::jitlink::PassConfiguration& config) override {
        config.PostFixupPasses.push_back([this](llvm::jitlink::LinkGraph& graph) {
            linked(graph);
            return llvm::Error::success();
        });
    }
    llvm::Error notifyFailed(llvm::orc::MaterializationResponsibility&) override { return llvm::Error::success(); }
    llvm::Error notifyRemovingResources(llvm::orc::JITDylib&, llvm::orc::ResourceKey) override {
        return llvm::Error::success();
    }
    void notifyTransferringResources(llvm::orc::JITDylib&, llvm::orc::ResourceKey, llvm::orc::ResourceKey) override {}

protected:
    // Called on the linking thread (modules link on several at once).
    virtual void linked(llvm::jitlink::LinkGraph& graph) = 0;
};

}  // namespace psys::codegen_llvm
