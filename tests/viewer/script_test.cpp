// Scripts are checked whole when read: every bad line named FILE:LINE with why, nothing
// left to fail at its frame.
#include <doctest/doctest.h>

#include <string>

#include "script.h"

using psys::viewer::Script;

namespace {

std::string problem(const std::string& text) {
    std::string error;
    auto script = Script::parse(text, "s.script", error);
    return script ? "" : error;
}

}  // namespace

TEST_CASE("a script is checked whole when it is read, each bad line named FILE:LINE") {
    CHECK(problem("# a comment\n1 zoom 1\n2 orbit 10 -5\n3 key SPACE\n4 set rate=3\n5 fire boom:1,2\n6 screenshot a.jpg\n"
                  "7 quit\n") == "");
    CHECK(problem("1 zoom 1\n4294967298 screenshot x.png\n") ==
          "s.script:2: a line starts with the frame number (1 to 2147483647), not `4294967298`");
    CHECK(problem("0 quit\n") == "s.script:1: a line starts with the frame number (1 to 2147483647), not `0`");
    CHECK(problem("2 orbit abc def\n") == "s.script:1: `orbit` takes finite numbers, not `abc`");
    CHECK(problem("2 orbit 1e50 0\n") == "s.script:1: `orbit` takes finite numbers, not `1e50`");
    CHECK(problem("2 orbit 10abc 5\n") == "s.script:1: `orbit` takes finite numbers, not `10abc`");
    CHECK(problem("2 zoom nan\n") == "s.script:1: `zoom` takes finite numbers, not `nan`");
    CHECK(problem("2 pan inf 0\n") == "s.script:1: `pan` takes finite numbers, not `inf`");
    CHECK(problem("2 key FOO\n") == "s.script:1: unknown key `FOO` (F R B G L H SPACE S T = - 1…9 P V F1 ? Q ESC)");
    CHECK(problem("2 screenshot x.gif\n") ==
          "s.script:1: cannot write `x.gif`: an unknown image format `.gif` (it writes png, jpg, bmp or tga)");
    CHECK(problem("2 set =3\n").rfind("s.script:1: ", 0) == 0);
    CHECK(problem("2 jump\n") == "s.script:1: the actions are orbit, pan, zoom, key, set, fire, screenshot and quit");
    CHECK(problem("2 orbit 1\n") == "s.script:1: `orbit` takes 2 arguments");
}

TEST_CASE("a script's numbers are read once, when it is read") {
    std::string error;
    auto script = Script::parse("3 orbit 10 -2.5\n", "s.script", error);
    REQUIRE(script);
    REQUIRE(script->actions.size() == 1);
    CHECK(script->actions[0].numbers == std::vector<float>{10.0f, -2.5f});
}
