#include "test_support.h"

#include <fstream>
#include <functional>
#include <sstream>
#include <stdexcept>

namespace psys::test {

std::string readFile(const std::string& path) {
    std::ifstream in(path);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

Checked check(const std::string& text, const std::string& path) {
    Checked c;
    c.sources = std::make_unique<SourceManager>();
    c.diags = std::make_unique<DiagnosticEngine>(*c.sources);
    c.program = checkText(path, text, *c.sources, *c.diags);
    c.output = c.diags->render(false);
    return c;
}

const ast::ObjectDecl& Checked::object(const std::string& name) const {
    std::function<const ast::ObjectDecl*(const ast::ObjectDecl&)> find = [&](const ast::ObjectDecl& o) -> const ast::ObjectDecl* {
        if (o.name == name) return &o;
        for (auto& child : o.children)
            if (auto* found = find(*child)) return found;
        return nullptr;
    };
    for (auto& module : program->modules)
        for (auto& d : module->decls)
            if (d->kind == ast::DeclKind::Object)
                if (auto* found = find(static_cast<const ast::ObjectDecl&>(*d))) return *found;
    throw std::runtime_error("no object " + name);
}

const ast::Equation& Checked::equation(const std::string& objectName, const std::string& name) const {
    for (auto& eq : object(objectName).equations)
        for (auto& n : eq->names)
            if (n == name) return *eq;
    throw std::runtime_error("no equation " + name);
}

const ast::Decl& Checked::decl(const std::string& name) const {
    for (auto& module : program->modules)
        for (auto& d : module->decls)
            if (d->name == name) return *d;
    throw std::runtime_error("no declaration " + name);
}

}  // namespace psys::test
