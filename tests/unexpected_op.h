// A module whose render kernel holds an op no backend runs (a `snapshot`, which the passes
// lower away before any backend sees one), for the test that every backend refuses it
// the same way: ir::unexpectedOp's located internal error, before the first frame.
#pragma once

#include <doctest/doctest.h>

#include <string>

#include "ir/parser.h"
#include "rt/system.h"

namespace psys::test {

inline constexpr const char* kUnexpectedOpModule = R"(object a()
  kernel init
    storage
  end
  kernel update
    storage
  end
  kernel render
    %0 = age.f32  loc(a.psys:3:7)
    %1 = snapshot.f32 %0 #0  loc(a.psys:3:9)
    %2 = const.vec3 0 0 0  loc(a.psys:3:1)
    %3 = const.vec4 1 1 1 1  loc(a.psys:3:1)
    %4 = const.bool 1  loc(a.psys:3:1)
    yield position = %2
    yield color = %3
    yield size = %1
    yield visible = %4
    storage
  end
end
start
  emit a burst
  kernel start
    %0 = const.f32 1
    yield emit.count #0 = %0
  end
end
)";

// What `backend` says of it: the message of what it throws from building the system and
// drawing a frame, or "" where it throws nothing.
inline std::string refusal(rt::Backend& backend) {
    std::string error;
    auto module = ir::parseModule(kUnexpectedOpModule, error);
    INFO(error);
    REQUIRE(module.has_value());
    try {
        rt::System system(std::move(*module), backend);
        system.step(1.0 / 60);
        (void)system.points(0);
    } catch (const std::exception& e) {
        return e.what();
    }
    return "";
}

inline std::string expectedRefusal(const char* backend) {
    return std::string("internal error: ") + backend + " has no code for `snapshot` (the instruction from line 3, column 9)";
}

}  // namespace psys::test
