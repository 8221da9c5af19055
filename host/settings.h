// What a host sets on a running system, as people write it on a command line or in a
// config: numbers ("0.5", "1/60", "1e-3"), extern settings (NAME=V[,V…]) and triggers to
// fire (TRIGGER[:V,…]@FRAME). Parsed in one place for psysc, the viewer and the
// benchmarks; the messages say what was expected.
#pragma once

#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace psys::host {

// A value or the message saying why there is none.
template <typename T>
struct Parsed {
    std::optional<T> value;
    std::string error;
    explicit operator bool() const { return value.has_value(); }
    const T& operator*() const { return *value; }
    const T* operator->() const { return &*value; }
    static Parsed fail(std::string message) { return {std::nullopt, std::move(message)}; }
};

// "0.5", "1/60", "1e-3".
std::optional<double> parseNumber(const std::string& text);
// "1,2,3" (an empty text is no numbers).
std::optional<std::vector<float>> parseNumbers(const std::string& text);

struct ExternSetting {
    std::string name;
    std::vector<float> values;
    bool words = false;  // a value was written `true` or `false` (a bool's only)
};
// NAME=VALUE or NAME=X,Y,Z
Parsed<ExternSetting> parseSet(const std::string& text);

struct TriggerFiring {
    std::string trigger;
    std::vector<float> args;
    int frame = 0;  // fired before this frame's step (frames count from 1)
};
// TRIGGER@FRAME or TRIGGER:X,Y,Z@FRAME
Parsed<TriggerFiring> parseFire(const std::string& text);

// A step length: a finite, non-negative number of seconds ("1/60").
Parsed<double> parseStep(const std::string& text);

}  // namespace psys::host
