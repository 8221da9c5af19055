// The types of .psys values.
//
// Scalars and vectors are float; `color` is vec4 and `point` is vec3 (names for the
// reader, the same types). Tuples exist only to carry composite state: `(pos, vel) = …`.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace psys {

class Type {
public:
    enum class Kind { Error, Unknown, Bool, Float, Vec2, Vec3, Vec4, Tuple };

    Type() = default;
    static Type error() { return Type(Kind::Error); }
    static Type unknown() { return Type(Kind::Unknown); }
    static Type boolean() { return Type(Kind::Bool); }
    static Type scalar() { return Type(Kind::Float); }
    static Type vec(int width);  // 1 gives float
    static Type tuple(std::vector<Type> elements);

    Kind kind() const { return kind_; }
    bool isError() const { return kind_ == Kind::Error; }
    bool isUnknown() const { return kind_ == Kind::Unknown; }
    // Error and Unknown stand for "some type we cannot name": they never cause a second error.
    bool isVague() const { return isError() || isUnknown(); }
    bool isBool() const { return kind_ == Kind::Bool; }
    bool isFloat() const { return kind_ == Kind::Float; }
    bool isVector() const { return kind_ == Kind::Vec2 || kind_ == Kind::Vec3 || kind_ == Kind::Vec4; }
    bool isNumeric() const { return isFloat() || isVector(); }
    bool isTuple() const { return kind_ == Kind::Tuple; }
    int width() const;  // components of a float (1) or vector (2..4); 0 otherwise
    const std::vector<Type>& elements() const { return elements_; }

    std::string str() const;
    bool operator==(const Type& other) const = default;

    // `float`, `vec3`, `color`, … ; nullopt for an unknown name.
    static std::optional<Type> fromName(std::string_view name);
    // Every name fromName knows.
    static std::vector<std::string_view> names();

private:
    explicit Type(Kind kind) : kind_(kind) {}
    Kind kind_ = Kind::Error;
    std::vector<Type> elements_;
};

}  // namespace psys
