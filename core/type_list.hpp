#pragma once
// A compile-time list of types, walked with for_each_type to build the registries.

namespace stepbench {

template <class... Ts>
struct type_list {};

template <class... Ts, class F>
constexpr void for_each_type(type_list<Ts...>, F&& f) {
  (f.template operator()<Ts>(), ...);
}

// The types of several lists, in order: type_list_cat_t<type_list<A, B>, type_list<C>>
// is type_list<A, B, C>.
template <class... Lists>
struct type_list_cat;
template <class... Ts>
struct type_list_cat<type_list<Ts...>> {
  using type = type_list<Ts...>;
};
template <class... Ts, class... Us, class... Rest>
struct type_list_cat<type_list<Ts...>, type_list<Us...>, Rest...> : type_list_cat<type_list<Ts..., Us...>, Rest...> {};
template <class... Lists>
using type_list_cat_t = typename type_list_cat<Lists...>::type;

}  // namespace stepbench
