// A generated test case: a program, what the host does to it frame by frame (triggers
// fired, externs set, a hot reload of an edit of it), and how long it runs. A case is kept
// as its program with these as `//!` lines at the top, and its edit in NAME.edit.psys
// beside it (tests/programs/generated/): the file is a program any tool can read.
//
//   //! frames 120
//   //! dt 0.0166667               (or `dt varied`: every frame its own, from the seed)
//   //! fire blast 0 2 0 @10       (before the step of frame 10)
//   //! set wind 1 0 0 @30
//   //! reload @60                 (NAME.edit.psys, before the step of frame 60)
//   //! compare fast               (fast maths must decide as exact maths: generator.h)
//   //! play 2 0 -1 @5             (an instance of an instanced program, translated so)
//   //! stop 0 @50                 (the first instance the case played; `kill 0` kills it)
//   //! speed 0 0.5 @20            (that instance's speed; `pause 0 1` pauses it, `pause 0 0` resumes)
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace psys::progen {

struct Event {
    enum class Kind { Fire, Set, Reload, Play, Stop, Kill, Speed, Pause } kind = Kind::Fire;
    int frame = 0;
    std::string name;           // the trigger or extern
    std::vector<float> values;  // its arguments or value; a play's translation; which played instance
};

struct Case {
    std::string source;
    std::string edit;  // the program a Reload event loads (empty: none)
    int frames = 120;
    double dt = 1.0 / 60;  // 0: varied, every frame's from `seed`
    uint64_t seed = 0;
    std::vector<Event> events;  // in frame order
    bool compareFast = false;   // fast maths creates and kills what exact maths does
    // Whether it sets an instance's speed or pauses one (rows kept in the memory cannot).
    bool paces() const;

    // The step of frame `f`.
    double stepAt(int f) const;
};

// The case as a file (its program with the `//!` lines on top) and its edit's text.
std::string caseText(const Case& c);
// A case from a file's text and its edit's (empty: none); nullopt with `error` set when a
// `//!` line is not understood.
std::optional<Case> parseCase(const std::string& text, const std::string& edit, std::string& error);
// Writes NAME.psys (and NAME.edit.psys where there is an edit) under `dir`; false on failure.
bool writeCase(const Case& c, const std::string& dir, const std::string& name);
// Reads PATH and, beside it, its edit.
std::optional<Case> readCase(const std::string& path, std::string& error);

}  // namespace psys::progen
