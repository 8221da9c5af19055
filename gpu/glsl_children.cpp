// The GLSL backend's children launches: the spawn kernel's launches of a step's emitters
// (rt::Backend::runChildren) as one dispatch, a launch block an emitter in the launch's
// words (codegen_glsl::childrenShader finds an invocation's by a binary search), the
// children's arguments written in place into the argument columns.
#include <algorithm>
#include <climits>
#include <cstdint>
#include <vector>

#include <epoxy/gl.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/gl_context.h"
#include "gpu/gl_memory.h"
#include "gpu/glsl_program.h"
#include "gpu/hazards.h"

namespace psys::gpu {

using codegen_glsl::LaunchBlock;
using rt::Buffer;
using rt::ColumnLayout;

// An emitter's launch block but for where its children go (kFirstInvocation, the argument
// columns' words): its clock, seed and first child's draw index, the externs, its parents'
// values, and its creation time, id, parameters and state from its row — copied into the
// block on the GPU where the column is there (a fill at words from `base` on: the host does
// not wait for it), from the host's copy where it is not. A parameter the pool does not
// keep reads 0, as on every backend.
std::vector<uint32_t> GlslBackend::emitterBlock(GlMemory& memory, const Program& p, const rt::ChildrenLaunch& launch,
                                                uint32_t base, std::vector<BlockFill>& fill) {
    const ir::Object& o = *launch.object;
    const ColumnLayout& l = *launch.layout;
    std::vector<uint32_t> block = blockHeader(p.block, launch.count, launch.clock, launch.seed, launch.draw);
    block[LaunchBlock::kFirstChild] = launch.firstChild;
    for (uint32_t e = 0; e < p.block.externCount; ++e) putValue(block, p.block.externs + 4 * e, launch.externs[e]);
    auto fromRow = [&](Buffer b, uint32_t word) {
        if (!b.valid()) return;
        size_t w = GlMemory::wordsPerRow(memory.elem(b));
        if (memory.onDevice(b)) {
            fill.push_back({memory.deviceBuffer(b), launch.row * w * 4, base + word, static_cast<uint32_t>(w)});
            return;
        }
        uint32_t words[2] = {0, 0};
        memory.read(b, launch.row, 1, words);  // on the host: no wait
        for (size_t k = 0; k < w; ++k) block[word + k] = words[k];
    };
    fromRow(launch.columns[ColumnLayout::kCreated], LaunchBlock::kCreated);
    fromRow(launch.columns[ColumnLayout::kIds], LaunchBlock::kObjectId);
    auto fromColumns = [&](int column, int width, uint32_t word) {
        for (int c = 0; c < width; ++c) fromRow(launch.columns[static_cast<size_t>(column + c)], word + static_cast<uint32_t>(c));
    };
    for (size_t i = 0; i < o.params.size(); ++i)
        fromColumns(l.paramOffset[i], o.params[i].type.width, p.block.params + 4 * static_cast<uint32_t>(i));
    for (size_t i = 0; i < o.state.size(); ++i)
        fromColumns(l.stateOffset[i], o.state[i].type.width, p.block.state + 4 * static_cast<uint32_t>(i));
    for (size_t i = 0; i < l.parentColumns.size(); ++i)
        putValue(block, p.block.parents + 4 * static_cast<uint32_t>(i), launch.parents[i]);
    return block;
}

void GlslBackend::run(const rt::ChildrenLaunch& launch) { runChildren({&launch, 1}); }

// The launches of one spawn kernel together, one dispatch for those on the GPU; a launch
// small enough for the host side (its columns there) runs there. A launch reads only its
// emitter's row and writes only its own children's argument rows, so the order between
// launches changes nothing: K emitters with two sites each, which queue their launches
// site after site, make two dispatches, not 2·K.
void GlslBackend::runChildren(std::span<const rt::ChildrenLaunch> all) {
    std::vector<rt::ChildrenLaunch> grouped;
    std::span<const rt::ChildrenLaunch> launches = all;
    if (std::any_of(all.begin(), all.end(), [&](const rt::ChildrenLaunch& l) { return l.spawn != all.front().spawn; })) {
        std::vector<const ir::Kernel*> kernels;  // in the order they first come
        for (const rt::ChildrenLaunch& l : all)
            if (std::find(kernels.begin(), kernels.end(), l.spawn) == kernels.end()) kernels.push_back(l.spawn);
        grouped.reserve(all.size());
        for (const ir::Kernel* k : kernels)
            for (const rt::ChildrenLaunch& l : all)
                if (l.spawn == k) grouped.push_back(l);
        launches = grouped;
    }
    size_t from = 0;
    auto flush = [&](size_t to) {
        if (to > from) dispatchChildren(launches.subspan(from, to - from));
        from = to;
    };
    for (size_t k = 0; k < launches.size(); ++k) {
        const rt::ChildrenLaunch& l = launches[k];
        if (k > from && l.spawn != launches[from].spawn) flush(k);
        if (l.count == 0 || (onHost(l.columns, Buffer{}, l.count) && onHost(l.args, Buffer{}, l.count))) {
            flush(k);
            from = k + 1;
            if (l.count == 0) continue;
            ++hostLaunches_;
            hostSide_->run(l);
        }
    }
    flush(launches.size());
}

// One dispatch for every child of the launches (all of one spawn kernel, so all into the
// same argument columns): emitter e's launch block at word firstWord + e·W of the words;
// each invocation finds its emitter's block (codegen_glsl::childrenShader). The children
// write their arguments in place, each column bound from the first launch's rows on
// (codegen_glsl::directArguments); else into the words before the blocks (component c of
// every child at c·N + its place), copied to the columns after.
void GlslBackend::dispatchChildren(std::span<const rt::ChildrenLaunch> launches) {
    if (context_) context_->makeCurrent();
    memory_.flushPending();  // before anything is bound
    const rt::ChildrenLaunch& front = launches.front();
    Program& p = childrenProgram(*front.object, *front.spawn);
    size_t total = 0, columns = front.args.size(), bound = SIZE_MAX, end = 0;
    for (const rt::ChildrenLaunch& launch : launches) {
        total += launch.count;
        bound = std::min(bound, launch.argsFirst);
        end = std::max(end, launch.argsFirst + launch.count);
    }
    const bool direct = !p.direct.empty();
    bound = bound * 4 / storageAlignment_ * storageAlignment_ / 4;  // (f32 columns: a word a row)
    if (direct)
        for (size_t c = 0; c < columns; ++c)
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(2 + c), memory_.deviceBuffer(front.args[c]),
                              static_cast<GLintptr>(bound * 4), static_cast<GLsizeiptr>((end - bound) * 4));
    const size_t recordWords = (p.block.words + 4 + 3) & ~size_t{3}, firstWord = direct ? 0 : columns * total;
    std::vector<uint32_t> records;
    records.reserve(launches.size() * recordWords);
    std::vector<BlockFill> fill;
    size_t place = 0;
    for (const rt::ChildrenLaunch& launch : launches) {
        auto base = static_cast<uint32_t>(firstWord + records.size());
        std::vector<uint32_t> block = emitterBlock(memory_, p, launch, base, fill);
        block.resize(recordWords, 0);
        block[LaunchBlock::kFirstInvocation] = static_cast<uint32_t>(place);
        for (size_t c = 0; c < columns; ++c)
            block[LaunchBlock::kColumns + c] = static_cast<uint32_t>(direct ? launch.argsFirst - bound : c * total + place);
        records.insert(records.end(), block.begin(), block.end());
        place += launch.count;
    }
    ensureWords(firstWord + records.size());
    glNamedBufferSubData(words_, static_cast<GLintptr>(firstWord * 4), static_cast<GLsizeiptr>(records.size() * 4),
                         records.data());
    afterWrite(Write::Upload, kStorageBlock);
    for (const BlockFill& f : fill)
        glCopyNamedBufferSubData(f.from, words_, static_cast<GLintptr>(f.byte), static_cast<GLintptr>(f.word) * 4,
                                 static_cast<GLsizeiptr>(f.words) * 4);
    if (!fill.empty()) afterWrite(Write::Copy, kStorageBlock);
    using R = codegen_glsl::LaunchRecords;
    std::vector<uint32_t> uniform(4, 0);
    uniform[R::kChildren] = static_cast<uint32_t>(total);
    uniform[R::kEmitters] = static_cast<uint32_t>(launches.size());
    uniform[R::kFirstWord] = static_cast<uint32_t>(firstWord);
    uniform[R::kWords] = static_cast<uint32_t>(recordWords);
    dispatch(p, uniform, total, p.pass);
    // The children's arguments stay on the GPU: creation scatters them into pool rows
    // there. From the words, launches whose rows follow each other in one copy.
    if (direct) {
        for (Buffer b : front.args) memory_.written(b);
        return;
    }
    place = 0;
    for (size_t k = 0; k < launches.size();) {
        const rt::ChildrenLaunch& a = launches[k];
        size_t count = a.count, next = k + 1;
        while (next < launches.size() && std::equal(a.args.begin(), a.args.end(), launches[next].args.begin(),
                                                    launches[next].args.end()) &&
               launches[next].argsFirst == a.argsFirst + count)
            count += launches[next++].count;
        for (size_t c = 0; c < columns; ++c) memory_.adopt(a.args[c], a.argsFirst, count, words_, c * total + place);
        place += count;
        k = next;
    }
}

}  // namespace psys::gpu
