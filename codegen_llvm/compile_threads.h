#pragma once
// The JIT's compile threads: runs ORC's tasks (materializations, lookups' completions)
// the way LLVM 19's DynamicThreadPoolTaskDispatcher does — a thread a task, at most
// `materializers` materializations at once, the rest queued — but frees each task
// *before* it counts as done. LLVM 19's dispatcher frees a thread's last task after
// counting it, so `shutdown()` can return while that task's materialization unit still
// holds symbol names: the session then goes first and its symbol pool aborts ("Dangling
// references at pool destruction time": tests/llvm/jit_test.cpp's engine that goes right
// after compiling, in CI's ASan run). Later LLVMs free it first too.

#include <condition_variable>
#include <cstddef>
#include <deque>
#include <memory>
#include <mutex>

#include <llvm/ExecutionEngine/Orc/TaskDispatch.h>

namespace psys::codegen_llvm {

class CompileThreads final : public llvm::orc::TaskDispatcher {
public:
    explicit CompileThreads(size_t materializers);
    ~CompileThreads() override;
    void dispatch(std::unique_ptr<llvm::orc::Task> task) override;
    // Waits until every task dispatched so far, and every task they dispatch, has run and
    // been freed (a thread takes the waiting materializations before it counts itself
    // done). Called by the engine before the JIT goes, and again by the session's end,
    // which may dispatch more: they run, as LLVM's dispatcher runs them.
    void shutdown() override;

private:
    void work(std::unique_ptr<llvm::orc::Task> task, bool materializing);

    const size_t materializers_;
    std::mutex mutex_;
    std::condition_variable idle_;
    size_t outstanding_ = 0;    // threads running a task, or about to
    size_t materializing_ = 0;  // of them, those running a materialization
    std::deque<std::unique_ptr<llvm::orc::Task>> waiting_;  // materializations past the limit
};

}  // namespace psys::codegen_llvm
