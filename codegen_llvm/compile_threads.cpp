#include "codegen_llvm/compile_threads.h"

#include <system_error>
#include <thread>
#include <utility>

#include <llvm/ExecutionEngine/Orc/Core.h>

namespace psys::codegen_llvm {

CompileThreads::CompileThreads(size_t materializers) : materializers_(materializers == 0 ? 1 : materializers) {}

CompileThreads::~CompileThreads() { shutdown(); }

void CompileThreads::dispatch(std::unique_ptr<llvm::orc::Task> task) {
    const bool materialization = llvm::isa<llvm::orc::MaterializationTask>(*task);
    {
        std::lock_guard lock(mutex_);
        if (materialization) {
            if (materializing_ == materializers_) {
                waiting_.push_back(std::move(task));
                return;
            }
            ++materializing_;
        }
        ++outstanding_;
    }
    // Other tasks get a thread each, whatever runs: a lookup's completion may be what a
    // materialization waits for. Where no thread can be had, the task runs here, as
    // LLVM's in-place dispatcher runs every task (it is counted: work counts it done).
    llvm::orc::Task* owned = task.release();
    try {
        std::thread([this, owned, materialization] { work(std::unique_ptr<llvm::orc::Task>(owned), materialization); })
            .detach();
    } catch (const std::system_error&) {
        work(std::unique_ptr<llvm::orc::Task>(owned), materialization);
    }
}

// A thread's tasks: its own, then waiting materializations while there are any. Each is
// freed before the thread takes the next or counts itself done, so that nothing a task
// holds outlives shutdown().
void CompileThreads::work(std::unique_ptr<llvm::orc::Task> task, bool materializing) {
    for (;;) {
        task->run();
        task.reset();
        std::lock_guard lock(mutex_);
        if (!waiting_.empty()) {
            task = std::move(waiting_.front());
            waiting_.pop_front();
            if (!materializing) ++materializing_, materializing = true;
            continue;
        }
        if (materializing) --materializing_;
        if (--outstanding_ == 0) idle_.notify_all();
        return;
    }
}

void CompileThreads::shutdown() {
    std::unique_lock lock(mutex_);
    idle_.wait(lock, [this] { return outstanding_ == 0; });
}

}  // namespace psys::codegen_llvm
