#include "ir/types.h"

namespace psys::ir {

std::string Type::str() const {
    switch (kind) {
        case Kind::Bool: return "bool";
        case Kind::U32: return "u32";
        case Kind::F32: return width == 1 ? "f32" : "vec" + std::to_string(width);
    }
    return "?";
}

std::optional<Type> Type::parse(std::string_view text) {
    if (text == "bool") return boolean();
    if (text == "u32") return u32();
    if (text == "f32") return f32();
    if (text == "vec2") return vec(2);
    if (text == "vec3") return vec(3);
    if (text == "vec4") return vec(4);
    return std::nullopt;
}

}  // namespace psys::ir
