#include "script.h"

#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>

#include "host/settings.h"
#include "image_file.h"
#include "keys.h"

namespace psys::viewer {
namespace {

// A finite number, the whole word.
std::optional<float> finite(const std::string& word) {
    char* end = nullptr;
    errno = 0;
    float v = std::strtof(word.c_str(), &end);
    if (word.empty() || *end != '\0' || errno == ERANGE || !std::isfinite(v)) return std::nullopt;
    return v;
}

// What is wrong with an action's arguments (their count checked), or "".
std::string problem(ScriptAction& a) {
    if (a.verb == "orbit" || a.verb == "pan" || a.verb == "zoom") {
        for (const std::string& w : a.words) {
            auto v = finite(w);
            if (!v) return "`" + a.verb + "` takes finite numbers, not `" + w + "`";
            a.numbers.push_back(*v);
        }
    } else if (a.verb == "key") {
        if (!keyPress(a.words[0])) return "unknown key `" + a.words[0] + "` (" + keyNames() + ")";
    } else if (a.verb == "set") {
        if (auto s = host::parseSet(a.words[0]); !s) return s.error;
    } else if (a.verb == "fire") {
        if (auto f = host::parseFire(a.words[0] + "@1"); !f) return f.error;
    } else if (a.verb == "screenshot") {
        if (auto p = imageFormatProblem(a.words[0])) return "cannot write `" + a.words[0] + "`: " + *p;
    }
    return "";
}

}  // namespace

std::optional<Script> Script::parse(const std::string& text, const std::string& file, std::string& error) {
    static const std::set<std::string> verbs = {"orbit", "pan", "zoom", "key", "set", "fire", "screenshot", "quit"};
    Script script;
    std::istringstream in(text);
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        auto fail = [&](const std::string& why) {
            error = file + ":" + std::to_string(number) + ": " + why;
            return std::nullopt;
        };
        if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
        std::istringstream words(line);
        std::string first;
        if (!(words >> first)) continue;
        ScriptAction action;
        char* end = nullptr;
        errno = 0;
        long long frame = std::strtoll(first.c_str(), &end, 10);
        if (*end != '\0' || frame < 1 || frame > INT_MAX || errno == ERANGE)
            return fail("a line starts with the frame number (1 to " + std::to_string(INT_MAX) + "), not `" + first + "`");
        action.frame = static_cast<int>(frame);
        if (!(words >> action.verb) || !verbs.count(action.verb))
            return fail("the actions are orbit, pan, zoom, key, set, fire, screenshot and quit");
        for (std::string w; words >> w;) action.words.push_back(w);
        size_t wanted = action.verb == "orbit" || action.verb == "pan" ? 2 : action.verb == "quit" ? 0 : 1;
        if (action.words.size() != wanted)
            return fail("`" + action.verb + "` takes " + std::to_string(wanted) + " argument" + (wanted == 1 ? "" : "s"));
        if (std::string why = problem(action); !why.empty()) return fail(why);
        script.actions.push_back(std::move(action));
    }
    return script;
}

}  // namespace psys::viewer
