// Internal to rt/: the deaths of a step, from the kill to the free stack, in one record.
// A death is frozen when it is known — at once (a kill read from the flags or a chunk's
// list) or late (a launch whose kills are taken at the step's end: LateKills) — and freed
// by the step's Release phase: a type's in the order its deaths came, a frozen parent once
// its last reader is gone (Ledger::release says in which order). Where a backend still owes a late launch's kills at the step's end (it
// clearsKilled: the GPU), the step's deaths wait, in their order, for the next settle.
// Everything outside the step's Release phase goes through one call, `settle`: the
// schedule's Settle phase, a trigger, the start, finish, a reload, stats.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "rt/backend.h"
#include "rt/pool.h"

namespace psys::rt::detail {

struct State;

// The kills (and unstable counts) of launches that answered late (RowsLaunch::late) or
// whose kills are taken late: applied at the end of the step, in their place among the
// step's kills, so that rows are freed in the order they would have been at once. Only
// for types whose dead nobody looks at before then (TypeInfo::late): the room a creation
// sees counts a killed object as taken until the end of the step anyway.
struct LateKills {
    size_t type = 0;
    size_t at = 0;  // its place among the step's deaths (Ledger::defer sets it)
    struct Part {
        uint64_t ticket = 0;          // to collect (Backend::collect); 0: `rows` are here
        std::vector<uint32_t> rows;   // launch rows, in order
        // A type whose rows are in the memory: its launch's first row and kill list
        // (RowsLaunch::killList), whether the backend listed the kills there, and whether
        // they are counted (Pool::released).
        size_t begin = 0;
        Buffer killList;
        bool listed = false, counted = false;
        size_t count = 0;  // counted: how many
        // Its kills gathered into its type's list of the step's earlier sub-steps, its own
        // list gone (`taken`: Ledger::takeOut), or that list itself (`gathered`: its rows
        // are counted as the others' parts, where they were taken).
        bool taken = false, gathered = false;
        size_t lists = 0;  // gathered: the parts taken into it (each counts its own)
        // Empty, as made, its list's vector kept (Ledger::fresh).
        void reset() {
            std::vector<uint32_t> kept = std::move(rows);
            kept.clear();
            *this = {};
            rows = std::move(kept);
        }
    };
    std::vector<Part> parts;
    // A type whose rows are in the memory: its kills freed there at the end of the step,
    // in their place; a creation batch's rows (launch row first + r is pool row map[r]).
    bool released = false;
    Buffer map;
    double t1 = 0, dt = 0;  // a pool's update: killed at t1 − dt
    bool scaled = false;    // a scaled step's: at t1 − dt · its instance's speed (State::rowSpeed)
    // A creation batch's first update: launch row first + r is pool row poolRows[r],
    // killed at t1 − spans[r].
    size_t first = 0;
    std::vector<uint32_t> poolRows;
    std::vector<double> spans;
};

class Ledger {
public:
    explicit Ledger(State& state) : s_(state) {}

    // An object is dead: frozen now, freed at the end of the step unless children read it.
    // `at`: the time of its last values (those of the update before the one that killed it).
    void kill(size_t type, uint32_t row, double at);
    // The same for many (distinct rows: a launch's kill lists, one a chunk), in their order:
    // at[k] the k-th row's time, or at[0] every row's (Pool::freeze of many, on every thread).
    void kill(size_t type, Pool::RowLists lists, std::span<const double> at);
    void kill(size_t type, std::span<const uint32_t> rows, std::span<const double> at) {
        kill(type, Pool::RowLists(&rows, 1), at);
    }
    // A launch's kills as a part of a LateKills: its ticket, or the rows it listed, else
    // those of [begin, end) its kill flags (`flags`) mark.
    void record(LateKills::Part& part, const RowsResult& result, Buffer flags, size_t begin, size_t end) const;
    // Kills to take late, placed after the deaths known so far.
    void defer(LateKills late);
    // An empty LateKills of `type` with the vectors of one of its type taken before (with
    // `parts` parts, each empty): a steady-state step allocates none
    // (tests/capi/allocation_test.cpp). A type's vectors stay with it, so that they grow
    // to what its steps need and no more.
    LateKills fresh(size_t type, size_t parts = 0);
    // l.parts resized to `parts`, a new part with the vector of one of its type dropped before.
    void resizeParts(LateKills& l, size_t parts);
    // `lates` LateKills of `type` made now, each with `parts` parts, each with room for
    // `rowsEach` rows, for fresh to give (System::reserve).
    void reserve(size_t type, size_t parts, size_t rowsEach, size_t lates);

    // Where the backend must be waited for: `Yes` takes everything (what the last step
    // owes and every late kill; before anything takes rows or reads the pools whole: the
    // Settle phase, a trigger, finish, a reload); `No` only what costs no wait (what is
    // owed if the backend has it ready, and late kills on a backend that leaves kills to
    // the host: after objects are created outside a step, stats, finished).
    enum class Wait : bool { No, Yes };
    void settle(Wait wait);
    // The step's end (the Release phase): its deaths freed in their order (frozen parents
    // with readers kept), or, where the backend clearsKilled and still owes some late
    // kill, kept for the next settle.
    void endStep();
    // Before a hot reload (System::carryOver, after a settle that waits): the kills a
    // trigger left listed in the memory for the next step's end freed now, in row order —
    // as a reload frees the frozen rows of a pool kept on the host, after its free rows —
    // and counted: the new system keeps no record of the old one's deaths.
    void releaseForReload();
    // A late launch's kills of a type whose rows are in the memory and that children read,
    // listed and cleared in its masks now (not at the step's end): the children's
    // `parent.alive` in the same step sees them dead. Their deaths' times: a batch's
    // sub-step's from each object's clock where `nows` is given (Memory::stampDeaths).
    void listNow(LateKills& l, Buffer nows = {}, Buffer lengths = {});
    // A late launch's kills of a type whose rows are in the memory, listed and cleared in
    // both its masks now, freed at the step's end: an update before its last sub-step's
    // (the next sub-step must not update them), or a batch's (`batchMask`: its step mask,
    // by launch row, cleared too). Its lists are gathered into `into` (Memory::appendKills:
    // one list a type a step, or a batch, whatever the sub-steps), which deferGathered
    // placed among the step's deaths before them.
    void takeOut(LateKills& l, Buffer into, Buffer batchMask = {});
    // `into` (a u32 buffer of a row more than the pool's, or the batch's, rows) emptied and
    // placed among the step's deaths now, for takeOut to gather into.
    void deferGathered(size_t type, Buffer into);
    // A reload's (rt/reload.cpp, readers counted again): every frozen object nobody reads
    // freed, by the rule of the step's end (`release`), a pool's in row order.
    void freeUnread();

private:
    void releaseForReload(LateKills& late);  // (one type's kill lists; its waiting rows after)
    // (type, row) of each death, in order; no row twice, so a type's rows free in pieces on
    // every thread (Pool::releaseFrozen): kill of a row takes only the living, and the
    // lists kill and take are of living rows (an update's kill lists: its updatable rows;
    // a batch's: rows it just created).
    using Deaths = std::vector<std::pair<size_t, uint32_t>>;
    struct Owed {
        Deaths dying;
        std::vector<LateKills> late;
    };

    // A part's kills: collected from the backend once (its ticket cleared, its unstable
    // count added), or the rows it holds.
    RowsResult collect(size_t type, LateKills::Part& part);
    // The late kills frozen in their place among `deaths` (those of types whose rows are in
    // the memory listed, or counted where already freed, and kept).
    void take(Deaths& deaths, std::vector<LateKills>& lates);
    // take then release, at once: the late kills of a type that nobody reads and that
    // reads no parent go straight onto its free stack in their place (nothing else can
    // happen to them between), each part as one run of rows.
    void free(Deaths& deaths, std::vector<LateKills>& lates);
    // The rule that frees the rows of deaths (and of the parents they were the last readers of).
    void release(Deaths& deaths);
    bool owedReady();
    // A type whose rows are in the memory: its kills listed where the backend did not
    // (and, where it does not clear kills, cleared in the pool's masks), freed there at the
    // step's end, counted once the backend gives their counts.
    void listInMemory(LateKills& l, bool aliveOnly = false);
    static std::pair<uint32_t, size_t> listRows(const LateKills& l, const LateKills::Part& part);
    void releaseAllInMemory(std::vector<LateKills>& lates);
    void releaseInMemory(LateKills& l);
    void countInMemory(LateKills& l);
    void countParents();
    // The LateKills of `lates` kept for their vectors (fresh gives them again); `lates` emptied.
    void recycle(std::vector<LateKills>& lates);

    State& s_;
    Deaths dying_;
    std::vector<LateKills> late_;
    std::optional<Owed> owed_;
    // Kept from step to step for their vectors, per type: LateKills taken (fresh) and the
    // parts' lists resizeParts dropped; and take's, free's and release's lists.
    struct Spares {
        std::vector<LateKills> lates;
        std::vector<std::vector<uint32_t>> rows;
    };
    std::vector<Spares> spares_;
    Spares& spares(size_t type);
    static constexpr size_t kMostSpares = 8;  // LateKills kept a type (a step takes one or two)
    struct Lists {
        Deaths merged, kept, its;
        std::vector<LateKills> keptLates, single;
        std::vector<std::vector<uint32_t>> own, waited, copies;
        std::vector<std::span<const uint32_t>> spans;
    } lists_;
};

}  // namespace psys::rt::detail
