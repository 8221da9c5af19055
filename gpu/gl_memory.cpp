#include "gpu/gl_memory.h"
#include "gpu/gl_column.h"

#include "gpu/gl_context.h"
#include "gpu/gl_programs.h"
#include "gpu/hazards.h"

#include <algorithm>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include <epoxy/gl.h>

namespace psys::gpu {

using rt::Buffer;
using rt::Elem;

void toWords(const void* from, Elem e, size_t rows, uint32_t* to) {
    if (e == Elem::U8) {
        const auto* b = static_cast<const uint8_t*>(from);
        for (size_t r = 0; r < rows; ++r) to[r] = b[r];
    } else {
        std::memcpy(to, from, rows * rt::elemSize(e));
    }
}

void fromWords(const uint32_t* from, Elem e, size_t rows, void* to) {
    if (e == Elem::U8) {
        auto* b = static_cast<uint8_t*>(to);
        for (size_t r = 0; r < rows; ++r) b[r] = static_cast<uint8_t>(from[r]);
    } else {
        std::memcpy(to, from, rows * rt::elemSize(e));
    }
}

namespace {

// A scatter's or a gather's blocks and uniforms (GlMemory::runRows binds them); `main`
// follows, invocation i moving a row of `w` words.
const char* kRowsHeader = R"(#version 450
layout(local_size_x = 64) in;
layout(std430, binding = 0) readonly buffer From { uint from[]; };
layout(std430, binding = 1) buffer To { uint to[]; };
layout(std430, binding = 2) readonly buffer Rows { uint rows[]; };
#define count param(0u)
#define first param(1u)
#define w param(2u)
#define rowsAt param(3u)
)";

std::string rowsShader(const char* main) {
    return std::string(kRowsHeader) + kParamsBlock + "#define INVOCATION " + kInvocationIndex + "\n" + main;
}

// to[rows[i]] = from[first + i] (kSkipRow: nothing).
const char* kScatter = R"(void main() {
    uint i = INVOCATION;
    if (i >= count || rows[rowsAt + i] == 0xFFFFFFFFu) return;
    for (uint k = 0u; k < w; ++k) to[rows[rowsAt + i] * w + k] = from[(first + i) * w + k];
}
)";

// Up to kScatterColumns pairs of columns at once, by a row list in a buffer:
// to_k[rows[rowsAt + i]] = from_k[first + i] for the pairs k < pairs, w_k words a row
// (2 bits each of `widths`); kSkipRow: nothing.
std::string scatterColumnsShader() {
    std::string text = std::string("#version 450\nlayout(local_size_x = 64) in;\n") + kParamsBlock +
                       "#define INVOCATION " + kInvocationIndex + "\n";
    const size_t n = GlMemory::kScatterColumns;
    for (size_t k = 0; k < n; ++k)
        text += "layout(std430, binding = " + std::to_string(k) + ") readonly buffer From" + std::to_string(k) +
                " { uint from" + std::to_string(k) + "[]; };\n" + "layout(std430, binding = " + std::to_string(n + k) +
                ") buffer To" + std::to_string(k) + " { uint to" + std::to_string(k) + "[]; };\n";
    text += "layout(std430, binding = " + std::to_string(2 * n) + ") readonly buffer Rows { uint rows[]; };\n";
    text += R"(void main() {
    uint i = INVOCATION;
    if (i >= param(0u)) return;
    uint row = rows[param(2u) + i], source = param(1u) + i, pairs = param(3u), widths = param(4u);
    if (row == 0xFFFFFFFFu) return;
)";
    for (size_t k = 0; k < n; ++k) {
        std::string K = std::to_string(k);
        text += "    if (pairs > " + K + "u) { uint w = (widths >> " + std::to_string(2 * k) +
                "u) & 3u; for (uint j = 0u; j < w; ++j) to" + K + "[row * w + j] = from" + K + "[source * w + j]; }\n";
    }
    return text + "}\n";
}

// to[first + i] = from[rows[i]], or 0 for kSkipRow.
const char* kGather = R"(void main() {
    uint i = INVOCATION;
    if (i >= count) return;
    uint row = rows[rowsAt + i];
    for (uint k = 0u; k < w; ++k) to[(first + i) * w + k] = row == 0xFFFFFFFFu ? 0u : from[row * w + k];
}
)";

}  // namespace

GlMemory::GlMemory() = default;

GlMemory::~GlMemory() {
    for (auto& c : columns_)
        if (c && c->gl) glDeleteBuffers(1, &c->gl);
    for (unsigned program : {scatterProgram_, scatterColumnsProgram_, gatherProgram_, allocateProgram_, releaseProgram_, pushedProgram_, freshProgram_,
                             identifyProgram_, boundsProgram_, emitRowsProgram_, emitScanProgram_, identifyRecordsProgram_,
                             clearMappedProgram_, parentsProgram_, gatherAliveProgram_, survivorsProgram_,
                             readersGoneProgram_, releaseUnreadProgram_, releaseWaitingProgram_, gatherAgeProgram_,
                             stampDeathsProgram_, subStepProgram_, clearRowsProgram_, appendProgram_,
                             appendedProgram_, ancestorRowsProgram_})
        if (program) glDeleteProgram(program);
    if (runsBuffer_) glDeleteBuffers(1, &runsBuffer_);
    if (rowsBuffer_) glDeleteBuffers(1, &rowsBuffer_);
    if (paramsBuffer_) glDeleteBuffers(1, &paramsBuffer_);
    if (pendingBuffer_) glDeleteBuffers(1, &pendingBuffer_);
    if (uploadBuffer_) glDeleteBuffers(1, &uploadBuffer_);
    if (boxBuffer_) glDeleteBuffers(1, &boxBuffer_);
    if (metaBuffer_) glDeleteBuffers(1, &metaBuffer_);
}

GlMemory::Column& GlMemory::at(Buffer b) const { return *columns_.at(b.id); }

Buffer GlMemory::create(Elem elem, size_t rows) {
    uint32_t id;
    if (!free_.empty()) {
        id = free_.back();
        free_.pop_back();
    } else {
        id = static_cast<uint32_t>(columns_.size());
        columns_.push_back(std::make_unique<Column>());
    }
    Column& c = *columns_[id];
    c.elem = elem;
    c.rows = rows;
    c.hostCopy.assign(rows * rt::elemSize(elem), 0);
    c.device = false;
    c.live = true;
    return Buffer{id};
}

void GlMemory::resize(Buffer b, size_t rows) {
    Column& c = at(b);
    if (c.device) {  // grown or shrunk on the GPU: the column stays there
        if (rows < c.rows) flush(c);  // (rows pending past the end would land in rows to be zeroed)
        std::optional<PassTimer::Scope> timed;  // timed where there is GL work: a new buffer, rows zeroed
        size_t w = wordsPerRow(c.elem);
        // A pool grows a row at a time: the GL buffer doubles, and is zeroed past the rows
        // once then, not at each row.
        auto clear = [&](size_t from, size_t to) {
            if (to <= from) return;
            if (!timed) timed.emplace(timer, "grow", rows);
            uint32_t zero = 0;
            glClearNamedBufferSubData(c.gl, GL_R32UI, static_cast<GLintptr>(from * w * 4),
                                      static_cast<GLsizeiptr>((to - from) * w * 4), GL_RED_INTEGER, GL_UNSIGNED_INT,
                                      &zero);
            afterWrite(Write::Clear, kColumnReaders);
        };
        if (rows > c.glRows) {
            timed.emplace(timer, "grow", rows);
            size_t room = std::max(rows, 2 * c.glRows);
            GLuint grown = 0;
            glCreateBuffers(1, &grown);
            glNamedBufferData(grown, static_cast<GLsizeiptr>(room * w * 4), nullptr, GL_DYNAMIC_COPY);
            checkAllocation("a column", room * w * 4);
            if (c.rows) glCopyNamedBufferSubData(c.gl, grown, 0, 0, static_cast<GLsizeiptr>(c.rows * w * 4));
            afterWrite(Write::Copy, kColumnReaders);
            glDeleteBuffers(1, &c.gl);
            c.gl = grown;
            c.glRows = room;
            clear(c.rows, room);
            c.zeroFrom = c.rows;
        }
        if (rows > c.rows) {  // new rows are zero
            clear(c.rows, std::min(rows, c.zeroFrom));
            c.zeroFrom = std::max(c.zeroFrom, rows);
        }
    }
    // A column on the GPU keeps no host copy of its rows' size: toHost makes one when asked
    // (a pool that grows step after step would otherwise zero-fill host pages for nothing).
    if (!c.device) c.hostCopy.resize(rows * rt::elemSize(c.elem), 0);
    c.rows = rows;
}

void GlMemory::release(Buffer b) {
    if (!b.valid() || b.id >= columns_.size() || !columns_[b.id]->live) return;
    Column& c = at(b);
    c.live = false;
    c.device = false;
    c.rows = 0;
    c.pending.clear();
    c.pendingRows = 0;
    if (c.gl) glDeleteBuffers(1, &c.gl);  // its memory goes back to the GL (a pool of 10M rows holds GBs)
    c.gl = 0;
    c.glRows = 0;
    c.hostCopy.clear();
    c.hostCopy.shrink_to_fit();
    free_.push_back(b.id);
}

size_t GlMemory::rows(Buffer b) const { return at(b).rows; }
Elem GlMemory::elem(Buffer b) const { return at(b).elem; }

void GlMemory::toHost(Column& c) const {
    if (!c.device) return;
    flush(c);
    std::vector<uint32_t> words(c.words());
    if (!words.empty()) glGetNamedBufferSubData(c.gl, 0, static_cast<GLsizeiptr>(words.size() * 4), words.data());
    transferred += words.size() * 4;
    waits += !words.empty();
    c.hostCopy.resize(c.rows * rt::elemSize(c.elem));
    fromWords(words.data(), c.elem, c.rows, c.hostCopy.data());
    c.device = false;
}

void GlMemory::overwriteOnHost(Buffer b) {
    Column& c = at(b);
    if (!c.device) return;
    c.pending.clear();
    c.pendingRows = 0;
    c.hostCopy.resize(c.rows * rt::elemSize(c.elem));
    c.device = false;
}

unsigned GlMemory::overwriteOnDevice(Buffer b) {
    Column& c = at(b);
    c.pending.clear();
    c.pendingRows = 0;
    uploadRows(c, 0, 0);  // (a GL buffer of its rows, nothing sent)
    written(b);
    return c.gl;
}

void GlMemory::upload(Column& c) const { uploadRows(c, 0, c.rows); }

void GlMemory::uploadRows(Column& c, size_t first, size_t count) const {
    if (c.device) return;
    if (!c.gl) glCreateBuffers(1, &c.gl);
    if (c.glRows < c.rows || c.glRows == 0) {
        size_t room = std::max<size_t>({c.rows, 2 * c.glRows, 1});
        glNamedBufferData(c.gl, static_cast<GLsizeiptr>(room * wordsPerRow(c.elem) * 4), nullptr, GL_DYNAMIC_COPY);
        checkAllocation("a column", room * wordsPerRow(c.elem) * 4);
        c.glRows = room;
    }
    c.zeroFrom = c.glRows;  // what is past the rows in the GL buffer is not known
    if (count == 0) return;
    size_t w = wordsPerRow(c.elem);
    PassTimer::Scope timed(timer, "upload", count);
    std::vector<uint32_t> staging(count * w);
    toWords(c.hostCopy.data() + first * rt::elemSize(c.elem), c.elem, count, staging.data());
    sendThrough(uploadBuffer_, c.gl, first * w * 4, staging.size() * 4, staging.data());
    afterWrite(Write::Upload, kColumnReaders);
    transferred += staging.size() * 4;
}

void GlMemory::read(Buffer b, size_t first, size_t count, void* out) const {
    if (count == 0) return;  // an empty column has no address
    Column& c = at(b);
    if (!c.device) {
        std::memcpy(out, c.hostCopy.data() + first * rt::elemSize(c.elem), count * rt::elemSize(c.elem));
        return;
    }
    flush(c);
    size_t w = wordsPerRow(c.elem);
    std::vector<uint32_t> words(count * w);
    if (count)
        glGetNamedBufferSubData(c.gl, static_cast<GLintptr>(first * w * 4), static_cast<GLsizeiptr>(words.size() * 4),
                                words.data());
    transferred += words.size() * 4;
    ++waits;
    fromWords(words.data(), c.elem, count, out);
}

void GlMemory::write(Buffer b, size_t first, size_t count, const void* in) {
    if (count == 0) return;  // an empty column has no address
    Column& c = at(b);
    if (!c.device) {
        std::memcpy(c.hostCopy.data() + first * rt::elemSize(c.elem), in, count * rt::elemSize(c.elem));
        return;
    }
    flush(c);
    size_t w = wordsPerRow(c.elem);
    std::vector<uint32_t> words(count * w);
    toWords(in, c.elem, count, words.data());
    sendThrough(uploadBuffer_, c.gl, first * w * 4, words.size() * 4, words.data());
    afterWrite(Write::Upload, kColumnReaders);
    transferred += words.size() * 4;
}

void GlMemory::copy(Buffer from, size_t fromFirst, Buffer to, size_t toFirst, size_t count) {
    if (count == 0) return;  // an empty column has no address
    Column &f = at(from), &t = at(to);
    if (!f.device && !t.device) {
        size_t e = rt::elemSize(f.elem);
        std::memmove(t.hostCopy.data() + toFirst * e, f.hostCopy.data() + fromFirst * e, count * e);
        return;
    }
    flush(f);
    flush(t);
    uploadRows(f, fromFirst, count);  // only the rows copied: the source stays on the host
    if (toFirst == 0 && count >= t.rows) uploadRows(t, 0, 0);  // all of it written here: nothing to send
    else upload(t);
    PassTimer::Scope timed(timer, "copy", count);
    size_t w = wordsPerRow(f.elem) * 4;
    if (count)
        glCopyNamedBufferSubData(f.gl, t.gl, static_cast<GLintptr>(fromFirst * w), static_cast<GLintptr>(toFirst * w),
                                 static_cast<GLsizeiptr>(count * w));
    afterWrite(Write::Copy, kColumnReaders);
    t.device = true;
}

// On the GPU, but for small columns that are on the host with their source (hostRows):
// scatters fill pools' columns with what creation computed (state, exports, parameters),
// which then stay on the GPU.
void GlMemory::scatter(Buffer from, size_t fromFirst, Buffer to, std::span<const uint32_t> rows) {
    Column &f = at(from), &t = at(to);
    if (rows.empty()) return;
    if (!f.device && !t.device && t.rows <= hostRows) {
        size_t n = rt::elemSize(f.elem);
        for (size_t i = 0; i < rows.size(); ++i)
            if (rows[i] != rt::kSkipRow)
                std::memcpy(t.hostCopy.data() + rows[i] * n, f.hostCopy.data() + (fromFirst + i) * n, n);
        return;
    }
    if (!f.device && t.device && rows.size() <= kPendingScatter) {  // a few rows: sent with the next ones
        size_t w = wordsPerRow(f.elem);
        for (size_t i = 0; i < rows.size(); ++i) {
            if (rows[i] == rt::kSkipRow) continue;
            t.pending.push_back(rows[i]);
            size_t at = t.pending.size();
            t.pending.resize(at + w);
            toWords(f.hostCopy.data() + (fromFirst + i) * rt::elemSize(f.elem), f.elem, 1, t.pending.data() + at);
            ++t.pendingRows;
        }
        if (!t.pending.empty() && std::find(pendingColumns_.begin(), pendingColumns_.end(), to.id) == pendingColumns_.end())
            pendingColumns_.push_back(to.id);
        if (t.pendingRows >= kPendingFlush) flush(t);
        return;
    }
    flush(f);
    flush(t);
    uploadRows(f, fromFirst, rows.size());  // only the rows scattered: the source stays on the host
    upload(t);
    if (!scatterProgram_) scatterProgram_ = computeProgram(rowsShader(kScatter), "scatter");
    runRows(scatterProgram_, f.gl, t.gl, wordsPerRow(f.elem), fromFirst, rows, "scatter");
    t.device = true;
}

// With the rows already on the GPU (a pool's rows allocated there: Memory::allocateRows):
// kScatterColumns pairs of columns a dispatch, each its own storage blocks.
void GlMemory::scatter(std::span<const std::pair<Buffer, Buffer>> columns, size_t fromFirst, Buffer rows,
                       size_t rowsFirst, size_t count) {
    if (count == 0 || columns.empty()) return;
    if (!at(rows).device) return rt::Memory::scatter(columns, fromFirst, rows, rowsFirst, count);  // the list's on the host
    if (!scatterColumnsProgram_) scatterColumnsProgram_ = computeProgram(scatterColumnsShader(), "scatter");
    for (size_t begin = 0; begin < columns.size(); begin += kScatterColumns) {
        size_t pairs = std::min(kScatterColumns, columns.size() - begin);
        uint32_t widths = 0;
        for (size_t k = 0; k < pairs; ++k) {
            Column &f = at(columns[begin + k].first), &t = at(columns[begin + k].second);
            flush(f);
            flush(t);
            uploadRows(f, fromFirst, count);  // only the rows scattered: the source stays on the host
            upload(t);
            widths |= static_cast<uint32_t>(wordsPerRow(f.elem)) << (2 * k);
        }
        unsigned list = deviceBuffer(rows);
        PassTimer::Scope timed(timer, "scatter", count * pairs);
        for (size_t k = 0; k < pairs; ++k) {
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(k), at(columns[begin + k].first).gl);
            glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(kScatterColumns + k),
                             at(columns[begin + k].second).gl);
        }
        glBindBufferBase(GL_SHADER_STORAGE_BUFFER, static_cast<GLuint>(2 * kScatterColumns), list);
        glUseProgram(scatterColumnsProgram_);
        bindParams(paramsBuffer_, {static_cast<uint32_t>(count), static_cast<uint32_t>(fromFirst),
                                   static_cast<uint32_t>(rowsFirst), static_cast<uint32_t>(pairs), widths});
        dispatchInvocations(count, 64);
        ++dispatches;
        afterWrite(Write::Dispatch, kColumnReaders);
        for (size_t k = 0; k < pairs; ++k) at(columns[begin + k].second).device = true;
    }
}

// The rows scattered into a column on the GPU while it stayed there, in one upload and
// one scatter: a burst chain creates an object at a time, a hundred thousand times in a
// step, and would otherwise run a dispatch for each column of each. A row written twice
// keeps its last value (the scatter's rows must be distinct: its writes are unordered).
void GlMemory::flushPending() {
    for (uint32_t id : pendingColumns_)
        if (columns_[id]->live) flush(*columns_[id]);
    pendingColumns_.clear();
}

void GlMemory::flush(Column& c) const {
    if (c.pending.empty()) return;
    size_t w = wordsPerRow(c.elem);
    std::vector<uint32_t> rows, words;
    rows.reserve(c.pendingRows);
    words.reserve(c.pendingRows * w);
    std::unordered_set<uint32_t> seen;
    for (size_t at = c.pending.size(); at > 0;) {  // the last write of each row first
        at -= 1 + w;
        uint32_t row = c.pending[at];
        if (!seen.insert(row).second) continue;
        rows.push_back(row);
        words.insert(words.end(), c.pending.begin() + static_cast<std::ptrdiff_t>(at + 1),
                     c.pending.begin() + static_cast<std::ptrdiff_t>(at + 1 + w));
    }
    c.pending.clear();
    c.pendingRows = 0;
    if (!pendingBuffer_) glCreateBuffers(1, &pendingBuffer_);
    glNamedBufferData(pendingBuffer_, static_cast<GLsizeiptr>(words.size() * 4), words.data(), GL_STREAM_DRAW);
    afterWrite(Write::Upload, kStorageBlock);
    transferred += words.size() * 4;
    if (!scatterProgram_) scatterProgram_ = computeProgram(rowsShader(kScatter), "scatter");
    runRows(scatterProgram_, pendingBuffer_, c.gl, w, 0, rows, "scatter");
}

// On the GPU where the source is (a parent's exports, written there by its kernel), so
// that children read their parents without the host waiting for them.
void GlMemory::gather(Buffer from, Buffer to, size_t toFirst, std::span<const uint32_t> rows) {
    Column &f = at(from), &t = at(to);
    if (rows.empty()) return;
    if (!f.device && !t.device) {
        size_t n = rt::elemSize(f.elem);
        for (size_t i = 0; i < rows.size(); ++i) {
            uint8_t* out = t.hostCopy.data() + (toFirst + i) * n;
            if (rows[i] == rt::kSkipRow)
                std::memset(out, 0, n);
            else
                std::memcpy(out, f.hostCopy.data() + rows[i] * n, n);
        }
        return;
    }
    flush(f);
    flush(t);
    upload(f);
    upload(t);
    runRows(gatherProgram(), f.gl, t.gl, wordsPerRow(f.elem), toFirst, rows, "gather");
    t.device = true;
}

unsigned GlMemory::gatherProgram() {
    if (!gatherProgram_) gatherProgram_ = computeProgram(rowsShader(kGather), "gather");
    return gatherProgram_;
}

unsigned GlMemory::rowList(std::span<const uint32_t> rows) const {
    if (!rowsBuffer_) glCreateBuffers(1, &rowsBuffer_);
    if (!std::equal(rows.begin(), rows.end(), rowsSent_.begin(), rowsSent_.end())) {
        glNamedBufferData(rowsBuffer_, static_cast<GLsizeiptr>(std::max<size_t>(rows.size(), 1) * 4),
                          rows.empty() ? nullptr : rows.data(),
                          GL_STREAM_DRAW);
        afterWrite(Write::Upload, kStorageBlock);
        transferred += rows.size() * 4;
        rowsSent_.assign(rows.begin(), rows.end());
    }
    return rowsBuffer_;
}

// A scatter or gather over a list of rows; the list goes up once for every column of a
// batch or a parent that uses it.
void GlMemory::runRows(unsigned program, unsigned from, unsigned to, size_t w, size_t first,
                       std::span<const uint32_t> rows, const char* pass) const {
    runRows(program, from, to, w, first, rowList(rows), 0, rows.size(), pass);
}

// The same over `count` rows of a list already in a GL buffer, from its word `rowsAt`.
void GlMemory::runRows(unsigned program, unsigned from, unsigned to, size_t w, size_t first, unsigned list,
                       size_t rowsAt, size_t count, const char* pass) const {
    PassTimer::Scope timed(timer, pass, count);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, from);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, to);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, list);
    glUseProgram(program);
    bindParams(paramsBuffer_, {static_cast<uint32_t>(count), static_cast<uint32_t>(first), static_cast<uint32_t>(w),
                               static_cast<uint32_t>(rowsAt)});
    dispatchInvocations(count, 64);
    ++dispatches;
    afterWrite(Write::Dispatch, kColumnReaders);  // into a column: any reader may follow
}

void GlMemory::clear(Buffer b, size_t first, size_t count) {
    if (count == 0) return;
    Column& c = at(b);
    if (!c.device) {
        std::memset(c.hostCopy.data() + first * rt::elemSize(c.elem), 0, count * rt::elemSize(c.elem));
        return;
    }
    fillWords(c, first, count, 0);
}

void GlMemory::fill(Buffer b, size_t first, size_t count, uint32_t word) {
    if (count == 0) return;
    Column& c = at(b);
    if (rt::elemSize(c.elem) != 4) throw std::logic_error("GlMemory::fill: a column of 4-byte elements");
    if (!c.device) {
        auto* words = reinterpret_cast<uint32_t*>(c.hostCopy.data()) + first;
        std::fill(words, words + count, word);
        return;
    }
    fillWords(c, first, count, word);
}

// Rows [first, first + count) of a column on the device, every 32-bit word set to `word`
// (a u8 column's rows are a word each here: wordsPerRow).
void GlMemory::fillWords(Column& c, size_t first, size_t count, uint32_t word) {
    flush(c);
    PassTimer::Scope timed(timer, "clear", count);
    size_t w = wordsPerRow(c.elem) * 4;
    glClearNamedBufferSubData(c.gl, GL_R32UI, static_cast<GLintptr>(first * w), static_cast<GLsizeiptr>(count * w),
                              GL_RED_INTEGER, GL_UNSIGNED_INT, &word);
    afterWrite(Write::Clear, kColumnReaders);
}

void* GlMemory::host(Buffer b) {
    Column& c = at(b);
    toHost(c);
    return c.hostCopy.data();
}

const void* GlMemory::view(Buffer b) const {
    Column& c = at(b);
    toHost(c);
    return c.hostCopy.data();
}

bool GlMemory::onDevice(Buffer b) const { return at(b).device; }

unsigned GlMemory::glBuffer(Buffer b) const {
    Column& c = at(b);
    flush(c);
    upload(c);
    return c.gl;
}

unsigned GlMemory::deviceBuffer(Buffer b) {
    Column& c = at(b);
    flush(c);
    upload(c);
    return c.gl;
}

unsigned GlMemory::deviceRows(Buffer b, size_t first, size_t count) {
    Column& c = at(b);
    flush(c);
    uploadRows(c, first, count);  // (nothing where it is on the GPU)
    return c.gl;
}

void GlMemory::adopt(Buffer b, size_t first, size_t count, unsigned words, size_t word, const char* pass) {
    Column& c = at(b);
    flush(c);
    upload(c);
    size_t w = wordsPerRow(c.elem) * 4;
    staged += count * w;
    PassTimer::Scope timed(timer, pass, count);
    glCopyNamedBufferSubData(words, c.gl, static_cast<GLintptr>(word * 4), static_cast<GLintptr>(first * w),
                             static_cast<GLsizeiptr>(count * w));
    afterWrite(Write::Copy, kColumnReaders);
    c.device = true;
}

void GlMemory::written(Buffer b) { at(b).device = true; }

size_t GlMemory::deviceBytes() const {
    size_t bytes = 0;
    for (const auto& c : columns_)
        if (c && c->gl) bytes += std::max<size_t>(c->glRows * wordsPerRow(c->elem), 1) * 4;
    return bytes;
}

}  // namespace psys::gpu
