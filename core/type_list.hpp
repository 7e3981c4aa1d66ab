#pragma once
// A compile-time list of types, walked with for_each_type to build the registries.
#include <cstddef>
#include <utility>

namespace stepbench {

template <class... Ts>
struct type_list {};

template <class... Ts, class F>
constexpr void for_each_type(type_list<Ts...>, F&& f) {
  (f.template operator()<Ts>(), ...);
}

// f.template operator()<T, K>() for each type T with its index K in the list.
template <class... Ts, class F>
constexpr void for_each_type_indexed(type_list<Ts...>, F&& f) {
  [&]<std::size_t... K>(std::index_sequence<K...>) { (f.template operator()<Ts, K>(), ...); }
  (std::index_sequence_for<Ts...>{});
}

template <class... Ts>
constexpr std::size_t type_list_size(type_list<Ts...>) {
  return sizeof...(Ts);
}

}  // namespace stepbench
