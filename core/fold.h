// The neighbour folds of .psys (`near_sum(boid, 2, other.vel)`, docs/language.md,
// "Neighbours"): how each combines its terms, its name in the language and in the IR, and
// what it is over no neighbours. The front end, the IR and every backend read this table.
#pragma once

#include <limits>
#include <optional>
#include <string_view>

namespace psys::core {

enum class Reduce : unsigned char { Sum, Min, Max, Count };

struct ReduceInfo {
    Reduce reduce;
    std::string_view name;     // in the IR's text: `fold sum: vec3 #0`
    std::string_view builtin;  // in .psys
    bool term;                 // whether it takes a term (count does not)
};
inline constexpr ReduceInfo kReduces[] = {
    {Reduce::Sum, "sum", "near_sum", true},
    {Reduce::Min, "min", "near_min", true},
    {Reduce::Max, "max", "near_max", true},
    {Reduce::Count, "count", "near_count", false},
};

constexpr const ReduceInfo& reduceInfo(Reduce r) {
    for (const ReduceInfo& info : kReduces)
        if (info.reduce == r) return info;
    return kReduces[0];
}
constexpr std::optional<Reduce> reduceFromName(std::string_view name) {
    for (const ReduceInfo& info : kReduces)
        if (info.name == name) return info.reduce;
    return std::nullopt;
}
// The fold a built-in of .psys names (`near_max`), if it is one.
constexpr std::optional<Reduce> neighbourFold(std::string_view builtin) {
    for (const ReduceInfo& info : kReduces)
        if (info.builtin == builtin) return info.reduce;
    return std::nullopt;
}
// Over no neighbours: 0 for a sum and a count, the largest float for a min, the lowest
// for a max (so that the first term replaces it).
constexpr float emptyFold(Reduce r) {
    if (r == Reduce::Min) return std::numeric_limits<float>::max();
    if (r == Reduce::Max) return std::numeric_limits<float>::lowest();
    return 0.0f;
}
// One step of the fold: the accumulator and a neighbour's term (a count's term is 1).
constexpr float combine(Reduce r, float acc, float term) {
    switch (r) {
        case Reduce::Min: return term < acc ? term : acc;
        case Reduce::Max: return term > acc ? term : acc;
        default: return acc + term;
    }
}

}  // namespace psys::core
