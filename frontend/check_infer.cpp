// Inferring the types of every object's equations (Checker::inferObjects), before any
// object is checked.
//
// Equations are a set: each may refer to any other, and recursion through `integrate`,
// `prev` or `->` is legal (thesis §3.1.5); a fold's term reads another type's equations
// (`other.vel`, of any type, declared before or after) and a nested object its parents'.
// So the types of every object's equations are inferred together: start from the
// annotations, re-check all equations until no type changes (diagnostics held back); a
// recursive equation whose width nothing fixes defaults to float. checkObject then checks
// each object once more with diagnostics on.
#include <functional>
#include <vector>

#include "frontend/checker.h"

namespace psys::detail {

using namespace ast;

void Checker::inferObjects() {
    std::vector<ObjectDecl*> objects;
    std::function<void(ObjectDecl&)> collect = [&](ObjectDecl& o) {
        objects.push_back(&o);
        for (auto& child : o.children) collect(*child);
    };
    for (auto& module : program_.modules)
        for (auto& decl : module->decls)
            if (decl->kind == DeclKind::Object) collect(static_cast<ObjectDecl&>(*decl));
    bool wasSuppressed = diags_.suppressed();
    diags_.setSuppressed(true);
    for (ObjectDecl* o : objects) {
        for (auto& eq : o->equations) {
            eq->types.assign(eq->names.size(), Type::unknown());
            if (eq->annotation) eq->types[0] = eq->annotation->type;
        }
        declareObjectNames(*o);
    }
    auto contextOf = [](const ObjectDecl& o) {
        Context ctx;
        ctx.where = Where::Object;
        ctx.object = &o;
        return ctx;
    };
    // (A read of a type checked later in the round takes a round a link: folds over
    // types declared after, chained, need as many rounds as types.)
    const size_t rounds = 16 + objects.size();
    for (size_t round = 0; round < rounds; ++round) {
        std::vector<std::vector<Type>> before;
        for (ObjectDecl* o : objects)
            for (auto& eq : o->equations) before.push_back(eq->types);
        for (ObjectDecl* o : objects)
            for (auto& eq : o->equations) checkEquation(*eq, contextOf(*o), false);
        bool changed = false;
        size_t i = 0;
        for (ObjectDecl* o : objects)
            for (auto& eq : o->equations) changed |= before[i++] != eq->types;
        if (changed) continue;
        // Stable: give any still-unknown recursive equation the default type float and go on.
        bool defaulted = false;
        for (ObjectDecl* o : objects)
            for (auto& eq : o->equations)
                for (auto& t : eq->types)
                    if (t.isUnknown()) {
                        t = Type::scalar();
                        defaulted = true;
                    }
        if (!defaulted) break;
    }
    // Still changing after every round (an unbounded widening): float, as a recursive
    // equation nothing fixes, so that the final check reports what does not fit.
    for (ObjectDecl* o : objects)
        for (auto& eq : o->equations)
            for (auto& t : eq->types)
                if (t.isUnknown()) t = Type::scalar();
    diags_.setSuppressed(wasSuppressed);
}

}  // namespace psys::detail
