#include "frontend/types.h"

namespace psys {

Type Type::vec(int width) {
    switch (width) {
        case 1: return Type(Kind::Float);
        case 2: return Type(Kind::Vec2);
        case 3: return Type(Kind::Vec3);
        case 4: return Type(Kind::Vec4);
        default: return Type(Kind::Error);
    }
}

Type Type::tuple(std::vector<Type> elements) {
    Type t(Kind::Tuple);
    t.elements_ = std::move(elements);
    return t;
}

int Type::width() const {
    switch (kind_) {
        case Kind::Float: return 1;
        case Kind::Vec2: return 2;
        case Kind::Vec3: return 3;
        case Kind::Vec4: return 4;
        default: return 0;
    }
}

std::string Type::str() const {
    switch (kind_) {
        case Kind::Error: return "<error>";
        case Kind::Unknown: return "<unknown>";
        case Kind::Bool: return "bool";
        case Kind::Float: return "float";
        case Kind::Vec2: return "vec2";
        case Kind::Vec3: return "vec3";
        case Kind::Vec4: return "vec4";
        case Kind::Tuple: {
            std::string s = "(";
            for (size_t i = 0; i < elements_.size(); ++i) s += (i ? ", " : "") + elements_[i].str();
            return s + ")";
        }
    }
    return "<error>";
}

namespace {

struct NamedType {
    std::string_view name;
    int width;  // 0: bool
};
constexpr NamedType kNamedTypes[] = {{"bool", 0}, {"float", 1}, {"scalar", 1}, {"vec2", 2}, {"vec3", 3},
                                     {"point", 3}, {"vector", 3}, {"vec4", 4}, {"color", 4}};

}  // namespace

std::optional<Type> Type::fromName(std::string_view name) {
    for (const NamedType& t : kNamedTypes)
        if (t.name == name) return t.width == 0 ? boolean() : vec(t.width);
    return std::nullopt;
}

std::vector<std::string_view> Type::names() {
    std::vector<std::string_view> all;
    for (const NamedType& t : kNamedTypes) all.push_back(t.name);
    return all;
}

}  // namespace psys
