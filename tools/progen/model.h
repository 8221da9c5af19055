// The generator's model of a program (tools/progen/generator.cpp): types, their
// equations, draws, kills and emits, triggers, externs and spawns, and its text.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace psys::progen {

// A number as the programs write it: three decimals at most, no trailing zeros.
std::string num(double v);

enum class Ty { Float, Vec3 };

struct Param {
    std::string name;
    Ty ty;
};

struct Emit {
    enum Kind { Rate, RateCount, Burst, When, Death } kind = Burst;
    int target = 0;
    std::string rate, count, cond;
    std::vector<std::string> args;
};

struct Type {
    std::string name;
    int parent = -1;
    int depth = 0;
    std::vector<Param> params;
    std::vector<std::string> attrs;
    std::vector<std::string> equations;  // whole statements
    std::string draw;
    std::vector<std::string> kills;  // conditions
    std::string whenKill;           // a `when C { kill; }` condition, or empty
    std::vector<Emit> emits;
    // Notifications (`notify "NAME"(…)`, docs/language.md "Events"): whole statements, those
    // `on death` printed only where the type dies (as its death emits are).
    std::vector<std::string> notifies, deathNotifies;
    std::vector<int> children;
    bool hasVel = false, removed = false;
    int foldOver = -1;  // the type its `crowd` fold reads
};

struct Trigger {
    std::string name;
    std::vector<Param> params;
    std::vector<Emit> emits;
};

struct Extern {
    std::string name;
    Ty ty;
    double lo, hi, def;
};

struct Model {
    std::vector<Extern> externs;
    std::vector<Type> types;
    std::vector<Trigger> triggers;
    std::vector<std::pair<int, std::vector<std::string>>> spawns;
    std::string fileAttr;
    bool instanced = false;  // its draws read `instance.pos`: the case plays instances
};

// The program's text.
std::string print(const Model& m);

}  // namespace psys::progen
