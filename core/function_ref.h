// A callable passed down a call and not kept: a pointer to it and a function that calls
// it. Where the run-time hands a lambda to a loop over pieces or chunks (every step, many
// times), a std::function would copy a lambda with more than two captures to the heap: a
// steady-state step allocates nothing (tests/capi/allocation_test.cpp).
#pragma once

#include <memory>
#include <type_traits>
#include <utility>

namespace psys::core {

template <class Signature>
class FunctionRef;

template <class R, class... Args>
class FunctionRef<R(Args...)> {
public:
    template <class F>
        requires(!std::is_same_v<std::remove_cvref_t<F>, FunctionRef> && std::is_invocable_r_v<R, F&, Args...>)
    FunctionRef(F&& f)  // NOLINT: converts as a std::function parameter would
        : callable_(const_cast<void*>(static_cast<const void*>(std::addressof(f)))),
          call_([](void* c, Args... args) -> R {
              return (*static_cast<std::remove_reference_t<F>*>(c))(std::forward<Args>(args)...);
          }) {}

    R operator()(Args... args) const { return call_(callable_, std::forward<Args>(args)...); }

private:
    void* callable_;
    R (*call_)(void*, Args...);
};

}  // namespace psys::core
