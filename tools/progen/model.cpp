// The generator's model printed as a program (tools/progen/model.h).
#include "tools/progen/model.h"

#include <fmt/format.h>

namespace psys::progen {

std::string num(double v) {
    std::string s = fmt::format("{:.3f}", v);
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
    return s == "-0" ? "0" : s;
}

namespace {

std::string emitText(const Emit& e, const std::vector<Type>& types) {
    const Type& t = types[static_cast<size_t>(e.target)];
    std::string call = t.name;
    if (!e.args.empty()) {
        call += "(";
        for (size_t i = 0; i < e.args.size(); ++i) call += (i ? ", " : "") + e.args[i];
        call += ")";
    }
    switch (e.kind) {
        case Emit::Rate: return fmt::format("emit {} at {} per second;", call, e.rate);
        case Emit::RateCount: return fmt::format("emit {} at {} per second count {};", call, e.rate, e.count);
        case Emit::Burst: return fmt::format("emit {} count {};", call, e.count);
        case Emit::When: return fmt::format("when {} {{ emit {} count {}; }}", e.cond, call, e.count);
        case Emit::Death: return fmt::format("on death {{ emit {} count {}; }}", call, e.count);
    }
    return "";
}

std::string paramList(const std::vector<Param>& params) {
    if (params.empty()) return "";
    std::string out = "(";
    for (size_t i = 0; i < params.size(); ++i)
        out += fmt::format("{}{}: {}", i ? ", " : "", params[i].name, params[i].ty == Ty::Vec3 ? "vec3" : "float");
    return out + ")";
}

void printType(const Model& m, int index, int indent, std::string& out) {
    const Type& t = m.types[static_cast<size_t>(index)];
    if (t.removed) return;
    std::string pad(static_cast<size_t>(indent), ' '), in(static_cast<size_t>(indent + 4), ' ');
    if (!t.attrs.empty()) {
        out += pad;
        for (size_t i = 0; i < t.attrs.size(); ++i) out += (i ? " " : "") + t.attrs[i];
        out += "\n";
    }
    out += fmt::format("{}object {}{} {{\n", pad, t.name, paramList(t.params));
    bool dies = !t.kills.empty() || !t.whenKill.empty();
    for (const Emit& e : t.emits)  // `on death` at the top of the body
        if (e.kind == Emit::Death && dies) out += in + emitText(e, m.types) + "\n";
    for (const std::string& e : t.equations) out += in + e + "\n";
    if (!t.draw.empty()) out += in + t.draw + "\n";
    for (const std::string& k : t.kills) out += fmt::format("{}kill when {};\n", in, k);
    if (!t.whenKill.empty()) out += fmt::format("{}when {} {{ kill; }}\n", in, t.whenKill);
    for (const Emit& e : t.emits)
        if (e.kind != Emit::Death) out += in + emitText(e, m.types) + "\n";
    for (const std::string& n : t.notifies) out += in + n + "\n";
    if (dies)
        for (const std::string& n : t.deathNotifies) out += fmt::format("{}on death {{ {} }}\n", in, n);
    for (int c : t.children) printType(m, c, indent + 4, out);
    out += pad + "}\n";
}

}  // namespace

std::string print(const Model& m) {
    std::string out;
    if (!m.fileAttr.empty()) out += m.fileAttr + "\n";
    for (const Extern& e : m.externs) {
        if (e.ty == Ty::Float)
            out += fmt::format("extern {}: float = {} range({}, {});\n", e.name, num(e.def), num(e.lo), num(e.hi));
        else
            out += fmt::format("extern {}: vec3 = vec3({}) range({}, {});\n", e.name, num(e.def), num(e.lo), num(e.hi));
    }
    for (size_t i = 0; i < m.types.size(); ++i)
        if (m.types[i].parent < 0) printType(m, static_cast<int>(i), 0, out);
    for (const Trigger& tr : m.triggers) {
        out += fmt::format("trigger {}{} {{", tr.name, paramList(tr.params).empty() ? "" : paramList(tr.params));
        for (const Emit& e : tr.emits) out += " " + emitText(e, m.types);
        out += " }\n";
    }
    for (const auto& [type, args] : m.spawns) {
        out += "spawn " + m.types[static_cast<size_t>(type)].name;
        if (!args.empty()) {
            out += "(";
            for (size_t i = 0; i < args.size(); ++i) out += (i ? ", " : "") + args[i];
            out += ")";
        }
        out += ";\n";
    }
    return out;
}

}  // namespace psys::progen
