#include "host/settings.h"

#include <cmath>
#include <cstdlib>

namespace psys::host {

std::optional<double> parseNumber(const std::string& text) {
    auto slash = text.rfind('/');  // the last: 1/60/2 is (1/60)/2
    if (slash != std::string::npos) {
        auto a = parseNumber(text.substr(0, slash)), b = parseNumber(text.substr(slash + 1));
        if (!a || !b) return std::nullopt;
        return *a / *b;
    }
    char* end = nullptr;
    double v = std::strtod(text.c_str(), &end);
    if (text.empty() || *end != '\0') return std::nullopt;
    return v;
}

namespace {

// Without the spaces around it: `k = 1`, `k=1 ` and `1, 2` read as written without them.
std::string trimmed(const std::string& text) {
    size_t begin = text.find_first_not_of(" \t"), end = text.find_last_not_of(" \t");
    return begin == std::string::npos ? "" : text.substr(begin, end - begin + 1);
}

}  // namespace

std::optional<std::vector<float>> parseNumbers(const std::string& text) {
    std::vector<float> out;
    if (text.empty()) return out;
    size_t start = 0;
    while (start <= text.size()) {
        size_t comma = text.find(',', start);
        std::string item = trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        // A bool extern's values: true and false (or 1 and 0).
        auto v = item == "true" ? 1.0 : item == "false" ? 0.0 : parseNumber(item);
        if (!v) return std::nullopt;
        out.push_back(static_cast<float>(*v));
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return out;
}

Parsed<ExternSetting> parseSet(const std::string& text) {
    auto eq = text.find('=');
    auto values = eq == std::string::npos ? std::nullopt : parseNumbers(text.substr(eq + 1));
    std::string name = eq == std::string::npos ? "" : trimmed(text.substr(0, eq));
    if (!values || values->empty() || name.empty())
        return Parsed<ExternSetting>::fail("--set takes NAME=VALUE or NAME=X,Y,Z, not `" + text + "`");
    bool words = false;
    for (size_t start = eq + 1; start <= text.size();) {
        size_t comma = text.find(',', start);
        std::string item = trimmed(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        words |= item == "true" || item == "false";
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return {ExternSetting{name, *values, words}, {}};
}

Parsed<TriggerFiring> parseFire(const std::string& text) {
    auto at = text.rfind('@');
    auto colon = text.find(':');
    double frame = -1;
    if (at != std::string::npos)
        if (auto n = parseNumber(text.substr(at + 1))) frame = *n;
    std::optional<std::vector<float>> args = std::vector<float>{};
    if (colon != std::string::npos && colon < at) args = parseNumbers(text.substr(colon + 1, at - colon - 1));
    if (frame < 1 || !args || !std::isfinite(frame) || frame > 2e9 || frame != std::floor(frame))
        return Parsed<TriggerFiring>::fail("--fire takes TRIGGER@FRAME or TRIGGER:X,Y,Z@FRAME with FRAME a whole number "
                                           "from 1, not `" + text + "`");
    return {TriggerFiring{text.substr(0, std::min(colon, at)), *args, static_cast<int>(frame)}, {}};
}

Parsed<double> parseStep(const std::string& text) {
    auto dt = parseNumber(text);
    if (!dt || !std::isfinite(*dt) || *dt < 0)
        return Parsed<double>::fail("--dt takes a number of seconds, finite and not negative (such as 0.016 or 1/60), not `" +
                                    text + "`");
    return {*dt, {}};
}

}  // namespace psys::host
