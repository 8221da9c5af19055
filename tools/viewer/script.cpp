#include "script.h"

#include <cstdlib>
#include <set>
#include <sstream>

namespace psys::viewer {

std::optional<Script> Script::parse(const std::string& text, std::string& error) {
    static const std::set<std::string> verbs = {"orbit", "pan", "zoom", "key", "set", "fire", "screenshot", "quit"};
    Script script;
    std::istringstream in(text);
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        if (auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
        std::istringstream words(line);
        std::string first;
        if (!(words >> first)) continue;
        ScriptAction action;
        char* end = nullptr;
        long frame = std::strtol(first.c_str(), &end, 10);
        if (*end != '\0' || frame < 1) {
            error = "line " + std::to_string(number) + ": a line starts with the frame number (from 1), not `" + first + "`";
            return std::nullopt;
        }
        action.frame = static_cast<int>(frame);
        if (!(words >> action.verb) || !verbs.count(action.verb)) {
            error = "line " + std::to_string(number) + ": the actions are orbit, pan, zoom, key, set, fire, screenshot "
                    "and quit";
            return std::nullopt;
        }
        for (std::string w; words >> w;) action.words.push_back(w);
        size_t wanted = action.verb == "orbit" || action.verb == "pan" ? 2 : action.verb == "quit" ? 0 : 1;
        if (action.words.size() != wanted) {
            error = "line " + std::to_string(number) + ": `" + action.verb + "` takes " + std::to_string(wanted) +
                    " argument" + (wanted == 1 ? "" : "s");
            return std::nullopt;
        }
        script.actions.push_back(std::move(action));
    }
    return script;
}

}  // namespace psys::viewer
