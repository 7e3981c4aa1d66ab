#pragma once
// A compile-time list of types, walked with for_each_type to build the registries.
#include <utility>

namespace stepbench {

template <class... Ts>
struct type_list {};

template <class... Ts, class F>
constexpr void for_each_type(type_list<Ts...>, F&& f) {
  (f.template operator()<Ts>(), ...);
}

}  // namespace stepbench
