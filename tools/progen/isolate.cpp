#include "tools/progen/isolate.h"

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>

namespace psys::progen {

namespace {

// The finding as one line for the pipe: config \t kind \t frame \t detail (tabs and
// newlines in the detail made spaces).
std::string encode(const std::optional<Finding>& f) {
    if (!f) return "ok";
    std::string detail = f->detail;
    for (char& ch : detail)
        if (ch == '\t' || ch == '\n') ch = ' ';
    return fmt::format("{}\t{}\t{}\t{}", f->config, f->kind, f->frame, detail);
}

std::optional<Finding> decode(const std::string& s) {
    if (s == "ok") return std::nullopt;
    Finding f;
    std::istringstream in(s);
    std::string frame;
    std::getline(in, f.config, '\t');
    std::getline(in, f.kind, '\t');
    std::getline(in, frame, '\t');
    std::getline(in, f.detail);
    try {
        f.frame = std::stoi(frame);
    } catch (const std::exception&) {
        f.frame = -1;
    }
    return f;
}

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) out.push_back(line);
    return out;
}

std::string join(const std::vector<std::string>& lines) {
    std::string out;
    for (const std::string& l : lines) out += l + "\n";
    return out;
}

// The line closing the block line `open` opens (braces counted), or `open` if none does.
size_t blockEnd(const std::vector<std::string>& lines, size_t open) {
    int depth = 0;
    for (size_t i = open; i < lines.size(); ++i) {
        for (char ch : lines[i]) depth += ch == '{' ? 1 : ch == '}' ? -1 : 0;
        if (depth == 0) return i;
    }
    return open;
}

bool same(const std::optional<Finding>& f, const Finding& target) {
    return f && f->config == target.config && f->kind == target.kind;
}

}  // namespace

std::optional<Finding> runIsolated(const Case& c, const RunOptions& options, unsigned seconds) {
    int fds[2];
    if (pipe(fds) != 0) return Finding{"-", "error", -1, std::string("pipe: ") + std::strerror(errno)};
    pid_t pid = fork();
    if (pid < 0) return Finding{"-", "error", -1, std::string("fork: ") + std::strerror(errno)};
    if (pid == 0) {
        close(fds[0]);
        alarm(seconds);
        std::string out;
        try {
            out = encode(runCase(c, options));
        } catch (const std::exception& e) {
            out = encode(Finding{"-", "exception", -1, e.what()});
        }
        out += "\n";
        ssize_t written = write(fds[1], out.data(), out.size());
        _exit(written == static_cast<ssize_t>(out.size()) ? 0 : 3);
    }
    close(fds[1]);
    std::string got;
    char buffer[4096];
    ssize_t n;
    while ((n = read(fds[0], buffer, sizeof buffer)) > 0) got.append(buffer, static_cast<size_t>(n));
    close(fds[0]);
    int status = 0;
    waitpid(pid, &status, 0);
    if (WIFSIGNALED(status)) {
        int sig = WTERMSIG(status);
        if (sig == SIGALRM) return Finding{"-", "timeout", -1, fmt::format("no answer in {} s", seconds)};
        return Finding{"-", "crash", -1, fmt::format("signal {} ({})", sig, strsignal(sig))};
    }
    if (!got.empty() && got.back() == '\n') got.pop_back();
    if (got.empty()) return Finding{"-", "crash", -1, fmt::format("exit {} without an answer", WEXITSTATUS(status))};
    return decode(got);
}

Finding attributeCrash(const Case& c, const RunOptions& options, const Finding& crash, unsigned seconds) {
    RunOptions one = options;
    one.configs = {options.configs.front()};
    auto alone = runIsolated(c, one, seconds);
    if (alone && (alone->kind == "crash" || alone->kind == "timeout")) {
        Finding f = *alone;
        f.config = options.configs.front().label;
        return f;
    }
    for (size_t i = 1; i < options.configs.size(); ++i) {
        one.configs = {options.configs.front(), options.configs[i]};
        auto pair = runIsolated(c, one, seconds);
        if (pair && (pair->kind == "crash" || pair->kind == "timeout")) {
            Finding f = *pair;
            f.config = options.configs[i].label;
            return f;
        }
    }
    return crash;  // only all of them together
}

Case shrink(const Case& c, const RunOptions& options, const Finding& found, unsigned seconds, int budget) {
    Case best = c;
    int runs = 0;
    auto fails = [&](const Case& candidate) {
        if (runs >= budget) return false;
        ++runs;
        auto f = runIsolated(candidate, options, seconds);
        if (f && f->kind == "crash" && found.kind == "crash") return true;
        return same(f, found);
    };
    // Frames past the one that showed it (rows are compared every tenth: keep to the next).
    if (found.frame >= 0 && found.frame + 1 < best.frames) {
        Case shorter = best;
        shorter.frames = std::min(best.frames, (found.frame / 10 + 1) * 10);
        std::erase_if(shorter.events, [&](const Event& e) { return e.frame >= shorter.frames; });
        if (std::none_of(shorter.events.begin(), shorter.events.end(),
                         [](const Event& e) { return e.kind == Event::Kind::Reload; }))
            shorter.edit.clear();
        if (fails(shorter)) best = shorter;
    }
    bool changed = true;
    while (changed && runs < budget) {
        changed = false;
        for (size_t i = best.events.size(); i-- > 0;) {
            Case fewer = best;
            fewer.events.erase(fewer.events.begin() + static_cast<std::ptrdiff_t>(i));
            if (best.events[i].kind == Event::Kind::Reload) fewer.edit.clear();
            if (fails(fewer)) {
                best = fewer;
                changed = true;
            }
        }
        std::vector<std::string> source = lines(best.source);
        // Lines i to end of the source, with the same run of lines in the edit.
        auto tryRemoving = [&](size_t i, size_t end) {
            std::vector<std::string> s = source, e = lines(best.edit);
            auto first = s.begin() + static_cast<std::ptrdiff_t>(i), last = s.begin() + static_cast<std::ptrdiff_t>(end) + 1;
            auto inEdit = std::search(e.begin(), e.end(), first, last);
            if (inEdit != e.end()) e.erase(inEdit, inEdit + (last - first));
            s.erase(first, last);
            Case fewer = best;
            fewer.source = join(s);
            if (!best.edit.empty()) fewer.edit = join(e);
            if (!fails(fewer)) return;
            best = fewer;
            source = s;
            changed = true;
        };
        // Whole blocks (a nested object, from its line to its closing brace), then lines.
        for (size_t i = source.size(); i-- > 0 && runs < budget;) {
            if (source[i].empty() || source[i].back() != '{') continue;
            size_t end = blockEnd(source, i);
            if (end != i) tryRemoving(i, end);
        }
        for (size_t i = source.size(); i-- > 0 && runs < budget;)
            if (!source[i].empty()) tryRemoving(i, i);
        // Lines only the edit has.
        std::vector<std::string> edit = lines(best.edit);
        for (size_t i = edit.size(); i-- > 0 && runs < budget;) {
            if (std::find(source.begin(), source.end(), edit[i]) != source.end()) continue;
            Case fewer = best;
            std::vector<std::string> e = edit;
            e.erase(e.begin() + static_cast<std::ptrdiff_t>(i));
            fewer.edit = join(e);
            if (fails(fewer)) {
                best = fewer;
                edit = e;
                changed = true;
            }
        }
    }
    return best;
}

}  // namespace psys::progen
