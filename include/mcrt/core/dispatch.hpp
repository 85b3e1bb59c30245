#pragma once
// Static dispatch over a std::variant by a chain of index comparisons. Unlike
// std::visit, whose table of function pointers keeps the compiler from
// inlining the alternatives, every branch here is inlined and the branch
// predictor sees plain conditional jumps.
#include <cstddef>
#include <variant>

namespace mcrt {

template <std::size_t I = 0, class F, class... T>
inline decltype(auto) dispatch(const std::variant<T...>& v, F&& f) {
  if constexpr (I + 1 == sizeof...(T)) {
    return f(*std::get_if<I>(&v));
  } else {
    if (v.index() == I) return f(*std::get_if<I>(&v));
    return dispatch<I + 1>(v, static_cast<F&&>(f));
  }
}

}  // namespace mcrt
