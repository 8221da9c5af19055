// The GLSL backend: runs a system's launches (rt/backend.h) as OpenGL 4.5 compute
// shaders emitted by codegen_glsl/, on whatever GL the machine has (a GPU's driver, or
// Mesa's llvmpipe on the CPU), headless through EGL unless a context is current.
//
// Where the columns live (gpu/gl_memory.h): an object's state and exports stay on the GPU
// from step to step, and shaders read and write them in place (storage blocks, buffer
// textures); the run-time's bookkeeping (kills, emissions, creation, parents) runs on
// the host, and so do the launches of the few rows of emitters (setHostSide), so a launch takes the rows of the masks that changed from the host and gives
// back, in one wait, its counts, the rows killed (compacted on the GPU: gpu/compact.h)
// and its emissions (docs/gpu.md) — or, for a late launch (rt::RowsLaunch::late), no wait:
// its counts and kills are taken when the run-time collects them (at the next step: its
// kills have cleared their rows in the alive mask the draws read, in their compaction).
#pragma once

#include <limits>
#include <map>
#include <span>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include "gpu/compact.h"
#include "gpu/gl_memory.h"
#include "gpu/pass_timer.h"
#include "rt/backend.h"

namespace psys::gpu {

class HeadlessContext;
class ProgramCompiler;
struct FoldWork;

class GlslBackend final : public rt::Backend {
public:
    // Null, and `error` set, when there is no OpenGL 4.5 to run on.
    static std::unique_ptr<GlslBackend> create(std::string& error);
    ~GlslBackend() override;

    std::string name() const override { return "glsl"; }
    rt::Memory& memory() override { return memory_; }
    void prepare(const rt::Plan& plan) override;
    // A program at a time, each compiled and linked at once (llvmpipe links on the calling
    // thread), until `seconds` are spent.
    bool prepareSome(const rt::Plan& plan, double seconds) override;
    void forget(const ir::Module& module) override;
    rt::RowsResult run(const rt::RowsLaunch& launch) override;
    void run(const rt::ChildrenLaunch& launch) override;
    // A spawn kernel's launches whose columns are on the GPU in one dispatch (a launch
    // block per emitter in the words); small ones on the host side as run() does.
    void runChildren(std::span<const rt::ChildrenLaunch> launches) override;
    rt::RowsResult collect(uint64_t ticket) override;
    bool ready(uint64_t ticket) override;
    bool clearsKilled() const override { return true; }
    // A neighbour group's folds on the GPU, grid and all (gpu/gl_fold.cpp); on the host
    // where none of its columns is on the GPU.
    bool fold(const rt::FoldLaunch& launch) override;
    // Unless dispatches are limited (a launch's kills then come in several lists).
    bool keepsRowsInMemory() const override { return dispatchRows_ == std::numeric_limits<size_t>::max(); }
    rt::BackendReport report() const override;
    // Programs compiled on another thread with a shared context (prepareShared), so far.
    size_t sharedPrograms() const {
        std::lock_guard lock(programsMutex_);
        return sharedPrograms_;
    }
    bool marksDrawn() const override { return true; }
    bool rendersInStep() const override { return false; }
    // One dispatch over every row (split only where a storage block cannot hold them).
    size_t chunkRows() const override { return std::numeric_limits<size_t>::max(); }

    // The GPU's work so far while timePasses is on, by pass (gpu/pass_timer.h): the
    // launches by kernel kind name, and what is recorded around them ("staging",
    // "scatter", "gather", "compaction", "read-back", "clear", "copy",
    // "adopt", "upload", "grow").
    using PassTime = PassTimer::Time;
    const std::map<std::string, PassTime>& passTimes() const { return timer_.times(); }
    void timePasses(bool on) { timer_.enable(on); }
    // At most this many rows per dispatch (else as many as a storage block holds): for
    // tests, which cannot reach the GL's limit.
    void limitDispatchRows(size_t rows) { dispatchRows_ = rows; }
    // Whether the driver compiles programs in parallel, and gives program binaries to keep
    // on disk (gpu/gl_programs.h); how many programs came from that cache.
    bool parallelCompile();
    bool programBinaries();
    size_t programsLoaded() const;
    // Compute dispatches so far (kernels, compactions, scatters, gathers, clearings).
    uint64_t dispatches() const { return memory_.dispatches; }
    // Bytes moved between the host and the GPU so far, either way.
    uint64_t transferredBytes() const { return memory_.transferred; }
    // Bytes launches copied on the GPU into and out of their words so far (GlMemory::staged).
    uint64_t stagedBytes() const { return memory_.staged; }
    // Times the host waited for a read-back from the GPU so far (GlMemory::waits).
    uint64_t waits() const { return memory_.waits; }
    // Late launches' read-backs taken so far, and of them those the host had to wait for
    // (the GPU had not finished them when the run-time collected them).
    uint64_t lateReads() const { return lateReads_; }
    uint64_t lateStalls() const { return lateStalls_; }
    // Late launches read before the run-time collected them, because the read-back buffer
    // had to grow (while the pools grow; none once it has).
    uint64_t lateEarly() const { return lateEarly_; }

    // A backend that runs launches on the host over this backend's memory (an interpreter:
    // host/backends.cpp makes it), and the rows up to which a launch runs there: a launch
    // over at most `rows` rows, or a spawn of at most `rows` children, whose columns are
    // all on the host. The few objects that emit — a launcher, a comet, rockets — then
    // stay on the host, as emitters do in the big engines, and the step need not wait for
    // the GPU to learn what they kill and emit; their many particles run on the GPU. So do
    // small pools of particles and the one-row batches of a burst chain: a launch costs a
    // dispatch or more on the GPU, a few rows cost microseconds here. Data decides: a
    // pool whose columns are on the GPU stays there (GlMemory::hostRows: scatters into
    // small pools on the host stay there).
    void setHostSide(std::unique_ptr<rt::Backend> host, size_t rows = kHostRows);
    static constexpr size_t kHostRows = 64;
    // Launches run by the host side so far.
    uint64_t hostLaunches() const { return hostLaunches_; }

private:
    GlslBackend() = default;
    struct Program;
    using RowsKey = std::tuple<const ir::Kernel*, rt::Clock::Source, rt::Clock::Source>;
    Program& rowsProgram(const ir::Object& object, const ir::Kernel& kernel, rt::Clock::Source now,
                         rt::Clock::Source dt);
    Program& childrenProgram(const ir::Object& object, const ir::Kernel& spawn);
    // What a launch needs besides the GL program (its layout, block, columns); the source.
    std::unique_ptr<Program> describeRows(const ir::Object& object, const ir::Kernel& kernel, rt::Clock::Source now,
                                          rt::Clock::Source dt, std::string& source, std::string& what) const;
    std::unique_ptr<Program> describeChildren(const ir::Object& object, const ir::Kernel& spawn, std::string& source,
                                              std::string& what) const;
    void prepareShared(const rt::Plan& plan);
    struct Made {  // a program prepareShared makes
        std::optional<RowsKey> key;
        const ir::Kernel* spawn = nullptr;
        std::unique_ptr<Program> program;
        std::string source, what;
    };
    // Launches of one spawn kernel as one dispatch (runChildren, gpu/glsl_children.cpp).
    void dispatchChildren(std::span<const rt::ChildrenLaunch> launches);
    unsigned compile(const std::string& source, const std::string& what);  // a GL program
    struct Late;
    rt::RowsResult runRows(const rt::RowsLaunch& launch, Program& program, size_t begin, size_t end, Late* late);
    void bindDirect(const rt::RowsLaunch& launch, const Program& program, size_t begin, size_t end,
                    std::vector<uint32_t>& block);
    // Uploads the block, fills the words of it that `fill` names from columns on the GPU
    // (on the GPU: no read-back), and runs `program` over `count` invocations; its counts
    // (killed, unstable, drawn, not finite) are left in the counts buffer.
    struct BlockFill {
        unsigned from;   // a GL buffer
        size_t byte;     // where in it
        uint32_t word;   // the block's word
        uint32_t words;
    };
    void dispatch(Program& program, const std::vector<uint32_t>& block, size_t count, const std::string& pass,
                  std::span<const BlockFill> fill = {});
    // gpu/glsl_children.cpp: an emitter's block of a children launch, its row's values
    // filled on the GPU from word `base` of the words (`fill`) where they are there (no
    // `base`: left out); the values of the block that come from its row, a column each.
    struct RowField {
        rt::Buffer column;
        uint32_t word;  // the block's
    };
    static std::vector<RowField> rowFields(const Program& program, const rt::ChildrenLaunch& launch);
    static std::vector<uint32_t> emitterBlock(GlMemory& memory, const Program& program, const rt::ChildrenLaunch& launch,
                                              std::optional<uint32_t> base, std::vector<BlockFill>& fill);
    bool blocksOnDevice(const rt::ChildrenLaunch& launch);
    size_t sendBlocks(const Program& program, std::span<const rt::ChildrenLaunch> launches, size_t firstWord,
                      size_t recordWords, size_t total, std::optional<size_t> direct);
    void buildBlocks(const rt::ChildrenLaunch& launch, const std::vector<RowField>& fields, size_t templateAt,
                     size_t firstWord, size_t recordWords);
    unsigned blocksProgram_ = 0;
    // gpu/glsl_readback.cpp: what a launch sends back, into a region of one buffer, read
    // at once (one wait) or, for a late launch, when the run-time collects it.
    rt::RowsResult readBack(const rt::RowsLaunch& launch, const Program& program, size_t begin, size_t n,
                            const std::vector<uint32_t>& block, Late* late);
    size_t reserveReadback(size_t words);  // a region's first word (late launches' regions kept)
    void ensureReadback(size_t words);
    // Words of the read-back buffer as the GPU left them (the GL waits for it where it must);
    // valid until the next read.
    std::span<const uint32_t> readRegion(size_t at, size_t words);
    uint64_t finishLate(std::unique_ptr<Late> late);  // its fence; its ticket
    void fetch(Late& late);           // waits for it if it must, and reads its counts and kills
    void hostClearKilled(const rt::RowsLaunch& launch);
    void ensureWords(size_t words);
    bool onHost(std::span<const rt::Buffer> columns, rt::Buffer mask, size_t rows) const;

    std::unique_ptr<HeadlessContext> context_;
    std::thread::id owner_;  // the thread whose GL context the backend uses
    GlMemory memory_;
    Compactor compactor_;
    // The programs, by kernel: found on the backend's thread, added there or by a thread
    // with a shared context (prepareShared), under the lock.
    std::map<RowsKey, std::unique_ptr<Program>> rows_;
    std::map<const ir::Kernel*, std::unique_ptr<Program>> children_;
    mutable std::mutex programsMutex_;
    size_t sharedPrograms_ = 0;
    unsigned words_ = 0, counts_ = 0, block_ = 0, readback_ = 0, params_ = 0;
    unsigned upload_ = 0;  // what the host sends into words_ goes through it (sendThrough)
    std::vector<uint32_t> readCopy_;  // readRegion's words
    size_t readbackWords_ = 0;
    size_t wordsCapacity_ = 0;
    size_t maxWords_ = 0;  // the largest storage block the GL allows, in words
    size_t storageAlignment_ = 16;  // of a storage block's offset, in bytes
    size_t textureAlignment_ = 16;  // of a buffer texture's offset, in bytes
    std::vector<unsigned> textures_;  // buffer textures, by unit (codegen_glsl::kTextureSlots)
    size_t dispatchRows_ = std::numeric_limits<size_t>::max();
    std::vector<uint32_t> staging_;
    size_t readbackUsed_ = 0;  // words of the read-back buffer held by late launches' regions
    std::map<uint64_t, std::unique_ptr<Late>> late_;
    uint64_t nextTicket_ = 1, lateReads_ = 0, lateStalls_ = 0, lateEarly_ = 0;
    std::vector<uint32_t> killedRows_;  // the last launch's or collect's (RowsResult::killedRows)
    std::unique_ptr<rt::Backend> hostSide_;
    size_t hostRows_ = 0;
    uint64_t hostLaunches_ = 0;
    std::unique_ptr<ProgramCompiler> compiler_;  // made on first use, on the context's thread
    bool preparing_ = false;
    struct Unfinished {
        unsigned program;
        std::string source, what;
    };
    std::vector<Unfinished> unfinished_;  // begun while preparing a plan, finished at its end
    size_t kernels_ = 0;
    double compileSeconds_ = 0;
    std::string renderer_;
    PassTimer timer_;
    std::unique_ptr<FoldWork> fold_;  // the neighbour folds' programs and buffers (gl_fold.cpp)
    void forgetFold(const ir::Kernel& pair);
};

}  // namespace psys::gpu
