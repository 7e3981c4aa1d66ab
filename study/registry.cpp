#include "study/registry.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cstddef>
#include <memory>
#include <stdexcept>
#include <utility>

#include "study/problem_model.hpp"

namespace stepbench {
namespace registry_detail {
// Defined in the shards (generated/problem_shard_<k>.cpp), one explicit instantiation
// each; declared here without its body so that no problem_model is compiled in this file.
template <std::size_t Shard>
std::unique_ptr<problem_instance> make_problem_in_shard(std::string_view name);
}  // namespace registry_detail

using namespace registry_detail;

std::vector<std::string> problem_names() {
  std::vector<std::string> names;
  for_each_type(all_problems{}, [&]<class P>() { names.emplace_back(P::name); });
  return names;
}

std::unique_ptr<problem_instance> make_problem(std::string_view name) {
  std::unique_ptr<problem_instance> out;
  [&]<std::size_t... S>(std::index_sequence<S...>) {
    ((out = out ? std::move(out) : make_problem_in_shard<S>(name)), ...);
  }
  (std::make_index_sequence<STEPBENCH_PROBLEM_SHARDS>{});
  if (!out)
    throw std::invalid_argument(
        fmt::format("unknown problem '{}' (known: {})", name, fmt::join(problem_names(), ", ")));
  return out;
}

const std::vector<method_info>& all_methods() {
  static const std::vector<method_info> all = [] {
    std::vector<method_info> out;
    for_each_method([&]<class M>() { out.push_back(info_of<M>()); });
    return out;
  }();
  return all;
}

std::vector<method_info> integrators() {
  std::vector<method_info> out;
  for (const auto& m : all_methods())
    if (m.origin == method_origin::ours) out.push_back(m);
  return out;
}

const method_info& find_method(std::string_view name) {
  for (const auto& m : all_methods())
    if (m.name == name) return m;
  std::vector<std::string> known;
  for (const auto& m : all_methods()) known.push_back(m.name);
  throw std::invalid_argument(fmt::format("unknown method '{}' (known: {})", name, fmt::join(known, ", ")));
}

}  // namespace stepbench
