// How an object type is drawn: its render command (`point`, `sprite`, `streak`) and the
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
// `streak(from, to, colour, width)`: a band `width` world units wide from `from` to `to`.
enum class DrawKind : uint8_t { Point, Sprite, Streak };
constexpr std::array<std::string_view, 3> kDrawKindNames = {"point", "sprite", "streak"};

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
