// IR value types: bool, u32 (random-number keys), f32 and f32 vectors of 2 to 4.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace psys::ir {

struct Type {
    enum class Kind : uint8_t { Bool, U32, F32 };
    Kind kind = Kind::F32;
    uint8_t width = 1;  // F32 only: 1 (float) to 4

    static Type boolean() { return {Kind::Bool, 1}; }
    static Type u32() { return {Kind::U32, 1}; }
    static Type f32() { return {Kind::F32, 1}; }
    static Type vec(int w) { return {Kind::F32, static_cast<uint8_t>(w)}; }

    bool isBool() const { return kind == Kind::Bool; }
    bool isFloat() const { return kind == Kind::F32; }
    bool isScalarFloat() const { return kind == Kind::F32 && width == 1; }
    bool isVector() const { return kind == Kind::F32 && width > 1; }

    bool operator==(const Type&) const = default;
    std::string str() const;
    static std::optional<Type> parse(std::string_view text);
};

}  // namespace psys::ir
