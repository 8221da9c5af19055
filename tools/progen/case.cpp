#include "tools/progen/case.h"

#include <algorithm>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace psys::progen {

namespace {

constexpr const char* kMark = "//! ";

std::string readText(const std::filesystem::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// Varied steps: from 1/240 s to 1/20 s, a function of the case's seed and the frame only.
double variedStep(uint64_t seed, int frame) {
    uint64_t x = seed * 0x9E3779B97F4A7C15ull + static_cast<uint64_t>(frame) * 0xBF58476D1CE4E5B9ull + 1;
    x ^= x >> 31;
    x *= 0x94D049BB133111EBull;
    x ^= x >> 29;
    double u = static_cast<double>(x >> 11) / 9007199254740992.0;
    return 1.0 / 240 + u * (1.0 / 20 - 1.0 / 240);
}

}  // namespace

double Case::stepAt(int f) const { return dt > 0 ? dt : variedStep(seed, f); }

bool Case::paces() const {
    return std::any_of(events.begin(), events.end(),
                       [](const Event& e) { return e.kind == Event::Kind::Speed || e.kind == Event::Kind::Pause; });
}

std::string caseText(const Case& c) {
    std::string out = fmt::format("{}frames {}\n", kMark, c.frames);
    if (c.dt > 0) out += fmt::format("{}dt {}\n", kMark, c.dt);
    else out += fmt::format("{}dt varied {}\n", kMark, c.seed);
    if (c.compareFast) out += fmt::format("{}compare fast\n", kMark);
    for (const Event& e : c.events) {
        switch (e.kind) {
            case Event::Kind::Fire: out += fmt::format("{}fire {}", kMark, e.name); break;
            case Event::Kind::Set: out += fmt::format("{}set {}", kMark, e.name); break;
            case Event::Kind::Reload: out += fmt::format("{}reload", kMark); break;
            case Event::Kind::Play: out += fmt::format("{}play", kMark); break;
            case Event::Kind::Stop: out += fmt::format("{}stop", kMark); break;
            case Event::Kind::Kill: out += fmt::format("{}kill", kMark); break;
            case Event::Kind::Speed: out += fmt::format("{}speed", kMark); break;
            case Event::Kind::Pause: out += fmt::format("{}pause", kMark); break;
        }
        for (float v : e.values) out += fmt::format(" {}", v);
        out += fmt::format(" @{}\n", e.frame);
    }
    return out + c.source;
}

std::optional<Case> parseCase(const std::string& text, const std::string& edit, std::string& error) {
    Case c;
    c.edit = edit;
    std::istringstream in(text);
    std::string line;
    int number = 0;
    while (std::getline(in, line)) {
        ++number;
        if (line.rfind(kMark, 0) != 0) {
            c.source += line + "\n";
            continue;
        }
        std::istringstream words(line.substr(4));
        std::string word;
        words >> word;
        auto fail = [&](const std::string& why) {
            error = fmt::format("line {}: {}: `{}`", number, why, line);
            return std::nullopt;
        };
        if (word == "frames") {
            if (!(words >> c.frames) || c.frames < 0) return fail("a number of frames");
        } else if (word == "dt") {
            std::string v;
            words >> v;
            if (v == "varied") {
                c.dt = 0;
                if (!(words >> c.seed)) return fail("`dt varied SEED`");
            } else {
                try {
                    c.dt = std::stod(v);
                } catch (const std::exception&) {
                    return fail("a step in seconds");
                }
            }
        } else if (word == "compare") {
            std::string what;
            if (!(words >> what) || what != "fast") return fail("`compare fast`");
            c.compareFast = true;
        } else if (word == "fire" || word == "set" || word == "reload" || word == "play" || word == "stop" ||
                   word == "kill" || word == "speed" || word == "pause") {
            Event e;
            e.kind = word == "fire"    ? Event::Kind::Fire
                     : word == "set"   ? Event::Kind::Set
                     : word == "play"  ? Event::Kind::Play
                     : word == "stop"  ? Event::Kind::Stop
                     : word == "kill"  ? Event::Kind::Kill
                     : word == "speed" ? Event::Kind::Speed
                     : word == "pause" ? Event::Kind::Pause
                                       : Event::Kind::Reload;
            if (e.kind == Event::Kind::Fire || e.kind == Event::Kind::Set) words >> e.name;
            std::string w;
            bool at = false;
            while (words >> w) {
                if (w[0] == '@') {
                    try {
                        e.frame = std::stoi(w.substr(1));
                    } catch (const std::exception&) {
                        return fail("a frame");
                    }
                    at = true;
                    break;
                }
                try {
                    e.values.push_back(std::stof(w));
                } catch (const std::exception&) {
                    return fail("a number");
                }
            }
            if (!at) return fail("an event needs its frame, @N");
            if (e.kind == Event::Kind::Reload && edit.empty()) return fail("a reload needs the case's .edit.psys");
            if (e.kind == Event::Kind::Play && e.values.size() != 3) return fail("a play takes a translation, X Y Z");
            if ((e.kind == Event::Kind::Stop || e.kind == Event::Kind::Kill) && e.values.size() != 1)
                return fail("which instance the case played, from 0");
            if ((e.kind == Event::Kind::Speed || e.kind == Event::Kind::Pause) && e.values.size() != 2)
                return fail("which instance the case played, from 0, and its speed (pause: 1 or 0)");
            c.events.push_back(e);
        } else {
            return fail("unknown directive");
        }
    }
    return c;
}

bool writeCase(const Case& c, const std::string& dir, const std::string& name) {
    std::filesystem::create_directories(dir);
    std::ofstream out(std::filesystem::path(dir) / (name + ".psys"));
    out << caseText(c);
    if (!c.edit.empty()) {
        std::ofstream e(std::filesystem::path(dir) / (name + ".edit.psys"));
        e << c.edit;
        if (!e) return false;
    }
    return static_cast<bool>(out);
}

std::optional<Case> readCase(const std::string& path, std::string& error) {
    std::filesystem::path p(path);
    if (!std::filesystem::exists(p)) {
        error = "no such file";
        return std::nullopt;
    }
    std::filesystem::path editPath = p.parent_path() / (p.stem().string() + ".edit.psys");
    std::string edit = std::filesystem::exists(editPath) ? readText(editPath) : "";
    return parseCase(readText(p), edit, error);
}

}  // namespace psys::progen
