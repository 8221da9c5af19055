// The scoping pass on its own: IR text in, the pass, IR text out (read and checked by
// hand) — a child's parent reads and a fold's reads of both objects become exports.
#include <doctest/doctest.h>

#include "opt/passes.h"
#include "pass_support.h"

using namespace psys;

using test::after;

TEST_CASE("scoping: a parent read becomes an export of the parent") {
    CHECK(after(R"(object rocket()
  emit rocket.spark rate
  kernel behaviour
    %0 = age.f32
    %1 = splat.vec3 %0  ; pos
    let pos = %1
  end
end
object rocket.spark()
  parent rocket
  read pos: vec3 ^1
  kernel behaviour
    %0 = parent.read.vec3 #0
    yield position = %0
  end
end
)", opt::scoping) == R"(object rocket()
  emit rocket.spark rate
  export pos: vec3
  kernel behaviour
    %0 = age.f32
    %1 = splat.vec3 %0  ; pos
    let pos = %1
    yield export #0 = %1
  end
end
object rocket.spark()
  parent rocket
  kernel behaviour
    %0 = parent.export.vec3 #0 ^1
    yield position = %0
  end
end
)");
}

TEST_CASE("scoping: a fold's reads become exports of both objects, and its group names their drawn positions") {
    // bead folds `other.p - q` over the rocks within 2: rock exports p (its drawn position
    // too: one value, one export), bead its drawn position (pos) and q.
    CHECK(after(R"(object rock(p: vec3)
  kernel behaviour
    %0 = param.vec3 #0
    let p = %0
    yield position = %0
  end
end
object bead(q: vec3)
  near rock 2
  fold sum: vec3 #0
  near.read p: vec3 other
  near.read q: vec3 self
  kernel behaviour
    %0 = param.vec3 #0
    %1 = fold.vec3 #0
    %2 = add.vec3 %0, %1  ; pos
    let pos = %2
    let q = %0
    yield position = %2
  end
  kernel pair #0
    %0 = neighbour.read.vec3 #0
    %1 = neighbour.read.vec3 #1
    %2 = sub.vec3 %0, %1
    yield fold #0 = %2
  end
end
)", opt::scoping) == R"(object rock(p: vec3)
  export (position): vec3
  kernel behaviour
    %0 = param.vec3 #0
    let p = %0
    yield position = %0
    yield export #0 = %0
  end
end
object bead(q: vec3)
  export (position): vec3
  export q: vec3
  near rock 2 position #0 #0
  fold sum: vec3 #0
  kernel behaviour
    %0 = param.vec3 #0
    %1 = fold.vec3 #0
    %2 = add.vec3 %0, %1  ; pos
    let pos = %2
    let q = %0
    yield position = %2
    yield export #0 = %2
    yield export #1 = %0
  end
  kernel pair #0
    %0 = neighbour.export.vec3 #0 ^1
    %1 = neighbour.export.vec3 #1
    %2 = sub.vec3 %0, %1
    yield fold #0 = %2
  end
end
)");
}
