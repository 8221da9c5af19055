// The GLSL backend's children launches: the spawn kernel's launches of a step's emitters
// (rt::Backend::runChildren) as one dispatch, a launch block an emitter in the launch's
// words (codegen_glsl::childrenShader finds an invocation's by a binary search), the
// children's arguments written in place into the argument columns. The blocks of a launch
// from records (emitters whose rate emissions the GPU decided) are built on the GPU.
#include <algorithm>
#include <climits>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <epoxy/gl.h>

#include <fmt/format.h>

#include "codegen_glsl/glsl_shaders.h"
#include "gpu/gl_context.h"
#include "gpu/gl_programs.h"
#include "gpu/gl_memory.h"
#include "gpu/glsl_program.h"
#include "gpu/hazards.h"

namespace psys::gpu {

using codegen_glsl::LaunchBlock;
using rt::Buffer;
using rt::ColumnLayout;

// The values of an emitter's block that come from its row: its creation time, id,
// parameters and state, each a column and the block word it goes to. A parameter the pool
// does not keep has no column and reads 0, as on every backend.
std::vector<GlslBackend::RowField> GlslBackend::rowFields(const Program& p, const rt::ChildrenLaunch& launch) {
    const ir::Object& o = *launch.object;
    const ColumnLayout& l = *launch.layout;
    std::vector<RowField> fields;
    auto add = [&](Buffer b, uint32_t word) {
        if (b.valid()) fields.push_back({b, word});
    };
    add(launch.columns[ColumnLayout::kCreated], LaunchBlock::kCreated);
    add(launch.columns[ColumnLayout::kIds], LaunchBlock::kObjectId);
    auto addColumns = [&](int column, int width, uint32_t word) {
        for (int c = 0; c < width; ++c) add(launch.columns[static_cast<size_t>(column + c)], word + static_cast<uint32_t>(c));
    };
    for (size_t i = 0; i < o.params.size(); ++i)
        addColumns(l.paramOffset[i], o.params[i].type.width, p.block.params + 4 * static_cast<uint32_t>(i));
    for (size_t i = 0; i < o.state.size(); ++i)
        addColumns(l.stateOffset[i], o.state[i].type.width, p.block.state + 4 * static_cast<uint32_t>(i));
    if (!launch.parents)  // (a launch from records: each emitter's parent reads are columns, State::gatherSpawnParents)
        for (size_t i = 0; i < l.parentColumns.size(); ++i)
            addColumns(l.parentColumns[i].offset, l.parentColumns[i].width, p.block.parents + 4 * static_cast<uint32_t>(i));
    return fields;
}

// An emitter's launch block but for where its children go (kFirstInvocation, the argument
// columns' words): its clock, seed and first child's draw index, the externs, its parents'
// values — and its row's values (rowFields), copied into the block on the GPU where the
// column is there (a fill at words from `base` on: the host does not wait for it), from
// the host's copy where it is not (`base` null: none; blocksFromRecords copies them).
std::vector<uint32_t> GlslBackend::emitterBlock(GlMemory& memory, const Program& p, const rt::ChildrenLaunch& launch,
                                                std::optional<uint32_t> base, std::vector<BlockFill>& fill) {
    std::vector<uint32_t> block = blockHeader(p.block, launch.count, launch.clock, launch.seed, launch.draw);
    block[LaunchBlock::kFirstChild] = launch.firstChild;
    for (uint32_t e = 0; e < p.block.externCount; ++e) putValue(block, p.block.externs + 4 * e, launch.externs[e]);
    for (size_t i = 0; launch.parents && i < launch.layout->parentColumns.size(); ++i)
        putValue(block, p.block.parents + 4 * static_cast<uint32_t>(i), launch.parents[i]);
    if (!base) return block;
    for (const RowField& f : rowFields(p, launch)) {
        size_t w = GlMemory::wordsPerRow(memory.elem(f.column));
        if (memory.onDevice(f.column)) {
            fill.push_back({memory.deviceBuffer(f.column), launch.row * w * 4, *base + f.word, static_cast<uint32_t>(w)});
            continue;
        }
        uint32_t words[2] = {0, 0};
        memory.read(f.column, launch.row, 1, words);  // on the host: no wait
        for (size_t k = 0; k < w; ++k) block[f.word + k] = words[k];
    }
    return block;
}

void GlslBackend::run(const rt::ChildrenLaunch& launch) { runChildren({&launch, 1}); }

// Whether a launch from records can have its blocks built where the records are: the
// records, the emitters' rows, their sub-step ends and their columns all on the GPU — and, where its group
// has other sites (its children's arguments among theirs), the arguments written in
// place (a dispatch's words are copied to the columns a launch's range at a time).
bool GlslBackend::blocksOnDevice(const rt::ChildrenLaunch& launch) {
    if (!memory_.onDevice(launch.records) || (launch.rows.valid() && !memory_.onDevice(launch.rows)) ||
        (launch.nows.valid() && !memory_.onDevice(launch.nows)))
        return false;
    const Program& p = childrenProgram(*launch.object, *launch.spawn);
    if (launch.recordStride > 1 && p.direct.empty()) return false;
    for (const RowField& f : rowFields(p, launch))
        if (!memory_.onDevice(f.column)) return false;
    return true;
}

// The launches of one spawn kernel together, one dispatch for those on the GPU; a launch
// small enough for the host side (its columns there) runs there, and so do the emitters'
// launches of a launch from records that is not all on the GPU. A launch reads only its
// emitters' rows and writes only its own children's argument rows, so the order between
// launches changes nothing: K emitters with two sites each, which queue their launches
// site after site, make two dispatches, not 2·K.
void GlslBackend::runChildren(std::span<const rt::ChildrenLaunch> all) {
    std::vector<rt::ChildrenLaunch> each;
    std::vector<std::vector<rt::Value>> parents;  // (each launch's emitters' parent reads: the launches point into them)
    auto apart = [&](const rt::ChildrenLaunch& l) { return l.records.valid() && !blocksOnDevice(l); };
    if (std::any_of(all.begin(), all.end(), apart)) {
        for (const rt::ChildrenLaunch& l : all) {
            if (!apart(l)) {
                each.push_back(l);
                continue;
            }
            std::vector<rt::ChildrenLaunch> one = rt::eachEmitter(memory_, l, parents.emplace_back());
            each.insert(each.end(), one.begin(), one.end());
        }
        all = each;
    }
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
        if (l.records.valid()) continue;
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

namespace {

// Emitter blocks built where the records are (a launch from records): an invocation a
// record, its block a copy of the launch's template with the record's children (count),
// their place among the site's added to the first invocation and their place among the
// group's to the argument columns' words, its first id as the first child's draw, and its
// emitter row's values copied from the columns — up to kBlockSources columns a dispatch,
// listed in a table after the template: argument columns, fields, then a word a field
// (block word | words a row << 24). Params: records, the first record's word, the
// template's word, the first block's word, words a block, flags (1: emitter rows from a
// list, 2: fields only, 4: now the record's first time, 8: now the emitter's own, from a
// column of f64 at param 8 on; the records' stride from bit 8), the first row (of the
// list, or of the columns), the table's word.
constexpr size_t kBlockSources = 12;
constexpr size_t kTableWords = 2 + kBlockSources;

std::string blocksShader() {
    std::string sources, cases;
    for (size_t k = 0; k < kBlockSources; ++k) {
        sources += fmt::format("layout(std430, binding = {}) readonly buffer S{} {{ uint s{}[]; }};\n", k + 3, k, k);
        cases += fmt::format("case {0}u: return s{0}[o]; ", k);
    }
    return fmt::format(R"(#version 450
layout(local_size_x = 64) in;
{0}layout(std430, binding = 0) buffer Words {{ uint w[]; }};
layout(std430, binding = 1) readonly buffer Records {{ uint records[]; }};
layout(std430, binding = 2) readonly buffer Rows {{ uint rowOf[]; }};
layout(std430, binding = 15) readonly buffer Nows {{ uint nows[]; }};
{1}uint source(uint f, uint o) {{ switch (f) {{ {2}}} return 0u; }}
void main() {{
    uint k = {3};
    if (k >= param(0u)) return;
    uint r = param(1u) + k * (param(5u) >> 8u) * {4}u, at = param(3u) + k * param(4u), table = param(7u);
    uint place = records[r], count = records[r + 1u];
    if ((param(5u) & 2u) == 0u) {{
        for (uint j = 0u; j < param(4u); ++j) w[at + j] = w[param(2u) + j];
        w[at + {5}u] = count;
        w[at + {6}u] += records[r + {9}u];
        w[at + {7}u] = records[r + 2u];
        if ((param(5u) & 4u) != 0u) {{
            w[at + {10}u] = records[r + 4u];
            w[at + {10}u + 1u] = records[r + 5u];
        }}
        if ((param(5u) & 8u) != 0u) {{
            w[at + {10}u] = nows[2u * (param(8u) + k)];
            w[at + {10}u + 1u] = nows[2u * (param(8u) + k) + 1u];
        }}
        for (uint c = 0u; c < w[table]; ++c) w[at + {8}u + c] += place;
    }}
    if (count == 0u) return;
    uint row = (param(5u) & 1u) != 0u ? rowOf[param(6u) + k] : param(6u) + k;
    for (uint f = 0u; f < w[table + 1u]; ++f) {{
        uint d = w[table + 2u + f], word = d & 0xffffffu, n = d >> 24u;
        for (uint j = 0u; j < n; ++j) w[at + word + j] = source(f, row * n + j);
    }}
}}
)",
                       kParamsBlock, sources, cases, kInvocationIndex, rt::kRunWords, LaunchBlock::kCount,
                       LaunchBlock::kFirstInvocation, LaunchBlock::kFirstChild, LaunchBlock::kColumns, rt::kRunSitePlace, LaunchBlock::kNow);
}

}  // namespace

// One dispatch for every child of the launches (all of one spawn kernel, so all into the
// same argument columns): a block an emitter (sendBlocks); each invocation finds its
// emitter's block (codegen_glsl::childrenShader). The children write their arguments in
// place, each column bound from the first launch's rows on
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
        end = std::max(end, launch.argsFirst + std::max(launch.count, launch.placed));
    }
    const bool direct = !p.direct.empty();
    bound = bound * 4 / storageAlignment_ * storageAlignment_ / 4;  // (f32 columns: a word a row)
    const size_t recordWords = (p.block.words + 4 + 3) & ~size_t{3}, firstWord = direct ? 0 : columns * total;
    size_t blocks = sendBlocks(p, launches, firstWord, recordWords, total, direct ? std::optional(bound) : std::nullopt);
    if (direct)  // (after the blocks: building them binds storage blocks of its own)
        for (size_t c = 0; c < columns; ++c)
            glBindBufferRange(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(2 + c), memory_.deviceBuffer(front.args[c]),
                              static_cast<GLintptr>(bound * 4), static_cast<GLsizeiptr>((end - bound) * 4));
    using R = codegen_glsl::LaunchRecords;
    std::vector<uint32_t> uniform(4, 0);
    uniform[R::kChildren] = static_cast<uint32_t>(total);
    uniform[R::kEmitters] = static_cast<uint32_t>(blocks);
    uniform[R::kFirstWord] = static_cast<uint32_t>(firstWord);
    uniform[R::kWords] = static_cast<uint32_t>(recordWords);
    dispatch(p, uniform, total, p.pass);
    // The children's arguments stay on the GPU: creation scatters them into pool rows
    // there. From the words, launches whose rows follow each other in one copy.
    if (direct) {
        for (Buffer b : front.args) memory_.written(b);
        return;
    }
    size_t place = 0;
    for (size_t k = 0; k < launches.size();) {
        const rt::ChildrenLaunch& a = launches[k];
        size_t count = a.count, next = k + 1;
        while (next < launches.size() && std::equal(a.args.begin(), a.args.end(), launches[next].args.begin(),
                                                    launches[next].args.end()) &&
               launches[next].argsFirst == a.argsFirst + count)
            count += launches[next++].count;
        for (size_t c = 0; c < columns; ++c)
            memory_.adopt(a.args[c], a.argsFirst, count, words_, c * total + place, "arguments adopted");
        place += count;
        k = next;
    }
}

// The blocks of a children dispatch, block e at word firstWord + e·recordWords: an
// emitter's from the host, or a launch from records' a record each, built on the GPU from
// a template the host sends (buildBlocks: the emitters need not come back to the host).
// Each with its children's place among the dispatch's and their argument columns' words
// (bound in place from row `direct`, else component c at c·total + place). Returns the
// blocks.
size_t GlslBackend::sendBlocks(const Program& p, std::span<const rt::ChildrenLaunch> launches, size_t firstWord,
                               size_t recordWords, size_t total, std::optional<size_t> direct) {
    const size_t columns = launches.front().args.size();
    std::vector<uint32_t> sent;  // the host's blocks, then each launch from records' template and tables
    std::vector<std::pair<size_t, size_t>> runs;  // (word, words) of `sent`, in order
    auto send = [&](size_t word, const std::vector<uint32_t>& words) {
        if (runs.empty() || runs.back().first + runs.back().second != word) runs.push_back({word, 0});
        runs.back().second += words.size();
        sent.insert(sent.end(), words.begin(), words.end());
    };
    struct Built {
        const rt::ChildrenLaunch* launch;
        size_t firstBlock;
        std::vector<uint32_t> block;  // the template
        std::vector<RowField> fields;
    };
    std::vector<Built> built;
    std::vector<BlockFill> fill;
    size_t place = 0, blocks = 0;
    for (const rt::ChildrenLaunch& launch : launches) {
        const size_t word = firstWord + blocks * recordWords;
        const bool records = launch.records.valid();
        std::vector<uint32_t> block =
            emitterBlock(memory_, p, launch, records ? std::nullopt : std::optional<uint32_t>(word), fill);
        block.resize(recordWords, 0);
        block[LaunchBlock::kFirstInvocation] = static_cast<uint32_t>(place);
        for (size_t c = 0; c < columns; ++c)
            block[LaunchBlock::kColumns + c] = static_cast<uint32_t>(direct ? launch.argsFirst - *direct : c * total + place);
        if (records) {
            built.push_back({&launch, blocks, std::move(block), rowFields(p, launch)});
            blocks += launch.recordCount;
        } else {
            send(word, block);
            ++blocks;
        }
        place += launch.count;
    }
    size_t extra = firstWord + blocks * recordWords;
    std::vector<size_t> templates;
    for (const Built& b : built) {
        templates.push_back(extra);
        send(extra, b.block);
        extra += recordWords;
        for (size_t from = 0; from == 0 || from < b.fields.size(); from += kBlockSources) {
            size_t n = std::min(kBlockSources, b.fields.size() - from);
            std::vector<uint32_t> table = {static_cast<uint32_t>(columns), static_cast<uint32_t>(n)};
            for (size_t f = from; f < from + n; ++f)
                table.push_back(b.fields[f].word |
                                static_cast<uint32_t>(GlMemory::wordsPerRow(memory_.elem(b.fields[f].column))) << 24);
            table.resize(kTableWords, 0);
            send(extra, table);
            extra += kTableWords;
        }
    }
    ensureWords(extra);
    size_t at = 0;
    for (auto [word, words] : runs) {
        sendThrough(upload_, words_, word * 4, words * 4, sent.data() + at);
        at += words;
    }
    memory_.transferred += sent.size() * 4;
    afterWrite(Write::Upload, kStorageBlock);
    for (const BlockFill& f : fill)
        glCopyNamedBufferSubData(f.from, words_, static_cast<GLintptr>(f.byte), static_cast<GLintptr>(f.word) * 4,
                                 static_cast<GLsizeiptr>(f.words) * 4);
    if (!fill.empty()) afterWrite(Write::Copy, kStorageBlock);
    for (size_t k = 0; k < built.size(); ++k)
        buildBlocks(*built[k].launch, built[k].fields, templates[k], firstWord + built[k].firstBlock * recordWords,
                    recordWords);
    return blocks;
}

// A launch from records' blocks from word `firstWord` on (blocksShader), from its template
// at word `templateAt` and the tables after it: a dispatch a kBlockSources of its row's values.
void GlslBackend::buildBlocks(const rt::ChildrenLaunch& launch, const std::vector<RowField>& fields, size_t templateAt,
                              size_t firstWord, size_t recordWords) {
    if (!blocksProgram_) blocksProgram_ = computeProgram(blocksShader(), "emitter blocks from records");
    PassTimer::Scope timed(&timer_, "spawn blocks", launch.recordCount);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, words_);
    unsigned records = memory_.deviceBuffer(launch.records);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, records);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, launch.rows.valid() ? memory_.deviceBuffer(launch.rows) : records);
    for (size_t from = 0, pass = 0; from == 0 || from < fields.size(); from += kBlockSources, ++pass) {
        for (size_t k = 0; k < kBlockSources; ++k)  // (every block bound to something)
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(3 + k),
                             from + k < fields.size() ? memory_.deviceBuffer(fields[from + k].column) : records);
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 15, launch.nows.valid() ? memory_.deviceBuffer(launch.nows) : records);
        uint32_t flags = (launch.rows.valid() ? 1u : 0u) | (pass > 0 ? 2u : 0u) | (launch.nowFromRecords ? 4u : 0u) |
                         (launch.nows.valid() ? 8u : 0u) | static_cast<uint32_t>(launch.recordStride) << 8;
        bindParams(params_, {static_cast<uint32_t>(launch.recordCount), static_cast<uint32_t>(launch.record * rt::kRunWords),
                             static_cast<uint32_t>(templateAt), static_cast<uint32_t>(firstWord),
                             static_cast<uint32_t>(recordWords), flags, static_cast<uint32_t>(launch.rowsFirst),
                             static_cast<uint32_t>(templateAt + recordWords + pass * kTableWords),
                             static_cast<uint32_t>(launch.nowsFirst)});
        glUseProgram(blocksProgram_);
        dispatchInvocations(launch.recordCount, 64);
        ++memory_.dispatches;
        afterWrite(Write::Dispatch, kStorageBlock);
    }
}

}  // namespace psys::gpu
