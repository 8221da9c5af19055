#include "ir/parser.h"

#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "ir/printer.h"

namespace psys::ir {
namespace {

struct ParseError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

std::vector<std::string> words(const std::string& line) {
    std::vector<std::string> out;
    std::istringstream in(line);
    std::string w;
    while (in >> w) out.push_back(w);
    return out;
}

float number(const std::string& text) {
    char* end = nullptr;
    float v = std::strtof(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0') throw ParseError("expected a number, found `" + text + "`");
    return v;
}

int integer(const std::string& text) {
    char* end = nullptr;
    long v = std::strtol(text.c_str(), &end, 10);
    if (end == text.c_str() || *end != '\0') throw ParseError("expected an integer, found `" + text + "`");
    return static_cast<int>(v);
}

Type type(const std::string& text) {
    auto t = Type::parse(text);
    if (!t) throw ParseError("unknown type `" + text + "`");
    return *t;
}

// "name: type, name: type" inside the parentheses of a header.
std::vector<Param> params(const std::string& header) {
    std::vector<Param> out;
    auto open = header.find('('), close = header.rfind(')');
    if (open == std::string::npos || close == std::string::npos) throw ParseError("expected (parameters)");
    std::string inside = header.substr(open + 1, close - open - 1);
    std::istringstream in(inside);
    std::string item;
    while (std::getline(in, item, ',')) {
        auto colon = item.find(':');
        if (colon == std::string::npos) throw ParseError("expected `name: type`");
        auto trim = [](std::string s) {
            s.erase(0, s.find_first_not_of(' '));
            s.erase(s.find_last_not_of(' ') + 1);
            return s;
        };
        std::string typeText = trim(item.substr(colon + 1));
        bool once = typeText.ends_with(" once");
        if (once) typeText = trim(typeText.substr(0, typeText.size() - 5));
        std::string spelling;  // `vec3 as point`
        if (auto as = typeText.find(" as "); as != std::string::npos) {
            spelling = trim(typeText.substr(as + 4));
            typeText = trim(typeText.substr(0, as));
        }
        out.push_back({trim(item.substr(0, colon)), type(typeText), !once, spelling});
    }
    return out;
}

int hashIndex(const std::string& t) {
    if (t.size() < 2 || t[0] != '#') throw ParseError("expected `#n`, found `" + t + "`");
    return integer(t.substr(1));
}

std::string nameBeforeParen(const std::string& header, size_t skip) {
    return header.substr(skip, header.find('(') - skip);
}

std::optional<YieldKind> yieldKind(const std::string& name) {
    for (YieldKind k : {YieldKind::StateNext, YieldKind::Kill, YieldKind::Visible, YieldKind::Position,
                        YieldKind::Color, YieldKind::Size, YieldKind::Rotation, YieldKind::Frame, YieldKind::End,
                        YieldKind::Trail, YieldKind::EmitRate, YieldKind::EmitCount,
                        YieldKind::EmitArg, YieldKind::Export, YieldKind::Uniform, YieldKind::Unstable,
                        YieldKind::Fold})
        if (yieldKindName(k) == name) return k;
    return std::nullopt;
}

std::optional<KernelKind> kernelKind(const std::string& name) {
    for (KernelKind k : {KernelKind::Behaviour, KernelKind::Init, KernelKind::Update, KernelKind::Render,
                         KernelKind::Exports, KernelKind::Spawn, KernelKind::Trigger, KernelKind::Start, KernelKind::Pair,
                         KernelKind::UniformUpdate, KernelKind::UniformRender, KernelKind::UniformExports})
        if (name == kernelName(k)) return k;
    return std::nullopt;
}

ValueId valueRef(const std::string& text) {
    if (text.empty() || text[0] != '%') throw ParseError("expected a value `%n`, found `" + text + "`");
    return static_cast<ValueId>(integer(text.substr(1)));
}

class Parser {
public:
    explicit Parser(const std::string& text) {
        std::istringstream in(text);
        std::string line;
        while (std::getline(in, line)) lines_.push_back(line);
    }

    Module run() {
        Module m;
        for (; pos_ < lines_.size(); ++pos_) {
            std::string line = current();
            auto w = words(line);
            if (w.empty()) continue;
            if (w[0] == "extern") m.externs.push_back(externDecl(line));
            else if (w[0] == "object") m.objects.push_back(object(line));
            else if (w[0] == "trigger") {
                Trigger t;
                t.name = nameBeforeParen(trimmed(line), 8);
                t.params = params(line);
                triggerBody(t);
                m.triggers.push_back(std::move(t));
            } else if (w[0] == "start" || w[0].starts_with("start(")) {
                m.start.name = "start";
                if (line.find('(') != std::string::npos) m.start.params = params(line);
                triggerBody(m.start);
            } else {
                throw ParseError("expected extern, object, trigger or start, found `" + w[0] + "`");
            }
        }
        return m;
    }

    size_t lineNumber() const { return pos_ + 1; }

private:
    std::string current() const { return lines_.at(pos_); }
    static std::string trimmed(std::string s) {
        s.erase(0, s.find_first_not_of(' '));
        return s;
    }

    Extern externDecl(const std::string& line) {
        // extern NAME: TYPE = v… [range lo… to hi…]
        auto w = words(line);
        if (w.size() < 4 || w[1].back() != ':' || w[3] != "=") throw ParseError("expected `extern name: type = value`");
        Extern e;
        e.name = w[1].substr(0, w[1].size() - 1);
        e.type = type(w[2]);
        size_t i = 4;
        for (int c = 0; c < e.type.width; ++c) e.defaultValue[static_cast<size_t>(c)] = number(w.at(i++));
        if (i + 1 < w.size() && w[w.size() - 2] == "as") {
            e.spelling = w.back();
            w.resize(w.size() - 2);
        }
        if (i < w.size()) {
            if (w[i] != "range") throw ParseError("expected `range`");
            ++i;
            std::array<float, 4> lo{}, hi{};
            for (int c = 0; c < e.type.width; ++c) lo[static_cast<size_t>(c)] = number(w.at(i++));
            if (w.at(i++) != "to") throw ParseError("expected `to`");
            for (int c = 0; c < e.type.width; ++c) hi[static_cast<size_t>(c)] = number(w.at(i++));
            e.low = lo;
            e.high = hi;
        }
        return e;
    }

    Object object(const std::string& header) {
        Object o;
        o.name = nameBeforeParen(trimmed(header), 7);
        o.params = params(header);
        for (++pos_; pos_ < lines_.size(); ++pos_) {
            auto w = words(current());
            if (w.empty()) continue;
            if (w[0] == "end") {
                // A storage record prints only what is not a column: every emit column is there.
                for (Kernel& k : o.kernels)
                    if (k.storage.fixed && k.storage.emits.size() <= 2 * o.emits.size())
                        k.storage.emits.resize(2 * o.emits.size());
                return o;
            }
            if (w[0] == "parent") o.parent = w.at(1);
            else if (w[0] == "attribute") attribute(o.attributes, w);
            else if (w[0] == "draw") {
                // draw point|sprite|streak, or draw trail POINTS
                auto draw = w.size() >= 2 ? core::drawKindFromName(w[1]) : std::nullopt;
                bool trail = draw == core::DrawKind::Trail;
                if (!draw || w.size() != (trail ? 3u : 2u))
                    throw ParseError("expected `draw point|sprite|streak` or `draw trail POINTS`");
                o.draw = *draw;
                if (trail) o.trail = integer(w[2]);
                if (trail && (o.trail < 2 || o.trail > core::kMaxTrail))
                    throw ParseError(fmt::format("a trail has 2 to {} points, not {}", core::kMaxTrail, o.trail));
            }
            else if (w[0] == "state") {
                if (w.size() != 4 || w[1].back() != ':') throw ParseError("expected `state name: type zero|next`");
                StateInit init = w[3] == "zero" ? StateInit::Zero : w[3] == "next" ? StateInit::Next
                                 : throw ParseError("a state starts `zero` or `next`");
                o.state.push_back({w[1].substr(0, w[1].size() - 1), type(w[2]), init});
            } else if (w[0] == "emit") {
                o.emits.push_back(emitSite(w));
            } else if (w[0] == "export") {
                if (w.size() != 3 || w[1].back() != ':') throw ParseError("expected `export name: type`");
                o.exports.push_back({w[1].substr(0, w[1].size() - 1), type(w[2])});
            } else if (w[0] == "read") {
                if (w.size() != 4 || w[1].back() != ':' || w[3][0] != '^') throw ParseError("expected `read name: type ^depth`");
                o.parentReads.push_back({integer(w[3].substr(1)), w[1].substr(0, w[1].size() - 1), type(w[2])});
            } else if (w[0] == "near") {
                // near TARGET RADIUS [position #SELF #OTHER]
                if (w.size() != 3 && !(w.size() == 6 && w[3] == "position"))
                    throw ParseError("expected `near type radius [position #self #other]`");
                NeighbourGroup g{w[1], number(w[2])};
                if (w.size() == 6) {
                    g.selfPosition = hashIndex(w[4]);
                    g.otherPosition = hashIndex(w[5]);
                }
                o.neighbours.push_back(g);
            } else if (w[0] == "fold") {
                auto reduce = w.size() == 4 && w[1].back() == ':' ? core::reduceFromName(w[1].substr(0, w[1].size() - 1))
                                                                  : std::nullopt;
                if (!reduce) throw ParseError("expected `fold sum|min|max|count: type #group`");
                o.folds.push_back({hashIndex(w[3]), *reduce, type(w[2])});
            } else if (w[0] == "near.read") {
                if (w.size() != 4 || w[1].back() != ':' || (w[3] != "self" && w[3] != "other"))
                    throw ParseError("expected `near.read name: type self|other`");
                o.neighbourReads.push_back({w[3] == "other", w[1].substr(0, w[1].size() - 1), type(w[2])});
            } else if (w[0] == "kernel") {
                o.kernels.push_back(kernel(w));
            } else {
                throw ParseError("unexpected `" + w[0] + "` in an object");
            }
        }
        throw ParseError("object `" + o.name + "` has no `end`");
    }

    static void attribute(Attributes& a, const std::vector<std::string>& w) {
        if (w.size() >= 5 && w[1] == "texture") {  // attribute texture COLUMNS ROWS PATH…
            a.textureColumns = integer(w[2]);
            a.textureRows = integer(w[3]);
            if (a.textureColumns < 1 || a.textureRows < 1) throw ParseError("a texture has at least one column and row");
            a.texture = w[4];
            for (size_t i = 5; i < w.size(); ++i) a.texture += " " + w[i];
            return;
        }
        if (w.size() == 4 && w[1] == "tolerance") {  // attribute tolerance METRES SECONDS
            a.tolerance = number(w[2]);
            a.toleranceOver = number(w[3]);
            return;
        }
        if (w.size() != 3) throw ParseError("expected `attribute name value`");
        if (w[1] == "integrator") {
            a.integrator = core::integratorFromName(w[2]);
            if (!a.integrator) throw ParseError("unknown integrator `" + w[2] + "`");
        } else if (w[1] == "step") {
            a.step = number(w[2]);
        } else if (w[1] == "precision") {
            auto precision = precisionFromName(w[2]);
            if (!precision) throw ParseError("unknown precision `" + w[2] + "` (float or double)");
            a.precision = *precision;
        } else if (w[1] == "capacity") {
            a.capacity = static_cast<uint64_t>(integer(w[2]));
        } else if (w[1] == "shape") {
            a.shape = core::shapeFromName(w[2]);
            if (!a.shape) throw ParseError("unknown shape `" + w[2] + "`");
        } else if (w[1] == "blend") {
            a.blend = core::blendFromName(w[2]);
            if (!a.blend) throw ParseError("unknown blend `" + w[2] + "`");
        } else {
            throw ParseError("unknown attribute `" + w[1] + "`");
        }
    }

    static EmitSite emitSite(const std::vector<std::string>& w) {
        auto when = w.size() == 3 ? emitWhenFromName(w[2]) : std::nullopt;
        if (!when) throw ParseError("expected `emit object rate|burst|edge|death`");
        return {w[1], *when};
    }

    void triggerBody(Trigger& t) {
        for (++pos_; pos_ < lines_.size(); ++pos_) {
            auto w = words(current());
            if (w.empty()) continue;
            if (w[0] == "end") return;
            if (w[0] == "emit") t.emits.push_back(emitSite(w));
            else if (w[0] == "kernel") t.kernel = kernel(w);
            else throw ParseError("unexpected `" + w[0] + "` in a trigger");
        }
        throw ParseError("a trigger has no `end`");
    }

    Kernel kernel(const std::vector<std::string>& header) {
        Kernel k;
        auto kind = kernelKind(header.at(1));
        if (!kind) throw ParseError("unknown kernel kind `" + header[1] + "`");
        k.kind = *kind;
        if (k.kind == KernelKind::Spawn || k.kind == KernelKind::Pair) k.site = integer(header.at(2).substr(1));
        for (++pos_; pos_ < lines_.size(); ++pos_) {
            std::string line = current();
            auto w = words(line);
            if (w.empty()) continue;
            if (w[0] == "end") {
                for (const Inst& inst : k.insts())
                    for (ValueId v : inst.operands)
                        if (v >= k.size()) throw ParseError(fmt::format("value %{} is not defined", v));
                for (const Yield& y : k.yields)
                    if (y.value >= k.size()) throw ParseError(fmt::format("value %{} is not defined", y.value));
                for (auto& [name, v] : k.equations)
                    if (v >= k.size()) throw ParseError(fmt::format("value %{} is not defined", v));
                k.rehash();
                defaultDrawn(k);
                return k;
            }
            if (w[0] == "yield") k.yields.push_back(yield(w));
            else if (w[0] == "storage") storage(k, w);
            else if (w[0] == "let") {
                if (w.size() != 4 || w[2] != "=") throw ParseError("expected `let name = %v`");
                k.equations[w[1]] = valueRef(w[3]);
            }
            else instruction(k, line);
        }
        throw ParseError("a kernel has no `end`");
    }

    // `storage` (the record is fixed), or one fact of it (printer.cpp's storageText).
    static void storage(Kernel& k, const std::vector<std::string>& w) {
        KernelStorage& st = k.storage;
        st.fixed = true;
        if (w.size() == 1) return;
        auto index = [](const std::string& t) {
            if (t.empty() || t[0] != '#') throw ParseError("expected `#n`, found `" + t + "`");
            return integer(t.substr(1));
        };
        if (w[1] == "emit.rate" || w[1] == "emit.count") {
            // storage emit.rate #site = const V | extern #i | uniform #i
            if (w.size() < 6 || w[3] != "=") throw ParseError("expected `storage emit.rate #site = …`");
            size_t column = static_cast<size_t>(2 * index(w[2]) + (w[1] == "emit.count" ? 1 : 0));
            if (st.emits.size() <= column) st.emits.resize(column + 1);
            KernelStorage::Shared& e = st.emits[column];
            using From = KernelStorage::Shared::From;
            if (w[4] == "const") e = {From::Constant, 0, number(w[5])};
            else if (w[4] == "extern") e = {From::Extern, index(w[5]), 0};
            else if (w[4] == "uniform") e = {From::Uniform, index(w[5]), 0};
            else throw ParseError("expected const, extern or uniform, found `" + w[4] + "`");
        } else if (w[1] == "drawn") {
            // storage drawn position.y = state #slot.lane | const V
            if (w.size() < 6 || w[3] != "=") throw ParseError("expected `storage drawn column = …`");
            int column = 0;
            const int columns = kDrawnColumns + 3 * (core::kMaxTrail - 1);
            while (column < columns && w[2] != drawnColumnName(column)) ++column;
            if (column == columns) throw ParseError("unknown render column `" + w[2] + "`");
            if (st.drawn.size() <= static_cast<size_t>(column))
                st.drawn.resize(std::max(static_cast<size_t>(column) + 1, static_cast<size_t>(kDrawnColumns)));
            KernelStorage::Drawn& d = st.drawn[static_cast<size_t>(column)];
            using From = KernelStorage::Drawn::From;
            if (w[4] == "const") {
                d = {From::Constant, 0, 0, number(w[5])};
            } else if (w[4] == "state") {
                auto dot = w[5].find('.');
                if (dot == std::string::npos) throw ParseError("expected `#slot.lane`, found `" + w[5] + "`");
                d = {From::State, index(w[5].substr(0, dot)), integer(w[5].substr(dot + 1)), 0};
            } else {
                throw ParseError("expected state or const, found `" + w[4] + "`");
            }
        } else if (w[1] == "parent") {
            // storage parent OP #export ^depth width
            if (w.size() != 6 || w[4].empty() || w[4][0] != '^') throw ParseError("expected `storage parent op #e ^d width`");
            auto op = opFromName(w[2]);
            if (!op || !isGathered(*op)) throw ParseError("expected a parent read or a fold, found `" + w[2] + "`");
            st.parents.push_back({*op, integer(w[4].substr(1)), index(w[3]), integer(w[5])});
        } else if (w[1] == "zeroed") {
            // storage zeroed #slot …
            for (size_t i = 2; i < w.size(); ++i) st.zeroed.push_back(index(w[i]));
        } else {
            throw ParseError("unknown storage fact `" + w[1] + "`");
        }
    }

    static Yield yield(const std::vector<std::string>& w) {
        // yield KIND [#index [#sub]] = %v
        Yield y;
        auto kind = yieldKind(w.at(1));
        if (!kind) throw ParseError("unknown yield `" + w[1] + "`");
        y.kind = *kind;
        size_t i = 2;
        if (w.at(i)[0] == '#') y.index = integer(w[i++].substr(1));
        if (w.at(i)[0] == '#') y.sub = integer(w[i++].substr(1));
        if (w.at(i++) != "=") throw ParseError("expected `=` in a yield");
        y.value = valueRef(w.at(i));
        return y;
    }

    void instruction(Kernel& k, std::string line) {
        Inst inst;
        if (auto semi = line.find(';'); semi != std::string::npos) {
            inst.name = trimmed(line.substr(semi + 1));
            line = line.substr(0, semi);
        }
        if (auto at = line.find("loc("); at != std::string::npos) {
            auto close = line.find(')', at);
            if (close == std::string::npos) throw ParseError("expected `)` after a location");
            inst.loc = location(line.substr(at + 4, close - at - 4));
            line.erase(at, close - at + 1);
        }
        if (auto open = line.find('<'); open != std::string::npos) {
            auto close = line.find('>', open);
            if (close == std::string::npos) throw ParseError("expected `>`");
            for (auto& lane : words(line.substr(open + 1, close - open - 1)))
                inst.lanes.push_back(static_cast<uint8_t>(integer(lane)));
            line.erase(open, close - open + 1);
        }
        for (char& c : line)
            if (c == ',') c = ' ';
        auto w = words(line);
        if (w.size() < 3 || w[1] != "=") throw ParseError("expected `%n = op.type …`");
        if (valueRef(w[0]) != k.size())
            throw ParseError(fmt::format("expected %{} next, found {}", k.size(), w[0]));
        auto dot = w[2].rfind('.');
        if (dot == std::string::npos) throw ParseError("expected `op.type`, found `" + w[2] + "`");
        auto op = opFromName(w[2].substr(0, dot));
        if (!op) throw ParseError("unknown instruction `" + w[2].substr(0, dot) + "`");
        inst.op = *op;
        inst.type = type(w[2].substr(dot + 1));
        size_t components = 0;
        for (size_t i = 3; i < w.size(); ++i) {
            const std::string& t = w[i];
            if (t[0] == '%') inst.operands.push_back(valueRef(t));
            else if (t[0] == '#') inst.attr = integer(t.substr(1));
            else if (t[0] == '^') inst.attr2 = integer(t.substr(1));
            else if (inst.op == Op::Const && components < 4) inst.constant[components++] = number(t);
            else throw ParseError("unexpected `" + t + "`");
        }
        k.addUnique(std::move(inst));
    }

    // FILE:LINE:COLUMN; files are numbered in the order they first appear.
    Loc location(const std::string& text) {
        auto second = text.rfind(':');
        auto first = second == std::string::npos || second == 0 ? std::string::npos : text.rfind(':', second - 1);
        if (first == std::string::npos) throw ParseError("expected a location `file:line:column`");
        std::string file = text.substr(0, first);
        size_t index = 0;
        while (index < files_.size() && files_[index] != file) ++index;
        if (index == files_.size()) files_.push_back(file);
        return {static_cast<int32_t>(index), static_cast<uint32_t>(integer(text.substr(first + 1, second - first - 1))),
                static_cast<uint32_t>(integer(text.substr(second + 1))), 1};
    }

public:
    std::vector<std::string> files_;

private:
    std::vector<std::string> lines_;
    size_t pos_ = 0;
};

}  // namespace

std::optional<Module> parseModule(const std::string& text, std::string& error) {
    Parser parser(text);
    try {
        Module m = parser.run();
        m.files = parser.files_;
        return m;
    } catch (const std::exception& e) {
        error = fmt::format("line {}: {}", parser.lineNumber(), e.what());
        return std::nullopt;
    }
}

}  // namespace psys::ir
