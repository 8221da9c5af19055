// Name resolution and type checking of a loaded program (internal to frontend/).
//
// One Checker walks the whole program once: it fills in every NameExpr's Ref, every
// Expr's Type, every emit's target and every equation's types, and reports what is wrong.
// Split over files by concern: symbols.cpp (scopes and lookup), check_expr.cpp
// (expressions), check_infer.cpp (every object's equation types, together),
// check_object.cpp (objects, equations, commands), check_decls.cpp
// (constants, functions, externs, triggers, spawns, attributes), check_cycles.cpp
// (algebraic loops among an object's equations), check_size.cpp (functions' size once inlined).
#pragma once

#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "frontend/ast.h"
#include "frontend/diagnostics.h"
#include "frontend/frontend.h"

namespace psys::detail {

// Where an expression appears decides what it may use.
enum class Where { Object, Fn, Const, ExternValue, Trigger, Spawn, Attribute };

struct Context {
    Where where = Where::Object;
    const ast::ObjectDecl* object = nullptr;
    const ast::FnDecl* fn = nullptr;
    size_t letsVisible = 0;  // lets of `fn` declared before the expression
    const ast::TriggerDecl* trigger = nullptr;
    const ast::Command* block = nullptr;  // the `when` or `on` the commands are in
    bool dying = false;                   // in `on death`
    // In a neighbour fold's term (`near_sum(boid, 2, other.vel)`): the call, and the type
    // `other` is one of.
    const ast::CallExpr* fold = nullptr;
    const ast::ObjectDecl* other = nullptr;
};

// The names an object declares: its parameters and equations.
struct ObjectScope {
    std::map<std::string, ast::Ref> names;
    std::map<std::string, SourceRange> declaredAt;
};

class Checker {
public:
    Checker(ast::Program& program, DiagnosticEngine& diags, CheckOptions options = {})
        : program_(program), diags_(diags), options_(options) {}
    void run();

private:
    // symbols.cpp
    void collectGlobals();
    void declareGlobal(ast::Decl& decl);
    bool checkDeclarableName(const std::string& name, SourceRange range, const char* what);
    ast::Ref lookupName(const std::string& name, SourceRange range, const Context& ctx);
    const ast::ObjectDecl* findEmitTarget(const std::string& name, SourceRange range, const Context& ctx);
    // Where an `import` line goes in `file`: after its last import, else before its first declaration.
    SourceRange importPoint(int file) const;
    void reportUnknown(const std::string& what, const std::string& name, SourceRange range,
                       const std::function<std::vector<std::string>()>& candidates);
    std::vector<std::string> namesInScope(const Context& ctx) const;
    const ast::ObjectDecl* enclosingObject(const std::string& name, const Context& ctx, int* depth) const;
    // For did-you-mean: the names of the program's top-level declarations of the kinds
    // given, and its nested objects' (with repeats), each in name order; the ones declared
    // elsewhere too (CheckOptions).
    std::vector<std::string> globalNames(std::initializer_list<ast::DeclKind> kinds) const;
    std::vector<std::string> nestedNames() const;

    // check_expr.cpp
    Type check(ast::Expr& expr, const Context& ctx);
    Type checkName(ast::NameExpr& name, const Context& ctx);
    Type checkCall(ast::CallExpr& call, const Context& ctx);
    Type checkBuiltinCall(ast::CallExpr& call, const std::vector<Type>& args, const Context& ctx);
    Type checkUserCall(ast::CallExpr& call, const ast::FnDecl& fn, const std::vector<Type>& args);
    Type checkMember(ast::MemberExpr& member, const Context& ctx);
    Type checkInstanceMember(ast::MemberExpr& member, const Context& ctx);
    // `object`'s equation or parameter `member.member` (marked used), or an error naming
    // the closest of its names and `alsoNamed`.
    std::optional<ast::Ref> memberOf(const ast::ObjectDecl& object, const ast::MemberExpr& member,
                                     std::vector<std::string> alsoNamed);

    // check_near.cpp
    Type checkNear(ast::CallExpr& call, const Context& ctx);
    Type checkNeighbourMember(ast::MemberExpr& member, const Context& ctx);
    bool checkFoldTermRef(const ast::NameExpr& name, const Context& ctx);
    void checkFoldCall(const ast::CallExpr& call, const Context& ctx);
    const ast::ObjectDecl* findObjectType(const std::string& name) const;
    Type checkUnary(ast::UnaryExpr& unary, const Context& ctx);
    Type checkBinary(ast::BinaryExpr& binary, const Context& ctx);
    Type typeOfRef(const ast::Ref& ref);
    bool expectType(const ast::Expr& expr, const Type& want, const std::string& what);

    // check_object.cpp
    void checkObject(ast::ObjectDecl& object);
    void declareObjectNames(ast::ObjectDecl& object);
    // check_infer.cpp
    void inferObjects();
    void checkEquation(ast::Equation& eq, const Context& ctx, bool final);
    void checkCommands(std::vector<ast::CommandPtr>& commands, const Context& ctx, const ast::Command** point);
    void checkEmit(ast::Command& emit, const Context& ctx);
    void checkOn(ast::Command& on, const Context& ctx, const ast::Command** point);
    void checkNotify(ast::Command& cmd, const Context& ctx);
    void checkDraw(ast::Command& draw, const Context& ctx, const ast::Command** point);
    void checkTrailLength(ast::Command& trail, const ast::Expr& length);
    void checkTexture(ast::Attribute& texture, const Context& ctx);
    void checkTolerance(ast::Attribute& tolerance, const Context& ctx);
    void checkArguments(std::vector<ast::ExprPtr>& args, const ast::ObjectDecl& target, SourceRange callRange,
                        const Context& ctx);
    void checkAttributes(const std::vector<ast::Attribute*>& attributes);

    // check_cycles.cpp
    void checkAlgebraicLoops(const ast::ObjectDecl& object);

    // check_size.cpp
    void checkInlinedSize();

    // check_decls.cpp
    void checkConst(ast::ConstDecl& decl);
    void checkFn(const ast::FnDecl& decl);
    void checkExtern(ast::ExternDecl& decl);
    void checkTrigger(ast::TriggerDecl& decl);
    void checkSpawn(ast::SpawnDecl& decl);
    void checkParams(const std::vector<ast::Param>& params, const char* owner);
    void reportUnused();

    ast::Program& program_;
    DiagnosticEngine& diags_;
    CheckOptions options_;
    mutable std::optional<std::map<std::string, ast::DeclKind>> everyGlobal_;  // globalNames's, once

    std::map<std::string, ast::Decl*> globals_;
    std::multimap<std::string, const ast::ObjectDecl*> nestedObjects_;
    std::map<const ast::ObjectDecl*, ObjectScope> objectScopes_;

    // Lazily checked declarations: 1 while being checked (a second visit is a cycle), 2 when done.
    std::map<const ast::Decl*, int> progress_;
    std::vector<const ast::Decl*> checking_;

    std::set<const ast::Equation*> usedEquations_;
    std::set<const ast::ObjectDecl*> createdObjects_;
    // Externs a fold's term reads (the name, the fold's callee): an error once the program
    // turns out instanced, where each instance has its own (reportInstancedFoldExterns).
    std::vector<std::pair<const ast::NameExpr*, std::string>> foldExternReads_;
    void reportInstancedFoldExterns();
};

// Levenshtein-nearest candidate within a small distance, for "did you mean …?".
std::string closestName(const std::string& name, const std::vector<std::string>& candidates);

}  // namespace psys::detail
