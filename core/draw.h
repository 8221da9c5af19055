// How an object type is drawn: its render command (`point`, `sprite`, `streak`, `trail`) and the
// attributes that are the draw's state rather than per-object values (`@shape`,
// `@blend`). The front end checks the names, the IR carries them as object attributes,
// and a viewer draws by them (docs/language.md, "Drawing"; docs/viewer.md).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace psys::core {

// `point(pos, colour, size)`: a round dot `size` pixels across at the reference distance;
// `sprite(pos, colour, size [, rotation [, frame]])`: a camera-facing square `size` world
// units across, turned by `rotation` radians, of the type's shape;
// `streak(from, to, colour, width)`: a band `width` world units wide from `from` to `to`;
// `trail(pos, colour, width, N)`: a ribbon through the object's positions at its last N
// updates (this one first), `width` world units wide at its head, narrowing and fading
// to nothing at its tail.
enum class DrawKind : uint8_t { Point, Sprite, Streak, Trail };
constexpr std::array<std::string_view, 4> kDrawKindNames = {"point", "sprite", "streak", "trail"};

// The parameters of the draw commands, the one table the checker (their names and types)
// and the lowering (what each becomes) read. A parameter's role says what it is drawn as:
// the render column it fills, or a trail's length (a whole-number constant the compiler
// turns into that many points of history).
enum class DrawRole : uint8_t { Position, Color, Size, Rotation, Frame, End, Length };
struct DrawParam {
    std::string_view name;
    int width;  // 1: a float, 3: a vec3, 4: a vec4
    DrawRole role;
};
struct DrawSignature {
    std::array<DrawParam, 5> params;
    size_t count;     // params[0 … count)
    size_t required;  // the first `required` must be given
};
// A trail's points: at least 2 (a head and one point behind), at most kMaxTrail.
constexpr int kMaxTrail = 64;

constexpr DrawSignature drawSignature(DrawKind kind) {
    using R = DrawRole;
    switch (kind) {
        case DrawKind::Point: return {{{{"position", 3, R::Position}, {"colour", 4, R::Color}, {"size", 1, R::Size}}}, 3, 3};
        case DrawKind::Sprite:
            return {{{{"position", 3, R::Position}, {"colour", 4, R::Color}, {"size", 1, R::Size},
                      {"rotation", 1, R::Rotation}, {"frame", 1, R::Frame}}}, 5, 3};
        case DrawKind::Streak:
            return {{{{"start", 3, R::Position}, {"end", 3, R::End}, {"colour", 4, R::Color}, {"width", 1, R::Size}}}, 4, 4};
        case DrawKind::Trail:
            return {{{{"position", 3, R::Position}, {"colour", 4, R::Color}, {"width", 1, R::Size},
                      {"length", 1, R::Length}}}, 4, 4};
    }
    return {{}, 0, 0};
}

// A sprite's shape, computed in the fragment shader (a disc with a soft edge, a hard disc,
// a ring, a four-pointed flare, a puff of value noise).
enum class Shape : uint8_t { Soft, Disc, Ring, Star, Smoke };
constexpr std::array<std::string_view, 5> kShapeNames = {"soft", "disc", "ring", "star", "smoke"};

// How a type's colours combine with what is behind them: added (light: sparks, fire,
// glows; order does not matter) or alpha-blended over it (matter: smoke, dust; drawn back
// to front).
enum class Blend : uint8_t { Add, Alpha };
constexpr std::array<std::string_view, 2> kBlendNames = {"add", "alpha"};

template <typename E, size_t N>
constexpr std::string_view nameOf(E e, const std::array<std::string_view, N>& names) {
    return names[static_cast<size_t>(e)];
}

template <typename E, size_t N>
constexpr std::optional<E> fromName(std::string_view name, const std::array<std::string_view, N>& names) {
    for (size_t i = 0; i < N; ++i)
        if (names[i] == name) return static_cast<E>(i);
    return std::nullopt;
}

constexpr std::string_view drawKindName(DrawKind k) { return nameOf(k, kDrawKindNames); }
constexpr std::string_view shapeName(Shape s) { return nameOf(s, kShapeNames); }
constexpr std::string_view blendName(Blend b) { return nameOf(b, kBlendNames); }
constexpr std::optional<DrawKind> drawKindFromName(std::string_view n) { return fromName<DrawKind>(n, kDrawKindNames); }
constexpr std::optional<Shape> shapeFromName(std::string_view n) { return fromName<Shape>(n, kShapeNames); }
constexpr std::optional<Blend> blendFromName(std::string_view n) { return fromName<Blend>(n, kBlendNames); }

// The blend a type gets when it names none: sprites and streaks of light add up; a point
// too (the viewer's look so far).
constexpr Blend defaultBlend(DrawKind) { return Blend::Add; }

}  // namespace psys::core
