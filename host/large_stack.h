// The compiler recurses over expressions (the parser, the checker, lowering): a sum of
// 100,000 terms is a tree 100,000 deep. Programs run their work on a thread with a large
// stack, so what the limits of docs/language.md allow always fits; the stack is address
// space, and memory only as deep as the recursion goes.
#pragma once

#include <cstddef>
#include <functional>

namespace psys::host {

constexpr size_t kLargeStackBytes = size_t{2} << 30;

// Runs `body` on a thread with a `bytes` stack and returns what it returns (if the thread
// cannot be made, on this one).
int runWithLargeStack(const std::function<int()>& body, size_t bytes = kLargeStackBytes);

}  // namespace psys::host
