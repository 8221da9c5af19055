#include "gpu/glsl_backend.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <cstring>
#include <stdexcept>
#include <thread>

#include <epoxy/gl.h>
#include <fmt/format.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/gl_context.h"
#include "gpu/gl_debug.h"
#include "gpu/gl_programs.h"
#include "gpu/compact.h"
#include "gpu/fold_work.h"
#include "gpu/gl_memory.h"
#include "gpu/glsl_program.h"
#include "gpu/hazards.h"

namespace psys::gpu {

using codegen_glsl::LaunchBlock;
using rt::Buffer;
using rt::ColumnLayout;
using rt::Elem;

std::unique_ptr<GlslBackend> GlslBackend::create(std::string& error) {
    std::unique_ptr<GlslBackend> b(new GlslBackend);
    b->owner_ = std::this_thread::get_id();
    if (!contextCurrent()) {
        b->context_ = HeadlessContext::open(error);
        if (!b->context_) return nullptr;
    }
    if (epoxy_gl_version() < 45) {
        error = "the GLSL backend needs OpenGL 4.5; this context has " + rendererName();
        return nullptr;
    }
    if (debugOutputRequested()) installDebugOutput();
    GLint64 maxBlock = 0;
    glGetInteger64v(GL_MAX_SHADER_STORAGE_BLOCK_SIZE, &maxBlock);
    b->maxWords_ = static_cast<size_t>(std::min<GLint64>(maxBlock, GLint64{1} << 31)) / 4;
    b->memory_.maxBlockBytes = static_cast<size_t>(std::max<GLint64>(maxBlock, 0));
    GLint alignment = 0, blocks = 0;
    glGetIntegerv(GL_SHADER_STORAGE_BUFFER_OFFSET_ALIGNMENT, &alignment);
    b->storageAlignment_ = static_cast<size_t>(std::max(alignment, 1));
    glGetIntegerv(GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS, &blocks);
    GLint units = 0, textureAlignment = 0, texels = 0;
    glGetIntegerv(GL_MAX_COMPUTE_TEXTURE_IMAGE_UNITS, &units);
    glGetIntegerv(GL_TEXTURE_BUFFER_OFFSET_ALIGNMENT, &textureAlignment);
    glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &texels);
    b->textureAlignment_ = static_cast<size_t>(std::max(textureAlignment, 1));
    b->maxWords_ = std::min(b->maxWords_, static_cast<size_t>(std::max(texels, 1)));
    if (static_cast<size_t>(units) < codegen_glsl::kTextureSlots) {
        error = fmt::format("the GLSL backend needs {} texture units in a compute shader; {} has {}",
                            codegen_glsl::kTextureSlots, rendererName(), units);
        return nullptr;
    }
    b->textures_.resize(codegen_glsl::kTextureSlots);
    glCreateTextures(GL_TEXTURE_BUFFER, static_cast<GLsizei>(b->textures_.size()), b->textures_.data());
    if (static_cast<size_t>(blocks) < 2 + codegen_glsl::kDirectSlots) {
        error = fmt::format("the GLSL backend needs {} storage blocks in a compute shader; {} has {}",
                            2 + codegen_glsl::kDirectSlots, rendererName(), blocks);
        return nullptr;
    }
    b->renderer_ = rendererName();
    glCreateBuffers(1, &b->words_);
    glCreateBuffers(1, &b->counts_);
    glCreateBuffers(1, &b->block_);
    glNamedBufferData(b->counts_, 16, nullptr, GL_DYNAMIC_COPY);
    b->memory_.timer = &b->timer_;
    b->compactor_.timer = &b->timer_;
    return b;
}

GlslBackend::~GlslBackend() {
    // A backend whose context could not be made has nothing of the GL's to give back (and
    // a GL call without a context aborts in libepoxy).
    if (!context_ && !contextCurrent()) return;
    if (context_) context_->makeCurrent();
    for (auto& [key, p] : rows_) glDeleteProgram(p->program);
    for (auto& [key, p] : children_) glDeleteProgram(p->program);
    fold_.reset();  // (its GL objects, while the context is current)
    for (auto& [ticket, late] : late_) fetch(*late);  // its fence deleted
    glDeleteTextures(static_cast<GLsizei>(textures_.size()), textures_.data());
    GLuint buffers[] = {words_, counts_, block_, readback_, params_, upload_};
    glDeleteBuffers(6, buffers);
    timer_.release();
}

void GlslBackend::ensureWords(size_t words) {
    if (words <= wordsCapacity_) return;
    wordsCapacity_ = std::max(words, wordsCapacity_ * 2);
    glNamedBufferData(words_, static_cast<GLsizeiptr>(wordsCapacity_ * 4), nullptr, GL_DYNAMIC_COPY);
    checkAllocation("a launch's words", wordsCapacity_ * 4);
}

void GlslBackend::dispatch(Program& program, const std::vector<uint32_t>& block, size_t count, const std::string& pass,
                           std::span<const BlockFill> fill) {
    uint32_t zero = 0;
    if (program.counts) glClearNamedBufferSubData(counts_, GL_R32UI, 0, 16, GL_RED_INTEGER, GL_UNSIGNED_INT, &zero);
    glNamedBufferData(block_, static_cast<GLsizeiptr>(block.size() * 4), block.data(), GL_STREAM_DRAW);
    afterWrite(Write::Upload, kStorageBlock | kUniformBlock);
    for (const BlockFill& f : fill)
        glCopyNamedBufferSubData(f.from, block_, static_cast<GLintptr>(f.byte), static_cast<GLintptr>(f.word) * 4,
                                 static_cast<GLsizeiptr>(f.words) * 4);
    if (!fill.empty()) afterWrite(Write::Copy, kUniformBlock);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, words_);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, counts_);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, block_);
    glUseProgram(program.program);
    {
        PassTimer::Scope timed(&timer_, pass.c_str(), count);
        dispatchInvocations(count, codegen_glsl::kWorkGroupSize);
    }
    ++memory_.dispatches;
    // What the shader wrote — columns in place, the launch's words, the counts — is read
    // next by anything a column has: kernels (storage blocks, buffer textures), copies
    // into launch blocks and read-backs, the viewer's vertex pulls.
    afterWrite(Write::Dispatch, kColumnReaders);
}

void GlslBackend::setHostSide(std::unique_ptr<rt::Backend> host, size_t rows) {
    hostSide_ = std::move(host);
    hostRows_ = hostSide_ ? rows : 0;
    memory_.hostRows = hostRows_;
}

// A late launch's kills cleared in its alive mask (Backend::clearsKilled) where the host
// side ran it, as the compaction of its kills does on the GPU (readBack): the run-time
// may take them at the next step (when another late launch of the step is still owed),
// and what is drawn before must leave them out (objects that died in their first update
// were drawn on the GPU).
void GlslBackend::hostClearKilled(const rt::RowsLaunch& launch) {
    const auto* flags = static_cast<const uint8_t*>(memory_.view(launch.columns[ColumnLayout::kKill]));
    if (launch.aliveRowsBuffer.valid()) {  // a batch's rows kept in the memory: cleared where they are
        std::vector<uint32_t> killed;
        for (size_t i = launch.begin; i < launch.end; ++i)
            if (flags[i]) killed.push_back(static_cast<uint32_t>(i - launch.aliveRowsFirst));
        memory_.clearMapped(launch.aliveMask, killed, launch.aliveRowsBuffer, 0);
        return;
    }
    uint8_t zero = 0;
    for (size_t i = launch.begin; i < launch.end; ++i) {
        if (!flags[i]) continue;
        size_t row = launch.aliveRows.empty() ? i : launch.aliveRows[i - launch.aliveRowsFirst];
        memory_.write(launch.aliveMask, row, 1, &zero);
    }
}

bool GlslBackend::onHost(std::span<const Buffer> columns, Buffer mask, size_t rows) const {
    if (!hostSide_ || rows > hostRows_) return false;
    auto there = [&](Buffer b) { return !b.valid() || !memory_.onDevice(b); };
    return there(mask) && std::all_of(columns.begin(), columns.end(), there);
}

rt::RowsResult GlslBackend::run(const rt::RowsLaunch& launch) {
    if (onHost(launch.columns, launch.mask, launch.end - launch.begin)) {
        ++hostLaunches_;
        rt::RowsResult result = hostSide_->run(launch);
        if (launch.kernel->kind == ir::KernelKind::Render)  // this backend marks what is drawn
            rt::markDrawn(memory_, launch, static_cast<const uint8_t*>(memory_.view(launch.mask)), launch.begin,
                          launch.end, result);
        if (launch.late && launch.aliveMask.valid() && result.killed) hostClearKilled(launch);
        return result;
    }
    if (context_) context_->makeCurrent();
    memory_.flushPending();  // before anything is bound
    Program& p = rowsProgram(*launch.object, *launch.kernel, launch.clock.now, launch.clock.dt);
    // Rows per dispatch: as many as the largest storage block the GL binds holds, for the
    // launch's words (the columns not bound in place, and a row of zeros) and for each
    // column bound in place (at most two words a row, from an aligned offset).
    size_t perRow = p.inPlace.back() ? 1 : 2;  // the zeros, and the mask where it is not in place
    for (int c = 0; c < p.layout.total; ++c) {
        Buffer b = launch.columns[static_cast<size_t>(c)];
        bool staged = p.needed[static_cast<size_t>(c)] || c == ColumnLayout::kKill;
        if (staged && b.valid() && !p.inPlace[static_cast<size_t>(c)])
            perRow += GlMemory::wordsPerRow(memory_.elem(b));
    }
    size_t rows = std::min(maxWords_ / perRow, (maxWords_ - storageAlignment_ / 4) / 2);
    rows = std::clamp<size_t>(std::min(rows, dispatchRows_), 1, size_t{codegen_glsl::kMaxGroupsX} * kCompactGroup);
    // Late: only the counts and kills come back (emission columns that stay in the memory
    // do not: RowsLaunch::emissionsStay), so they can wait for the run-time.
    auto comesBack = [&](int c) { return c != ColumnLayout::kKill && !launch.emissionsStay; };
    std::unique_ptr<Late> late;
    if (launch.late && p.counts && std::none_of(p.returned.begin(), p.returned.end(), comesBack))
        late = std::make_unique<Late>();
    if (late) {  // room for every dispatch's counts and kills, so that no region moves while it is issued
        size_t dispatches = (launch.end - launch.begin + rows - 1) / rows;
        reserveReadback(dispatches * 5 + (launch.end - launch.begin));
        // Kills listed on the GPU for a pool that frees them there: one dispatch, one list
        // (a kernel that kills nothing lists nothing: the run-time lists its none).
        bool kills = launch.columns[ColumnLayout::kKill].valid() &&
                     std::find(p.returned.begin(), p.returned.end(), ColumnLayout::kKill) != p.returned.end();
        late->listed = kills && launch.killList.valid() && launch.end - launch.begin <= rows;
    }
    rt::RowsResult result;
    killedRows_.clear();
    for (size_t begin = launch.begin; begin < launch.end; begin += rows) {
        rt::RowsResult r = runRows(launch, p, begin, std::min(launch.end, begin + rows), late.get());
        result.killed += r.killed;
        result.unstable += r.unstable;
        result.drawn += r.drawn;
        result.nonFinite += r.nonFinite;
    }
    if (late) {
        bool listed = late->listed;
        return {.ticket = finishLate(std::move(late)), .killsListed = listed};
    }
    result.killedRows = killedRows_;  // every dispatch's, in order
    return result;
}

// The columns a shader reads and writes in place (codegen_glsl::directColumns): each its
// own GL buffer bound to storage block 2 + k from an aligned offset at or before row
// `begin`; the block's column word says where row `begin` is in that range.
void GlslBackend::bindDirect(const rt::RowsLaunch& launch, const Program& p, size_t begin, size_t end,
                             std::vector<uint32_t>& block) {
    for (size_t k = 0; k < p.direct.size(); ++k) {
        auto c = static_cast<size_t>(p.direct[k]);
        Buffer b = c == static_cast<size_t>(p.layout.total) ? launch.mask : launch.columns[c];
        if (!b.valid())
            throw std::logic_error(fmt::format("{}: column {} has no buffer to bind in place", p.pass, c));
        size_t rowBytes = GlMemory::wordsPerRow(memory_.elem(b)) * 4;
        bool texture = k >= codegen_glsl::kDirectSlots;
        size_t alignment = texture ? textureAlignment_ : storageAlignment_;
        size_t offset = begin * rowBytes / alignment * alignment;
        auto size = static_cast<GLsizeiptr>(end * rowBytes - offset);
        if (texture) {
            GLuint t = textures_[k - codegen_glsl::kDirectSlots];
            glTextureBufferRange(t, GL_R32UI, memory_.deviceBuffer(b), static_cast<GLintptr>(offset), size);
            glBindTextureUnit(static_cast<GLuint>(k - codegen_glsl::kDirectSlots), t);
        } else {
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(2 + k), memory_.deviceBuffer(b),
                              static_cast<GLintptr>(offset), size);
        }
        block[LaunchBlock::kColumns + c] = static_cast<uint32_t>((begin * rowBytes - offset) / 4);
    }
}

rt::RowsResult GlslBackend::runRows(const rt::RowsLaunch& launch, Program& p, size_t begin, size_t end, Late* late) {
    size_t n = end - begin;
    if (n == 0) return {};
    // Each distinct buffer of the table once (the mask last), a column of zeros for the
    // columns the table has no buffer for (parameters the pool does not keep).
    struct Slot {
        Buffer buffer;
        size_t word;
        bool carried;  // its rows' values go in (else the shader only writes them)
    };
    std::vector<Slot> slots;
    std::vector<uint32_t> block = blockHeader(p.block, n, launch.clock, launch.seed, launch.draw);
    size_t words = n;  // the zeros first
    bool zeros = false;  // some column reads them (else they are not written: n words a launch)
    auto place = [&](Buffer b, bool carried = true) -> size_t {
        if (!b.valid()) {
            zeros = true;
            return 0;
        }
        for (Slot& s : slots)
            if (s.buffer == b) {
                s.carried = s.carried || carried;
                return s.word;
            }
        slots.push_back({b, words, carried});
        words += n * GlMemory::wordsPerRow(memory_.elem(b));
        return slots.back().word;
    };
    // An emission column's rows are written for every row the launch updates, and no one
    // reads the others (the host's emissions and Memory::emitAtRate take the mask's rows):
    // its values need not go in.
    auto writtenOnly = [&](int c) { return c >= p.layout.emits && c < p.layout.render; };
    const std::vector<bool>& direct = p.inPlace;
    for (int c = 0; c < p.layout.total; ++c)
        if (p.needed[static_cast<size_t>(c)] && !direct[static_cast<size_t>(c)])
            block[LaunchBlock::kColumns + static_cast<size_t>(c)] =
                static_cast<uint32_t>(place(launch.columns[static_cast<size_t>(c)], !writtenOnly(c)));
    // The kill flags: written for every row, carried only from the GPU.
    Buffer killBuffer = launch.columns[ColumnLayout::kKill];
    bool kills = std::find(p.returned.begin(), p.returned.end(), ColumnLayout::kKill) != p.returned.end();
    if (kills && killBuffer.valid()) {
        block[LaunchBlock::kColumns + ColumnLayout::kKill] = static_cast<uint32_t>(words);
        words += n;
    }
    if (!direct.back())
        block[LaunchBlock::kColumns + static_cast<size_t>(p.layout.total)] = static_cast<uint32_t>(place(launch.mask));
    bindDirect(launch, p, begin, end, block);
    ensureWords(words);
    // Columns on the GPU are copied there; the others come from the host.
    std::optional<PassTimer::Scope> staging(std::in_place, &timer_, "staging", n);
    uint32_t zero = 0;
    if (zeros) {
        glClearNamedBufferSubData(words_, GL_R32UI, 0, static_cast<GLsizeiptr>(n * 4), GL_RED_INTEGER, GL_UNSIGNED_INT,
                                  &zero);
        afterWrite(Write::Clear, kStorageBlock);
    }
    for (const Slot& s : slots) {
        if (!s.carried) continue;
        Elem e = memory_.elem(s.buffer);
        size_t w = GlMemory::wordsPerRow(e);
        if (memory_.onDevice(s.buffer)) {
            memory_.staged += n * w * 4;
            glCopyNamedBufferSubData(memory_.deviceBuffer(s.buffer), words_, static_cast<GLintptr>(begin * w * 4),
                                     static_cast<GLintptr>(s.word * 4), static_cast<GLsizeiptr>(n * w * 4));
            afterWrite(Write::Copy, kStorageBlock);
            continue;
        }
        staging_.resize(n * w);
        toWords(static_cast<const char*>(memory_.view(s.buffer)) + begin * rt::elemSize(e), e, n, staging_.data());
        sendThrough(upload_, words_, s.word * 4, n * w * 4, staging_.data());
        afterWrite(Write::Upload, kStorageBlock);
        memory_.transferred += n * w * 4;
    }

    staging.reset();
    for (uint32_t e = 0; e < p.block.externCount; ++e) putValue(block, p.block.externs + 4 * e, launch.externs[e]);
    if (launch.uniforms)
        for (uint32_t u = 0; u < p.block.uniformCount; ++u) putValue(block, p.block.uniforms + 4 * u, launch.uniforms[u]);
    dispatch(p, block, n, p.pass);
    for (int c : p.resident) {
        Buffer b = launch.columns[static_cast<size_t>(c)];
        if (!b.valid()) continue;
        if (direct[static_cast<size_t>(c)])
            memory_.written(b);
        else
            memory_.adopt(b, begin, n, words_, block[LaunchBlock::kColumns + static_cast<size_t>(c)]);
    }
    return readBack(launch, p, begin, n, block, late);
}

bool GlslBackend::parallelCompile() {
    if (!compiler_) compiler_ = std::make_unique<ProgramCompiler>();
    return compiler_->parallel;
}

bool GlslBackend::programBinaries() {
    if (!compiler_) compiler_ = std::make_unique<ProgramCompiler>();
    return compiler_->binaries;
}

size_t GlslBackend::programsLoaded() const { return compiler_ ? compiler_->loaded : 0; }

rt::BackendReport GlslBackend::report() const {
    rt::BackendReport r;
    r.target = renderer_;
    {
        std::lock_guard lock(programsMutex_);
        r.kernels = kernels_;
    }
    r.compileSeconds = compileSeconds_;
    r.fromDisk = compiler_ ? compiler_->loaded : 0;
    r.device = true;
    r.waits = memory_.waits;
    r.transferredBytes = memory_.transferred;
    r.stagedBytes = memory_.staged;
    r.lateReads = lateReads_;
    r.lateStalls = lateStalls_;
    r.hostLaunches = hostLaunches_;
    return r;
}

}  // namespace psys::gpu
