// The abstract syntax tree of a .psys program.
//
// Built from the parse tree by parse.cpp, then annotated in place by name resolution
// (every name gets a Ref) and type checking (every expression gets a Type). Each node
// keeps the source range it came from, for diagnostics and for `--emit=ast`.
#pragma once

#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/draw.h"
#include "frontend/source.h"
#include "frontend/types.h"

namespace psys::ast {

struct ObjectDecl;
struct ConstDecl;
struct FnDecl;
struct ExternDecl;
struct TriggerDecl;
struct Equation;
struct LetStmt;

// A value the checker computed at compile time (frontend/consteval.h), kept on the AST
// where the program needs it as a number (extern defaults and ranges, attributes, named
// constants), so that lowering reads it rather than computing it again.
struct ConstValue {
    Type type;                 // bool, float or vecN
    std::array<float, 4> v{};  // components; a bool is 0 or 1
    bool isTrue() const { return v[0] != 0; }
};

// ---------------------------------------------------------------- names

// What a name refers to, filled in by name resolution.
struct Ref {
    enum class Kind {
        Unresolved,
        Param,         // object: parameter `index` of `object`
        Equation,      // equation `equation`, component `index` of a tuple equation
        Const,
        Extern,
        FnParam,       // parameter `index` of `fn`
        Let,           // a `let` inside a fn body
        TriggerParam,  // parameter `index` of `trigger`
        Age,           // the object's age (seconds since it was created)
        Time,          // global time
        Dt,            // the length of the current step
        Alive,         // parent.alive: false once the parent has died
        BuiltinConst,  // pi, tau, e, origin, named colours
    };
    Kind kind = Kind::Unresolved;
    int index = 0;
    const ObjectDecl* object = nullptr;  // Param; and the object that owns an Equation
    const Equation* equation = nullptr;
    const ConstDecl* constant = nullptr;
    const ExternDecl* externVar = nullptr;
    const FnDecl* fn = nullptr;
    const LetStmt* let = nullptr;
    const TriggerDecl* trigger = nullptr;
};

// ---------------------------------------------------------------- expressions

enum class ExprKind { Number, Bool, Name, Call, Member, Unary, Binary, Conditional, Tuple, FollowedBy };

struct Expr {
    explicit Expr(ExprKind k, SourceRange r) : kind(k), range(r) {}
    virtual ~Expr() = default;
    ExprKind kind;
    SourceRange range;
    Type type = Type::unknown();  // set by the type checker
};
using ExprPtr = std::unique_ptr<Expr>;

struct NumberExpr : Expr {
    NumberExpr(SourceRange r, double v, std::string s)
        : Expr(ExprKind::Number, r), value(v), spelling(std::move(s)) {}
    double value;
    std::string spelling;
};

struct BoolExpr : Expr {
    BoolExpr(SourceRange r, bool v) : Expr(ExprKind::Bool, r), value(v) {}
    bool value;
};

struct NameExpr : Expr {
    NameExpr(SourceRange r, std::string n) : Expr(ExprKind::Name, r), name(std::move(n)) {}
    std::string name;
    Ref ref;
};

struct CallExpr : Expr {
    CallExpr(SourceRange r, std::string c, SourceRange cr)
        : Expr(ExprKind::Call, r), callee(std::move(c)), calleeRange(cr) {}
    std::string callee;
    SourceRange calleeRange;
    std::vector<ExprPtr> args;
    const FnDecl* fn = nullptr;  // a user function; else a built-in (see builtins.h)
    int builtin = -1;            // index into the built-in function table
    // A neighbour fold (`near_sum(boid, 2, other.vel)`): the type folded over and the radius.
    const ObjectDecl* neighbours = nullptr;
    float radius = 0;
};

// `base.name`: a swizzle (`v.xz`, `c.rgb`) or a live read of an enclosing object
// (`rocket.pos`, `rocket.alive`).
struct MemberExpr : Expr {
    MemberExpr(SourceRange r, ExprPtr b, std::string m, SourceRange mr)
        : Expr(ExprKind::Member, r), base(std::move(b)), member(std::move(m)), memberRange(mr) {}
    ExprPtr base;
    std::string member;
    SourceRange memberRange;
    std::vector<int> swizzle;              // component indices when a swizzle
    const ObjectDecl* parent = nullptr;    // the enclosing object when a parent read
    int parentDepth = 0;                   // 1: the direct parent, 2: its parent, …
    Ref parentRef;                         // what is read in the parent
    bool neighbour = false;                // `other.vel` in a fold's term: `parent` is the other's type
    int instance = -1;                     // `instance.pos`: its member (builtins.h, instanceMembers)
};

enum class UnaryOp { Neg, Not, Plus };
struct UnaryExpr : Expr {
    UnaryExpr(SourceRange r, UnaryOp o, ExprPtr e) : Expr(ExprKind::Unary, r), op(o), operand(std::move(e)) {}
    UnaryOp op;
    ExprPtr operand;
};

enum class BinaryOp { Add, Sub, Mul, Div, Mod, Lt, Le, Gt, Ge, Eq, Ne, And, Or };
const char* spelling(BinaryOp op);
const char* spelling(UnaryOp op);

struct BinaryExpr : Expr {
    BinaryExpr(SourceRange r, BinaryOp o, SourceRange orng, ExprPtr a, ExprPtr b)
        : Expr(ExprKind::Binary, r), op(o), opRange(orng), lhs(std::move(a)), rhs(std::move(b)) {}
    BinaryOp op;
    SourceRange opRange;
    ExprPtr lhs, rhs;
};

// `c ? a : b` and `if c then a else b`: the same thing.
struct ConditionalExpr : Expr {
    ConditionalExpr(SourceRange r, ExprPtr c, ExprPtr t, ExprPtr e)
        : Expr(ExprKind::Conditional, r), cond(std::move(c)), thenExpr(std::move(t)), elseExpr(std::move(e)) {}
    ExprPtr cond, thenExpr, elseExpr;
};

struct TupleExpr : Expr {
    explicit TupleExpr(SourceRange r) : Expr(ExprKind::Tuple, r) {}
    std::vector<ExprPtr> elements;
};

// `init -> next`: `init` at an object's first update, `next` afterwards (Lustre's followed-by).
struct FollowedByExpr : Expr {
    FollowedByExpr(SourceRange r, ExprPtr i, ExprPtr n)
        : Expr(ExprKind::FollowedBy, r), init(std::move(i)), next(std::move(n)) {}
    ExprPtr init, next;
};

// ---------------------------------------------------------------- shared pieces

struct TypeAnnotation {
    Type type;
    SourceRange range;
    std::string spelling;  // a named type as written: `color` and `vec4` are one type
};

struct Param {
    std::string name;
    SourceRange nameRange;
    TypeAnnotation type;
};

// `@integrator(rk4)`, `@step(1/240)`, `@capacity(100000)`.
struct Attribute {
    std::string name;
    SourceRange range;  // the whole attribute
    SourceRange nameRange;
    std::optional<std::string> text;  // a file name before the arguments (`@texture("a.png", 2, 2)`), unquoted
    SourceRange textRange;
    std::vector<ExprPtr> args;
    std::optional<ConstValue> value;  // set by the checker: its constant argument (@step, @capacity)
    // @capacity's count, exact: a number as written is read as a double (4294967295 is not
    // a float); an expression is its float value.
    std::optional<double> whole;
};

// ---------------------------------------------------------------- commands

enum class CommandKind { Draw, Kill, Emit, When, On, Notify };

struct Command {
    CommandKind kind;
    SourceRange range;
    SourceRange keywordRange;
    std::vector<ExprPtr> args;   // a draw command's (point: pos, colour, size); emit: the child's arguments;
                                 // notify: the event's values
    core::DrawKind draw = core::DrawKind::Point;  // a draw command's: point, sprite, streak or trail
    int trailPoints = 0;         // a trail's length, set by the checker where it is valid
    ExprPtr cond;                // kill when / when; null for a bare `kill;`
    // emit
    std::string target;
    SourceRange targetRange;
    const ObjectDecl* targetDecl = nullptr;
    ExprPtr rate;   // `at RATE per second`; null for a one-off emission at creation
    ExprPtr count;  // `count N`; null means 1
    // when, on: the commands it guards
    std::vector<std::unique_ptr<Command>> body;
    // on: the event (`death`); notify: the event's name (the string's text)
    std::string event;
    SourceRange eventRange;
};
using CommandPtr = std::unique_ptr<Command>;

// ---------------------------------------------------------------- declarations

enum class DeclKind { Import, Attribute, Const, Fn, Extern, Trigger, Object, Spawn };

struct Decl {
    Decl(DeclKind k, SourceRange r) : kind(k), range(r) {}
    virtual ~Decl() = default;
    DeclKind kind;
    SourceRange range;
    std::string name;
    SourceRange nameRange;
};
using DeclPtr = std::unique_ptr<Decl>;

struct ImportDecl : Decl {
    explicit ImportDecl(SourceRange r) : Decl(DeclKind::Import, r) {}
    std::string path;     // as written
    SourceRange pathRange;
    int module = -1;      // the loaded module, when found
};

// A file-level attribute: applies to every object of the file.
struct FileAttributeDecl : Decl {
    explicit FileAttributeDecl(SourceRange r) : Decl(DeclKind::Attribute, r) {}
    Attribute attribute;
};

struct ConstDecl : Decl {
    explicit ConstDecl(SourceRange r) : Decl(DeclKind::Const, r) {}
    std::optional<TypeAnnotation> annotation;
    ExprPtr value;
    Type type = Type::unknown();
    std::optional<ConstValue> evaluated;  // set by the checker where `value` is a constant bool, float or vector
};

struct LetStmt {
    std::string name;
    SourceRange nameRange;
    std::optional<TypeAnnotation> annotation;
    ExprPtr value;
    Type type = Type::unknown();
};

struct FnDecl : Decl {
    explicit FnDecl(SourceRange r) : Decl(DeclKind::Fn, r) {}
    std::vector<Param> params;
    std::optional<TypeAnnotation> returnType;
    std::vector<std::unique_ptr<LetStmt>> lets;
    ExprPtr body;
    Type resultType = Type::unknown();
};

struct ExternDecl : Decl {
    explicit ExternDecl(SourceRange r) : Decl(DeclKind::Extern, r) {}
    TypeAnnotation type;
    ExprPtr defaultValue;  // null: zero
    ExprPtr rangeLow, rangeHigh;
    // Set by the checker: the values of the three, every component (a float given for a
    // vector extern spread to each); the default zero where there is none.
    std::optional<ConstValue> defaultEvaluated, lowEvaluated, highEvaluated;
};

struct TriggerDecl : Decl {
    explicit TriggerDecl(SourceRange r) : Decl(DeclKind::Trigger, r) {}
    std::vector<Param> params;
    std::vector<CommandPtr> commands;
};

// `x = e;`, `x: T = e;` or `(a, b) = e;`. Equations of an object form a set.
struct Equation {
    std::vector<std::string> names;
    std::vector<SourceRange> nameRanges;
    std::optional<TypeAnnotation> annotation;  // single equations only
    ExprPtr value;
    SourceRange range;
    std::vector<Type> types;  // one per name, set by the type checker
    bool isTuple() const { return names.size() > 1; }
};
using EquationPtr = std::unique_ptr<Equation>;

struct ObjectDecl : Decl {
    explicit ObjectDecl(SourceRange r) : Decl(DeclKind::Object, r) {}
    std::vector<Attribute> attributes;
    std::vector<Param> params;
    std::vector<EquationPtr> equations;
    std::vector<CommandPtr> commands;
    std::vector<std::unique_ptr<ObjectDecl>> children;
    const ObjectDecl* parent = nullptr;  // the enclosing object, for nested objects
    int module = -1;
};

struct SpawnDecl : Decl {
    explicit SpawnDecl(SourceRange r) : Decl(DeclKind::Spawn, r) {}
    std::vector<ExprPtr> args;
    const ObjectDecl* targetDecl = nullptr;
};

// One source file.
struct Module {
    int file = -1;  // SourceManager id
    std::string path;
    std::vector<DeclPtr> decls;  // in source order
};

// The main file and everything it imports, each file once.
struct Program {
    std::vector<std::unique_ptr<Module>> modules;  // imported files before their importers; the main file last
    // Some expression reads `instance` (set by the checker): the program is played as
    // instances (core/instances.h).
    bool instanced = false;
    // The events `notify` names, in the order they are first notified, with their values'
    // types (set by the checker).
    struct Event {
        std::string name;
        std::vector<Type> types;
        SourceRange range;
    };
    std::vector<Event> events;
    const Module& main() const { return *modules.back(); }
};

// A deep copy of a declaration as the parser built it (not yet checked), its ranges moved
// by `shift` bytes into `file` (frontend/ast_clone.cpp).
DeclPtr cloneParsed(const Decl& decl, int file, int64_t shift);

}  // namespace psys::ast
