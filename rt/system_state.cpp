// The parts of a System share this: the object store (pools, parents, deaths), the
// uniform values, parent gathering and the column tables of launches over pools.
#include "rt/system_state.h"

#include <algorithm>
#include <bit>
#include <stdexcept>

#include "core/few.h"
#include "core/fold.h"
#include "rt/system_support.h"

namespace psys::rt::detail {

using ir::KernelKind;
using ir::YieldKind;

Scratch::~Scratch() {
    for (Buffer b : buffers_) memory_->release(b);
}

Buffer Scratch::at(size_t index, Elem elem, size_t rows, size_t room) {
    while (buffers_.size() <= index) buffers_.push_back({});
    Buffer& b = buffers_[index];
    if (!b.valid() || memory_->elem(b) != elem) {
        Buffer made = memory_->create(elem, rows);  // (first: a failure leaves b as it was)
        if (b.valid()) memory_->release(b);
        b = made;
    } else if (memory_->rows(b) < rows) {
        memory_->resize(b, rows);
    }
    if (room > rows) memory_->reserve(b, room);
    return b;
}

namespace {

TypeInfo typeInfo(const ir::Module& module, const ir::Object& o) {
    TypeInfo t;
    t.parentType = o.parent.empty() ? -1 : module.objectIndex(o.parent);
    t.stepLimit = o.attributes.step;
    t.init = initKernel(o);
    t.update = o.kernel(KernelKind::Update);
    t.exports = o.kernel(KernelKind::Exports);
    t.render = o.kernel(KernelKind::Render);
    if (!t.update) throw std::invalid_argument("object " + o.name + " has no update kernel: the module was not compiled");
    t.updateLayout = columnLayout(o, *t.update);
    if (t.exports) t.exportsLayout = columnLayout(o, *t.exports);
    if (t.render) {
        t.renderLayout = columnLayout(o, *t.render);
        for (const ir::Yield& y : t.render->yields) {
            if (y.kind == YieldKind::Visible) t.drawn[0] = true;
            if (y.kind == YieldKind::Position) t.drawn[1] = true;
            if (y.kind == YieldKind::Color) t.drawn[2] = true;
            if (y.kind == YieldKind::Size) t.drawn[3] = true;
        }
    }
    // What a creation batch zeroes: the compiler's record of what init leaves (every slot
    // where nothing runs at creation).
    if (t.init)
        for (int slot : t.init->storage.zeroed) t.zeroedState.push_back(static_cast<size_t>(slot));
    else
        for (size_t s = 0; s < o.state.size(); ++s) t.zeroedState.push_back(s);
    t.counted.assign(o.emits.size(), false);
    t.rated.assign(o.emits.size(), false);
    for (const ir::Yield& y : t.update->yields) {
        if (y.kind == YieldKind::Kill) t.kills = true;
        if (y.kind == YieldKind::Unstable) t.unstable = true;
        if (y.kind == YieldKind::EmitCount) t.counted[static_cast<size_t>(y.index)] = true;
        if (y.kind == YieldKind::EmitRate) t.rated[static_cast<size_t>(y.index)] = true;
    }
    for (size_t s = 0; s < o.emits.size(); ++s) {
        t.updateEmits |= o.emits[s].inUpdate();
        t.bursts |= o.emits[s].atCreation();
        t.emitsWhenKilled |= o.emits[s].whenKilled();
        const ir::Kernel* spawn = o.kernel(KernelKind::Spawn, static_cast<int>(s));
        t.spawn.push_back(spawn);
        t.emitTarget.push_back(static_cast<size_t>(module.objectIndex(o.emits[s].target)));
        t.spawnLayout.push_back(spawn ? columnLayout(o, *spawn) : ColumnLayout{});
    }
    return t;
}

// The types in a chain of bursts at creation (`object a { emit a; … }`, or a and b
// bursting each other), which are no emitters the memory decides: every object makes the
// next wave as it is created, so where the memory decides, a wave of one object is a batch
// of a dozen dispatches and a wait on a GPU — 10,000 waves took 9.2 s for 600 frames,
// 0.26 s where the host decides (docs/performance.md, "A chain of bursts at creation"). (A chain through bursts on edges or deaths
// makes such waves only where objects fire them as they are created or in their first
// update.)
std::vector<bool> burstChains(const std::vector<TypeInfo>& types, const ir::Module& module) {
    std::vector<bool> chained(types.size(), false);
    for (size_t from = 0; from < types.size(); ++from) {
        std::vector<bool> seen(types.size(), false);
        std::vector<size_t> next = {from};
        while (!next.empty() && !chained[from]) {
            size_t t = next.back();
            next.pop_back();
            for (size_t e = 0; e < module.objects[t].emits.size(); ++e) {
                size_t target = types[t].emitTarget[e];
                if (module.objects[t].emits[e].when != ir::EmitSite::When::Creation || seen[target]) continue;
                chained[from] = chained[from] || target == from;
                seen[target] = true;
                next.push_back(target);
            }
        }
    }
    return chained;
}

// A top-level type not drawn as the step goes (by a backend that draws on the host).
bool keptWhole(const TypeInfo& info, const SystemOptions& options, const Backend& backend) {
    return info.parentType < 0 && !(options.drawInStep && backend.rendersInStep() && info.render);
}

// The types that only die or never die: whose kills are late (TypeInfo::late) and which of
// them keep their rows in the memory (rowsInMemory).
void decideParticles(std::vector<TypeInfo>& types, const SystemOptions& options, bool inMemory, const Backend& backend) {
    // Nobody looks at the type's dead during the step: it emits nothing in its updates, has
    // no exports and no children.
    auto unwatched = [](const TypeInfo& t) { return !t.updateEmits && !t.exports && !t.read; };
    for (TypeInfo& t : types) t.late = options.lateKills && (t.kills || t.unstable) && unwatched(t);
    // Rows in the memory: where nothing but the type's own late kills frees them — or
    // nothing at all: it never dies, so its exports are every updated row's (folds read
    // them) — and its objects are created in a batch (no bursts, not drawn as the step
    // goes). Such a type may take sub-steps: each sub-step's kills are listed there and
    // taken out of its masks at once, freed at the step's end (Ledger::takeOut), and a
    // batch's first update steps each object through its own sub-steps
    // (Memory::subStepClocks).
    // (An emitter's bursts at creation, below, are the memory's too.)
    // A type that only dies whose exports folds read (no children) is one too: its kills
    // late all the same — a fold reads the rows updatable at the step's start — and its
    // exports those of its survivors, from the kill flags where they are (Memory::survivors;
    // under @step, each sub-step's survivors', at its clock).
    for (size_t t = 0; t < types.size(); ++t) {
        TypeInfo& info = types[t];
        bool silent = !info.kills && !info.unstable && !info.updateEmits && !info.read;
        bool folded = options.lateKills && (info.kills || info.unstable) && !info.updateEmits && !info.read &&
                      info.exports;
        info.rowsInMemory = inMemory && (info.late || silent || folded) && !info.bursts && keptWhole(info, options, backend);
        info.late = info.late || (info.rowsInMemory && folded);
    }
}

// The shapes of children that may keep their rows in the memory beside their parents
// (decideEmitters): a nested type created in a batch and not drawn as the step goes —
// `quiet` where it emits nothing, is read by no child, and its kills are late or it never
// dies (as a type that only dies); else only if it is such an emitter itself.
struct ChildShapes {
    std::vector<bool> shape, quiet;
};
ChildShapes childShapes(const std::vector<TypeInfo>& types, const ir::Module& module, const SystemOptions& options,
                        bool inMemory, const Backend& backend) {
    ChildShapes c{std::vector<bool>(types.size(), false), std::vector<bool>(types.size(), false)};
    for (size_t t = 0; t < types.size(); ++t) {
        const TypeInfo& info = types[t];
        bool silent = !info.kills && !info.unstable && !info.updateEmits;
        c.shape[t] = inMemory && options.createInBatches && info.parentType >= 0 &&
                     !(options.drawInStep && backend.rendersInStep() && info.render);
        c.quiet[t] = c.shape[t] && !info.read && (info.late || silent) && module.objects[t].emits.empty();
    }
    return c;
}

// The emitters whose emissions the memory decides (Memory::emitAtRate), and the children
// whose rows it keeps beside their parents — where rows are kept in the memory (a
// device's backend asks for it, any backend with Rows::InMemory) and objects are created
// in batches. Every site of such an emitter emits — at a rate, in a burst at creation, on
// an edge or on death — into a type whose rows are the memory's, its arguments' reads
// of its ancestors and its own folds gathered into columns before the operation
// (State::gatherSpawnParents; a new emitter's ancestors' ages at each of its own
// sub-steps: Creation::agesAtSubStep), so a step's
// emissions are one operation over the rows, and the objects they create batches of
// those types, whose bursts at creation and first updates emit by the same operation.
// Sites into one type share its room, their objects one batch in the host's order
// (rt::RateSites: a group); the batches of a step's generation go type by type, wherever
// its emissions were decided (Creation::groupByType).
// One that dies has its kills late, as a type's that only dies — nobody but its children
// looks at them before the step's end — and the operation reads its update's kill flags
// where they are (a row killed emits at no rate, and bursts); its exports, where children
// or folds read them, are its survivors' (Memory::survivors). In sub-steps (@step), each
// sub-step's emissions follow its update, over its clock, before what it killed is taken
// out of the masks (runEmissions; a new object's first update:
// Creation::firstUpdateInMemory) — where children read it, out of both at once
// (Ledger::takeOut); its exports are its last sub-step's survivors', each new one's at
// its own last clock. Where the emitters' rows are on a device, the host still reads the
// operation's totals back in the step (docs/gpu.md, "Emitters in the memory").
// Children beside their parents (ChildShapes): their ancestors' exports, whether they are
// alive and their ages gathered through their parents' rows (State::gatherThrough:
// further up, through each ancestor pool's), at each sub-step's clock in sub-steps — the
// parent type such an emitter, every type that reads it such a child, so that the
// parents' rows, readers and frozen objects are the memory's (Memory::releaseUnread). (A
// fold over it reads the rows updatable at the step's start, as on the host: a frozen
// parent is not among them.)
// They are decided together, as the greatest set that holds: every type starts a
// candidate and one that fails its rules — a target outside the memory among them —
// leaves, until none does; so an emitter of its own type (a rocket of rockets), two
// emitters of each other, and a child that emits beside its parent keep their rows in the
// memory, as a chain of emitters does. A chain of bursts at creation does not
// (burstChains).
void decideEmitters(std::vector<TypeInfo>& types, const ir::Module& module, const SystemOptions& options, bool inMemory,
                    const Backend& backend) {
    const ChildShapes shapes = childShapes(types, module, options, inMemory, backend);
    std::vector<bool> candidate(types.size(), true);
    auto child = [&](size_t t) { return shapes.quiet[t] || (shapes.shape[t] && candidate[t]); };
    auto readByChildren = [&](size_t t) {  // (every reader such a child)
        for (size_t c = 0; c < types.size(); ++c)
            if (types[c].parentType == static_cast<int>(t) && !child(c)) return false;
        return true;
    };
    auto inMemoryOr = [&](size_t target) {
        int parent = types[target].parentType;
        return types[target].rowsInMemory || candidate[target] ||
               (child(target) && parent >= 0 && candidate[static_cast<size_t>(parent)]);
    };
    auto decidedInMemory = [&](size_t t) {
        const TypeInfo& info = types[t];
        bool dies = info.kills || info.unstable;
        bool whole = keptWhole(info, options, backend);
        bool emitter = inMemory && options.createInBatches && (info.updateEmits || info.bursts) &&
                       (!dies || options.lateKills) && (!info.read || readByChildren(t)) &&
                       (whole || (shapes.shape[t] && candidate[static_cast<size_t>(info.parentType)]));
        for (size_t s = 0; emitter && s < module.objects[t].emits.size(); ++s) {
            size_t target = info.emitTarget[s];
            bool itsChild = child(target) && types[target].parentType == static_cast<int>(t);
            emitter = inMemoryOr(target) || itsChild;
        }
        return emitter;
    };
    std::vector<bool> chained = burstChains(types, module);
    for (size_t t = 0; t < types.size(); ++t) candidate[t] = !types[t].rowsInMemory && !chained[t] && decidedInMemory(t);
    for (bool fewer = true; fewer;) {
        fewer = false;
        for (size_t t = 0; t < types.size(); ++t)
            if (candidate[t] && !decidedInMemory(t)) candidate[t] = false, fewer = true;
    }
    for (size_t t = 0; t < types.size(); ++t) {
        if (!candidate[t]) continue;
        TypeInfo& info = types[t];
        info.rowsInMemory = true;
        info.late = info.late || info.kills || info.unstable;
        for (TypeInfo& c : types)  // (its children: `child` above, some of them candidates too)
            if (c.parentType == static_cast<int>(t)) c.rowsInMemory = true;
    }
}

// Which types' kills are late and which keep their rows in the memory (TypeInfo::late,
// rowsInMemory), decided once for the program.
void decideRows(std::vector<TypeInfo>& types, const ir::Module& module, const SystemOptions& options,
                const Backend& backend) {
    bool inMemory = options.rows == SystemOptions::Rows::InMemory ||
                    (options.rows == SystemOptions::Rows::AsBackend && backend.keepsRowsInMemory());
    decideParticles(types, options, inMemory, backend);
    decideEmitters(types, module, options, inMemory, backend);
}

// The backend's memory, taking its memory from the host's allocator where the options
// give one (before anything of the state is made in it).
Memory& allocatingFrom(Memory& memory, const HostAllocator& allocator) {
    memory.useAllocator(allocator);
    return memory;
}

}  // namespace

State::State(ir::Module m, Backend& b, SystemOptions o)
    : module(std::move(m)),
      backend(b),
      memory(allocatingFrom(b.memory(), o.allocator)),
      options(o),
      ancestors(b.memory()),
      parallel(std::make_unique<Parallel>(o.threads)) {
    if (module.instanced() && !memory.hostResident()) throw std::runtime_error(std::string(core::kNoInstances));
    for (const ir::Object& obj : module.objects) {
        size_t capacity = obj.attributes.capacity ? static_cast<size_t>(*obj.attributes.capacity) : options.capacity;
        pools.emplace_back(obj, capacity, memory);
        pools.back().runPiecesWith([this](size_t pieces, core::FunctionRef<void(size_t)> piece) {
            parallel->forEach(pieces, true, piece);
        });
        types.push_back(typeInfo(module, obj));
        typeStats.push_back({obj.name, 0, 0, 0, 0, 0});
    }
    std::vector<int> depth(types.size(), 0);
    for (size_t t = 0; t < types.size(); ++t) {
        if (types[t].parentType >= 0) types[static_cast<size_t>(types[t].parentType)].read = true;
        for (int up = types[t].parentType; up >= 0; up = types[static_cast<size_t>(up)].parentType) ++depth[t];
        deepestFirst.push_back(t);
    }
    std::stable_sort(deepestFirst.begin(), deepestFirst.end(), [&](size_t a, size_t b) { return depth[a] > depth[b]; });
    decideRows(types, module, options, backend);
    for (size_t t = 0; t < types.size(); ++t)
        if (types[t].rowsInMemory)
            pools[t].keepRowsInMemory(types[t].parentType >= 0, types[t].read);
    for (size_t t = 0; t < types.size(); ++t)  // (after every pool is: a parent's readers)
        if (types[t].rowsInMemory && types[t].parentType >= 0)
            pools[t].countsDownParent(pools[static_cast<size_t>(types[t].parentType)].memoryRows().readers);
    // Spawn kernels read the emitter's own columns, whose buffers never change: their
    // tables are bound once (the parent values come with each launch from the host, or,
    // for a launch from records, in parent columns gatherSpawnParents binds).
    for (size_t t = 0; t < pools.size(); ++t) {
        work.emplace_back(memory);
        for (const ColumnLayout& layout : types[t].spawnLayout) {
            std::vector<Buffer> table;
            if (layout.total > 0) {
                bindPool(t, layout, work[t].update, table);
                for (int column = layout.emits; column < layout.total; ++column) table[static_cast<size_t>(column)] = {};
                table[ColumnLayout::kKill] = {};
            }
            work[t].spawnTables.push_back(std::move(table));
        }
    }
    for (const ir::Extern& e : module.externs) externs.push_back({e.defaultValue, 0});
    if (module.instanced()) {  // the system's own instance, playing where the host has not moved it
        externs.push_back(Value::scalar(0));
        growInstances(1);
        setLife(0, InstanceLife::Playing);
    }
    uniformCache.resize(pools.size());
}

State::~State() = default;

std::pair<int, uint32_t> State::ancestor(size_t type, uint32_t row, int depth) const {
    int t = static_cast<int>(type);
    uint32_t r = row;
    for (int d = 0; d < depth; ++d) {
        Handle h = pools[static_cast<size_t>(t)].parent[r];
        t = types[static_cast<size_t>(t)].parentType;
        if (t < 0 || !h.valid() || !pools[static_cast<size_t>(t)].matches(h)) return {-1, 0};
        r = h.row;
    }
    return {t, r};
}


const ir::Kernel* State::uniformKernel(size_t type, const ir::Kernel& kernel) const {
    auto served = ir::uniformFor(kernel.kind);
    return served ? module.objects[type].kernel(*served) : nullptr;
}

const Value* State::uniforms(size_t type, const ir::Kernel& kernel, float dt, float time) {
    const ir::Kernel* u = uniformKernel(type, kernel);
    if (!u) return nullptr;
    size_t slot = kernel.kind == KernelKind::Update ? 0 : kernel.kind == KernelKind::Render ? 1 : 2;
    UniformCache& cache = uniformCache[type][slot];
    if (!cache.valid || cache.dt != dt || cache.time != time || cache.externs != externsVersion) {
        ir::KernelInputs in;
        in.externs = externs.data();
        in.dt = dt;
        in.time = time;
        in.seed = options.seed;
        std::vector<Value>& values = uniformValues;
        evaluator.run(*u, in, values);
        cache.values.assign(values.size(), Value{});
        for (size_t i = 0; i < u->yields.size(); ++i) cache.values.at(static_cast<size_t>(u->yields[i].index)) = values[i];
        cache.valid = true;
        cache.dt = dt;
        cache.time = time;
        cache.externs = externsVersion;
        ++stats.uniformEvaluations;
    }
    return cache.values.data();
}

void State::parentValues(size_t type, uint32_t row, const ColumnLayout& layout, double at, std::vector<Value>& out) const {
    out.clear();
    for (const auto& p : layout.parentColumns) {
        auto [t, r] = ancestor(type, row, p.depth);
        const Pool* parent = t < 0 ? nullptr : &pools[static_cast<size_t>(t)];
        Value v;
        if (p.op == ir::Op::ParentExport && parent) v = parent->exports.get(memory, static_cast<size_t>(p.exportIndex), r);
        if (p.op == ir::Op::Fold) {  // this object's own
            const Pool& self = pools[type];
            v = self.folds.get(memory, static_cast<size_t>(p.exportIndex), std::min<size_t>(row, self.foldRows));
        }
        if (p.op == ir::Op::ParentAlive) v = Value::boolean(parent && parent->status(r) == Status::Alive);
        if (p.op == ir::Op::ParentAge && parent) v = Value::scalar(ageAt(parent->ageClock(r, at), view<double>(parent->created)[r]));
        out.push_back(v);
    }
}

// A parent's exports are gathered where they live (Memory::gather: on the GPU for a GPU
// backend, so that children read their parents without the host waiting for the GPU);
// whether it is alive and its age are the host's, written into the launch's rows.
void State::gatherParents(size_t type, const ColumnLayout& layout, std::span<const Buffer> table, const uint8_t* mask,
                          size_t begin, size_t end, double at, const double* atRows, const uint32_t* poolRows,
                          size_t poolRowsFirst) {
    if (layout.parentColumns.empty() || end <= begin) return;
    // A pool's launch: its parents' rows where they are (per-row clocks: a reload's, at
    // each object's creation, its pool's created column).
    if (pools[type].parentRows.valid() && !poolRows)
        gatherThrough(type, layout, table, pools[type].parentRows, begin, begin, end, at,
                      atRows ? pools[type].created : Buffer{});
    // (On the stack up to 1,024 rows — chunks gather on every thread, and a launch
    // allocates nothing on whatever thread runs it: core/few.h — past them in the
    // thread's own vectors, kept from launch to launch.)
    thread_local std::vector<uint32_t> manyRows;
    thread_local std::vector<float> manyValues;
    core::Few<uint32_t, 1024> rows(end - begin, manyRows);
    core::Few<float, 1024> values(end - begin, manyValues);
    int rowsDepth = -1;
    for (const auto& p : layout.parentColumns) {
        // A pool's launch: its folds copied row for row (on a device, no list sent; no mask
        // read: a pool whose rows are in the memory has none on the host); rows past the
        // folds' hold objects created since, which fold over nothing.
        if (p.op == ir::Op::Fold && !poolRows) {
            const Pool& pool = pools[type];
            size_t stop = std::clamp(pool.foldRows, begin, end);
            for (int c = 0; c < p.width; ++c)
                memory.copy(pool.folds.column(static_cast<size_t>(p.exportIndex), static_cast<size_t>(c)), begin,
                            table[static_cast<size_t>(p.offset + c)], begin, stop - begin);
            emptyFold(type, p, table, stop, end - stop);
            continue;
        }
        if (pools[type].parentRows.valid()) continue;  // (gatherThrough's)
        int parentType = static_cast<int>(type);
        for (int d = 0; d < p.depth && parentType >= 0; ++d) parentType = types[static_cast<size_t>(parentType)].parentType;
        if (p.depth != rowsDepth) {  // the parents' rows, kSkipRow where there is none
            for (size_t i = begin; i < end; ++i) {
                uint32_t row = poolRows ? poolRows[i - poolRowsFirst] : static_cast<uint32_t>(i);
                auto [t, r] = mask[i] ? ancestor(type, row, p.depth) : std::pair<int, uint32_t>{-1, 0};
                rows[i - begin] = t < 0 ? kSkipRow : r;
            }
            rowsDepth = p.depth;
        }
        if (p.op == ir::Op::Fold) {  // this object's own folds (rows: its own)
            const Pool& pool = pools[type];
            foldRowsOf(type, rows.span());
            for (int c = 0; c < p.width; ++c)
                memory.gather(pool.folds.column(static_cast<size_t>(p.exportIndex), static_cast<size_t>(c)),
                              table[static_cast<size_t>(p.offset + c)], begin, rows.span());
            rowsDepth = -1;
            continue;
        }
        if (p.op == ir::Op::ParentExport) {
            for (int c = 0; c < p.width; ++c) {
                Buffer to = table[static_cast<size_t>(p.offset + c)];
                if (parentType < 0) {
                    memory.clear(to, begin, end - begin);
                    continue;
                }
                const Pool& parent = pools[static_cast<size_t>(parentType)];
                memory.gather(parent.exports.column(static_cast<size_t>(p.exportIndex), static_cast<size_t>(c)), to, begin,
                              rows.span());
            }
            continue;
        }
        std::fill_n(values.data(), values.size(), 0.0f);
        for (size_t i = begin; i < end; ++i) {
            if (rows[i - begin] == kSkipRow) continue;
            const Pool& parent = pools[static_cast<size_t>(parentType)];
            uint32_t r = rows[i - begin];
            if (p.op == ir::Op::ParentAlive) values[i - begin] = parent.status(r) == Status::Alive ? 1.0f : 0.0f;
            if (p.op == ir::Op::ParentAge)
                values[i - begin] = ageAt(parent.ageClock(r, atRows ? atRows[i] : at), view<double>(parent.created)[r]);
        }
        memory.write(table[static_cast<size_t>(p.offset)], begin, end - begin, values.data());
    }
}

void State::parentsToHost() {
    for (size_t t = 0; t < pools.size(); ++t) {
        Pool& pool = pools[t];
        if (pool.frozenAt.valid() && pool.rows() > 0) memory.read(pool.frozenAt, 0, pool.rows(), pool.diedAt.data());
        if (!pool.parentRows.valid() || pool.rows() == 0) continue;
        const HostArray<uint32_t>& generation = pools[static_cast<size_t>(types[t].parentType)].generations();
        std::vector<uint32_t> rows(pool.rows());
        memory.read(pool.parentRows, 0, rows.size(), rows.data());
        for (size_t r = 0; r < rows.size(); ++r)
            pool.parent[r] = rows[r] < generation.size() ? Handle{rows[r], generation[rows[r]]} : Handle{};
    }
}

void State::gatherSpawnParents(size_t type, std::span<const size_t> sites, double at) {
    const size_t rows = pools[type].rows();
    size_t first = 0;  // (each site's columns its own: launches of several sites wait together)
    for (size_t site = 0; site < types[type].spawnLayout.size(); ++site) {
        const ColumnLayout& layout = types[type].spawnLayout[site];
        const auto width = static_cast<size_t>(layout.total - layout.parents);
        if (width > 0 && rows > 0 && std::find(sites.begin(), sites.end(), site) != sites.end()) {
            std::vector<Buffer>& table = work[type].spawnTables[site];
            for (size_t c = 0; c < width; ++c)
                table[static_cast<size_t>(layout.parents) + c] = work[type].spawnParents.at(first + c, Elem::F32, rows);
            gatherParents(type, layout, table, nullptr, 0, rows, at, nullptr, nullptr, 0);
        }
        first += width;
    }
}

void State::gatherThrough(size_t type, const ColumnLayout& layout, std::span<const Buffer> table, Buffer parents,
                          size_t parentsFirst, size_t begin, size_t end, double at, Buffer atRows) {
    // The ancestors `depth` levels up, and their rows: a parent's through `parents`, one
    // further up through that pool's parents (Memory::ancestorRows), and so on.
    struct Up {
        size_t type;
        Buffer rows;
        size_t first;
    };
    std::vector<Up> up = {{static_cast<size_t>(types[type].parentType), parents, parentsFirst}};
    std::unique_lock<std::mutex> inUse(ancestorsInUse, std::defer_lock);  // (held from the first use of `ancestors` on)
    auto ancestor = [&](int depth) -> const Up& {
        while (up.size() < static_cast<size_t>(depth)) {
            if (!inUse.owns_lock()) inUse.lock();
            const Up& below = up.back();
            Buffer rows = ancestors.at(up.size() - 1, Elem::U32, end - begin);
            memory.ancestorRows(pools[below.type].parentRows, rows, 0, below.rows, below.first, end - begin);
            up.push_back({static_cast<size_t>(types[below.type].parentType), rows, 0});
        }
        return up[static_cast<size_t>(depth) - 1];
    };
    for (const auto& p : layout.parentColumns) {
        if (p.op == ir::Op::Fold) continue;  // (folds: gatherParents', emptyFolds')
        const auto [parentType, parentRows, rowsFirst] = ancestor(p.depth);
        const Pool& parent = pools[parentType];
        if (p.op == ir::Op::ParentAlive)
            memory.gatherAlive(parent.alive.column, table[static_cast<size_t>(p.offset)], begin, parentRows, rowsFirst,
                               end - begin);
        if (p.op == ir::Op::ParentAge)
            memory.gatherAge(parent.created, parent.frozenAt, parent.alive.column, table[static_cast<size_t>(p.offset)],
                             begin, parentRows, rowsFirst, end - begin, at, atRows, begin);
        if (p.op != ir::Op::ParentExport) continue;
        for (int c = 0; c < p.width; ++c)
            memory.gatherThrough(parent.exports.column(static_cast<size_t>(p.exportIndex), static_cast<size_t>(c)),
                                 table[static_cast<size_t>(p.offset + c)], begin, parentRows, rowsFirst, end - begin);
    }
}

void State::emptyFold(size_t type, const ColumnLayout::ParentColumn& p, std::span<const Buffer> table, size_t first,
                      size_t count) {
    float empty = core::emptyFold(module.objects[type].folds.at(static_cast<size_t>(p.exportIndex)).reduce);
    for (int c = 0; c < p.width; ++c)
        memory.fill(table[static_cast<size_t>(p.offset + c)], first, count, std::bit_cast<uint32_t>(empty));
}

void State::bindPool(size_t type, const ColumnLayout& layout, Scratch& scratch, std::vector<Buffer>& table) {
    Pool& pool = pools[type];
    pool.syncMasks();
    const ir::Object& o = pool.object();
    size_t rows = pool.rows();
    table.assign(static_cast<size_t>(layout.total), Buffer{});
    table[ColumnLayout::kCreated] = pool.created;
    table[ColumnLayout::kIds] = pool.ids;
    table[ColumnLayout::kKill] = scratch.at(0, Elem::U8, rows, pool.room());
    for (size_t s = 0; s < o.state.size(); ++s)
        for (int c = 0; c < o.state[s].type.width; ++c)
            table[static_cast<size_t>(layout.stateOffset[s] + c)] = pool.state.column(s, static_cast<size_t>(c));
    for (size_t p = 0; p < o.params.size(); ++p)
        if (pool.paramColumn[p] >= 0)
            for (int c = 0; c < o.params[p].type.width; ++c)
                table[static_cast<size_t>(layout.paramOffset[p] + c)] =
                    pool.params.column(static_cast<size_t>(pool.paramColumn[p]), static_cast<size_t>(c));
    for (size_t e = 0; e < o.exports.size(); ++e)
        for (int c = 0; c < o.exports[e].type.width; ++c)
            table[static_cast<size_t>(layout.exportOffset[e] + c)] = pool.exports.column(e, static_cast<size_t>(c));
    for (int column = layout.emits; column < layout.total; ++column)
        if (layout.needs(column))
            table[static_cast<size_t>(column)] =
                scratch.at(static_cast<size_t>(1 + column - layout.emits), Elem::F32, rows, pool.room());
}

size_t State::chunkCount(size_t rows) const {
    size_t per = backend.chunkRows();
    return rows / per + (rows % per != 0);
}

void State::forRows(size_t first, size_t end, core::FunctionRef<void(size_t, size_t)> fn) {
    if (end <= first) return;
    size_t chunks = (end - first + kHostRows - 1) / kHostRows;
    parallel->forEach(chunks, true, [&](size_t c) {
        size_t begin = first + c * kHostRows;
        fn(begin, std::min(end, begin + kHostRows));
    });
}

void State::scatter(std::span<const std::pair<Buffer, Buffer>> columns, size_t fromFirst, std::span<const uint32_t> rows) {
    if (!backend.concurrent()) {
        for (auto [from, to] : columns) memory.scatter(from, fromFirst, to, rows);
        return;
    }
    forRows(0, rows.size(), [&](size_t begin, size_t end) {
        for (auto [from, to] : columns) memory.scatter(from, fromFirst + begin, to, rows.subspan(begin, end - begin));
    });
}

void State::forChunks(size_t first, size_t end, core::FunctionRef<void(size_t, size_t, size_t)> chunk) {
    size_t per = backend.chunkRows();
    parallel->forEach(chunkCount(end - first), backend.concurrent(), [&](size_t c) {
        size_t begin = first + c * per;
        chunk(c, begin, begin + std::min(per, end - begin));
    });
}

}  // namespace psys::rt::detail
