// The schedule of a step (rt/schedule.h): built from what each type's kernels yield, and
// printed.
#include "rt/schedule.h"

#include <algorithm>

#include <fmt/format.h>

#include "rt/system_state.h"

namespace psys::rt {

const char* phaseName(PhaseKind kind) {
    switch (kind) {
        case PhaseKind::Settle: return "settle";
        case PhaseKind::Ready: return "ready";
        case PhaseKind::Neighbours: return "neighbours";
        case PhaseKind::SubSteps: return "sub-steps";
        case PhaseKind::Update: return "update";
        case PhaseKind::Kills: return "kills";
        case PhaseKind::Emissions: return "emissions";
        case PhaseKind::Create: return "create";
        case PhaseKind::Release: return "release";
    }
    return "?";
}

namespace {

const char* parallelismName(Parallelism p) {
    switch (p) {
        case Parallelism::Chunks: return "chunks on every thread";
        case Parallelism::Pieces: return "pieces on every thread";
        case Parallelism::Memory: return "in the memory";
        case Parallelism::Host: return "host";
    }
    return "?";
}

std::string names(const Schedule& s, const std::vector<int>& types) {
    std::string out;
    for (int t : types) out += (out.empty() ? "" : ", ") + s.types[static_cast<size_t>(t)];
    return out;
}

// Whether `type`'s update runs in sub-steps (a group of the schedule's).
bool subStepped(const Schedule& s, int type) {
    return std::any_of(s.phases.begin(), s.phases.end(),
                       [&](const Phase& p) { return p.kind == PhaseKind::SubSteps && p.type == type; });
}

std::string describe(const Schedule& s, const Phase& p) {
    std::string type = p.type >= 0 ? s.types[static_cast<size_t>(p.type)] : "";
    switch (p.kind) {
        case PhaseKind::Settle: return "what the last step owes: its late kills taken, its dead freed";
        case PhaseKind::Ready: return "the rows created during the last step become updatable";
        case PhaseKind::Neighbours: {
            std::string over;
            for (int t : p.targets) over += (over.empty() ? "" : ", ") + s.types[static_cast<size_t>(t)];
            return fmt::format("{}: its folds over the {} near each of its objects: a grid of their positions, then "
                               "each object's neighbours in the grid's order", type, over);
        }
        case PhaseKind::SubSteps:
            return fmt::format("{}: the next {} phases once per sub-step of @step({:g})", type, p.span, p.stepLimit);
        case PhaseKind::Update: {
            std::string also;
            if (p.exports) also += ", the survivors' exports";
            if (p.render) also += ", the render when the host draws every step";
            std::string listed = p.inMemory ? (p.late ? ", its kills listed in the memory" : ", its rows in the memory")
                                 : p.late || p.listed ? ", its kills listed" : "";
            return fmt::format("{}: the update kernel over the pool{}{}", type, also, listed);
        }
        case PhaseKind::Kills:
            if (p.inMemory && subStepped(s, p.type))
                return fmt::format("{}: the kill lists kept for the step's end, where the memory frees them; an earlier "
                                   "sub-step's taken out of the masks there at once", type);
            if (p.inMemory) return fmt::format("{}: the kill lists kept for the step's end, where the memory frees them", type);
            if (p.late && subStepped(s, p.type))
                return fmt::format("{}: the last sub-step's listed kills kept for the step's end (nobody looks at them "
                                   "before); an earlier sub-step's killed rows frozen at once, in row order", type);
            return p.late ? fmt::format("{}: the listed kills kept for the step's end (nobody looks at them before)", type)
                          : fmt::format("{}: the killed rows ({}) frozen, then among the step's deaths in row order", type,
                                        p.listed ? "its chunks' lists" : "its kill flags read a piece at a time");
        case PhaseKind::Emissions: {
            if (p.inMemory)
                return fmt::format("{}: {} ({}) decided by the memory's operation over the rows — events, "
                                   "times, the cut at room, ids; only its totals to the host — then the queue: each "
                                   "target's objects one run, each site's spawn launches one launch, from the records",
                                   type, p.events ? "rate emissions of the survivors, bursts on edges and deaths" : "rate emissions",
                                   names(s, p.targets));
            return fmt::format("{}: {} ({}): each row's events and times a piece at a time, then the rows that "
                               "emit queued in row order: ids, the queue", type,
                               p.events ? "rate emissions of the survivors, bursts on edges and deaths" : "rate emissions of the survivors",
                               names(s, p.targets));
        }
        case PhaseKind::Create: {
            std::vector<int> kept;
            for (int t : p.targets)
                if (static_cast<size_t>(t) < s.inMemory.size() && s.inMemory[static_cast<size_t>(t)]) kept.push_back(t);
            std::string memory = kept.empty() ? "" : fmt::format(" ({}: rows, ids and creation times by the memory's "
                                                                 "operations)", names(s, kept));
            return fmt::format("what {} queued ({}) and what that queues: rows (pieces), init and the first update "
                               "(chunks); bursts, kills and emissions of the new objects in queue order{}",
                               type, names(s, p.targets), memory);
        }
        case PhaseKind::Release: {
            std::vector<int> kept;  // the types in the memory that die (a kills phase)
            for (const Phase& q : s.phases)
                if (q.kind == PhaseKind::Kills && q.inMemory &&
                    std::find(kept.begin(), kept.end(), q.type) == kept.end())
                    kept.push_back(q.type);
            std::string memory = kept.empty() ? "" : fmt::format("; {}: the kill lists freed in the memory, counted "
                                                                 "when the backend's counts come", names(s, kept));
            return "late kills taken in their place; the dead nobody reads freed onto the free stack (each piece's "
                   "rows at the place the counts before it give; a child's parent counted down in order)" + memory;
        }
    }
    return "";
}

}  // namespace

std::string printSchedule(const Schedule& s) {
    std::string out;
    std::vector<size_t> ends;  // where each open sub-step group ends
    for (size_t i = 0; i < s.phases.size(); ++i) {
        while (!ends.empty() && ends.back() <= i) ends.pop_back();
        const Phase& p = s.phases[i];
        std::string indent(2 * ends.size(), ' ');
        out += fmt::format("{:>3}. {}{:<10} {:<24} {}\n", i + 1, indent, phaseName(p.kind), parallelismName(p.parallelism),
                           describe(s, p));
        if (p.kind == PhaseKind::SubSteps) ends.push_back(i + 1 + p.span);
    }
    return out;
}

namespace detail {

// Per type, parents before children (the module's order): its update (in sub-steps under
// @step, each with its kills and emissions), then the creation of what it queued.
Schedule stepSchedule(const State& s) {
    Schedule out;
    for (const ir::Object& o : s.module.objects) out.types.push_back(o.name);
    for (const TypeInfo& info : s.types) out.inMemory.push_back(info.rowsInMemory);
    auto add = [&](PhaseKind kind, int type, Parallelism parallelism) -> Phase& {
        Phase& p = out.phases.emplace_back();
        p.kind = kind;
        p.type = type;
        p.parallelism = parallelism;
        return p;
    };
    add(PhaseKind::Settle, -1, Parallelism::Pieces);  // first: a step of no time runs it alone (System::step)
    add(PhaseKind::Ready, -1, Parallelism::Pieces);
    // Every type's folds before any update: each sees the others as the last step left them.
    for (size_t t = 0; t < s.types.size(); ++t) {
        const ir::Object& o = s.module.objects[t];
        if (o.neighbours.empty()) continue;
        Phase& p = add(PhaseKind::Neighbours, static_cast<int>(t), Parallelism::Chunks);
        for (const ir::NeighbourGroup& g : o.neighbours) {
            int target = s.module.objectIndex(g.target);
            if (std::find(p.targets.begin(), p.targets.end(), target) == p.targets.end()) p.targets.push_back(target);
        }
    }
    for (size_t t = 0; t < s.types.size(); ++t) {
        const TypeInfo& info = s.types[t];
        auto type = static_cast<int>(t);
        size_t group = out.phases.size();
        if (info.stepLimit > 0) add(PhaseKind::SubSteps, type, Parallelism::Host).stepLimit = info.stepLimit;
        bool listed = info.kills && !info.updateEmits;
        Phase& update = add(PhaseKind::Update, type, Parallelism::Chunks);
        update.late = info.late;
        update.listed = listed;
        update.exports = info.exports != nullptr;
        // (drawing as the step goes: where the backend's launches run on the host's memory)
        update.render = info.render != nullptr && info.drawn[0] && s.options.drawInStep && s.backend.rendersInStep();
        update.inMemory = info.rowsInMemory;
        if (info.kills || info.late) {
            // (late kills on the host: their lists handed to the ledger, no rows touched)
            Phase& kills = add(PhaseKind::Kills, type,
                               info.rowsInMemory ? Parallelism::Memory : info.late ? Parallelism::Host : Parallelism::Pieces);
            kills.late = info.late;
            kills.listed = listed;
            kills.inMemory = info.rowsInMemory;
        }
        std::vector<int> rated, targets;
        for (size_t site = 0; site < info.emitTarget.size(); ++site) {
            auto target = static_cast<int>(info.emitTarget[site]);
            if (s.module.objects[t].emits[site].inUpdate()) rated.push_back(target);
            targets.push_back(target);
        }
        if (info.updateEmits) {
            Phase& emissions =
                add(PhaseKind::Emissions, type, info.rowsInMemory ? Parallelism::Memory : Parallelism::Pieces);
            emissions.targets = rated;
            emissions.events = info.emitsWhenKilled;
            emissions.inMemory = info.rowsInMemory;  // Memory::emitAtRate
        }
        // An emitter in the memory, in sub-steps, of objects that emit nothing, read no
        // parent and take no sub-steps: what each sub-step queued is created after it, to
        // the step's end — the rows, ids and order it would take after the last (nothing
        // between frees or takes their rows, they create nothing, and what their first
        // update kills is freed in their queue order either way: a target in sub-steps
        // would free them in (batch, sub-step, row) order, not (sub-step, row)) — but each
        // sub-step's records of its emissions (Memory::emitAtRate: its rows × sites) go
        // with it, not held through every sub-step of a hitch.
        bool eachSubStep = info.stepLimit > 0 && info.rowsInMemory && info.updateEmits &&
                           std::all_of(targets.begin(), targets.end(), [&](int target) {
                               const TypeInfo& to = s.types[static_cast<size_t>(target)];
                               return s.module.objects[static_cast<size_t>(target)].emits.empty() &&
                                      to.parentType < 0 && to.stepLimit == 0;
                           });
        if (eachSubStep) add(PhaseKind::Create, type, Parallelism::Pieces).targets = targets;
        if (info.stepLimit > 0) out.phases[group].span = out.phases.size() - group - 1;
        if (info.updateEmits && !eachSubStep) add(PhaseKind::Create, type, Parallelism::Pieces).targets = targets;
    }
    add(PhaseKind::Release, -1, Parallelism::Pieces);
    return out;
}

}  // namespace detail

}  // namespace psys::rt
