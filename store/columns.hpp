#pragma once
// A table's row-to-column mapping, written once for the writer, the reader and the schema
// (store/schema.cpp lists these maps' tables): each field of a study file table, in order,
// bound by name to a member of the row struct (its type the field's), through an accessor
// that returns a reference to it. The writer builds an h5::table from rows through it, the
// reader builds rows from an h5::table_data through it.
//
// Member and file types: bool <-> i8, integers <-> i64, double <-> f64, std::string <->
// str. A field the file stores derived from the row (a flag or ratio of it) is written
// only (`derived`); one stored in another form is written by a getter and read by a
// setter.
#include <algorithm>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "store/h5.hpp"
#include "store/schema.hpp"

namespace stepbench {

// The value of an enumeration a file stores as its name (to_string(value)); throws
// std::runtime_error, "unknown <what> '<text>'", for a name none of `values` has.
template <class E>
E parse_enum(std::string_view text, std::initializer_list<E> values, std::string_view what) {
  for (const E v : values)
    if (text == to_string(v)) return v;
  throw std::runtime_error(std::string("unknown ") + std::string(what) + " '" + std::string(text) + "'");
}

namespace columns_detail {

// A value as the file stores it.
template <class T>
auto stored(const T& v) {
  if constexpr (std::is_same_v<T, bool>)
    return static_cast<std::int8_t>(v);
  else if constexpr (std::is_integral_v<T>)
    return static_cast<std::int64_t>(v);
  else if constexpr (std::is_floating_point_v<T>)
    return static_cast<double>(v);
  else
    return std::string(v);
}

// A member's field type: that of the column holding its stored values.
template <class T>
schema::field_type type_of() {
  return h5::type_of(std::vector<decltype(stored(std::declval<T>()))>{});
}

// A column of a table read back, as the reader holds it (i8 and i64 both as int64).
using read_column =
    std::variant<const std::vector<double>*, const std::vector<std::int64_t>*, const std::vector<std::string>*>;

// The value at row i of a read column, as a member of type T.
template <class T>
T value_at(const read_column& c, std::size_t i) {
  if constexpr (std::is_same_v<T, bool>)
    return (*std::get<const std::vector<std::int64_t>*>(c))[i] != 0;
  else if constexpr (std::is_integral_v<T>)
    return static_cast<T>((*std::get<const std::vector<std::int64_t>*>(c))[i]);
  else if constexpr (std::is_floating_point_v<T>)
    return static_cast<T>((*std::get<const std::vector<double>*>(c))[i]);
  else
    return (*std::get<const std::vector<std::string>*>(c))[i];
}

// obj.*m.*rest...: the member at the end of a path of member pointers.
template <class T, class M, class... Rest>
constexpr auto& member_at(T& obj, M m, Rest... rest) {
  if constexpr (sizeof...(Rest) == 0)
    return obj.*m;
  else
    return member_at(obj.*m, rest...);
}

h5::column empty_column(schema::field_type type);
read_column column_of(const h5::table_data& t, const std::string& field, schema::field_type type);

}  // namespace columns_detail

template <class Row>
class column_map {
 public:
  // The schema's table `name`, stored at `where` (for the reader and the docs): its fields
  // are those bound below, in their order (store/schema.cpp lists the tables).
  column_map(std::string_view name, std::string_view where) : spec_{name, where, {}} {}
  // spec_ points into the map's vectors: a move keeps their buffers, a copy would not.
  column_map(column_map&&) = default;
  column_map(const column_map&) = delete;

  const schema::table& spec() const { return spec_; }

  // The field `name` is the member at `path` (member pointers, outermost first): row.*a.*b;
  // written and read.
  template <class... Path>
  column_map&& member(std::string_view name, Path... path) {
    static_assert((std::is_member_object_pointer_v<Path> && ...), "a path of member pointers");
    const auto access = [=](auto& r) -> auto& { return columns_detail::member_at(r, path...); };
    using M = std::remove_cvref_t<decltype(access(std::declval<Row&>()))>;
    return add(
        name, columns_detail::type_of<M>(), writer(access),
        [access](Row& r, const columns_detail::read_column& c, std::size_t i) {
          access(r) = columns_detail::value_at<M>(c, i);
        },
        timed_);
  }
  // The field `name` is get(row), read back by set(row, value).
  template <class Get, class Set>
  column_map&& field(std::string_view name, Get get, Set set) {
    using M = std::remove_cvref_t<decltype(get(std::declval<const Row&>()))>;
    return add(
        name, columns_detail::type_of<M>(), writer(get),
        [set](Row& r, const columns_detail::read_column& c, std::size_t i) {
          set(r, columns_detail::value_at<M>(c, i));
        },
        timed_);
  }
  // The field `name` is get(row), derived from the row: written only.
  template <class Get>
  column_map&& derived(std::string_view name, Get get) {
    using M = std::remove_cvref_t<decltype(get(std::declval<const Row&>()))>;
    return add(name, columns_detail::type_of<M>(), writer(get), nullptr, timed_);
  }
  // Every field of `inner`, bound to the member access(row) of this row.
  template <class Inner, class Access>
  column_map&& fields(const column_map<Inner>& inner, Access access) {
    for (const auto& b : inner.bindings_) {
      getter get;
      if (b.get)
        get = [g = b.get, access](Row& r, const columns_detail::read_column& c, std::size_t i) { g(access(r), c, i); };
      add(
          b.name, b.type, [p = b.put, access](const Row& r, h5::column& c) { p(access(r), c); }, std::move(get),
          b.timed);
      bindings_.back().missing = b.missing;
    }
    return std::move(*this);
  }
  // The last field, absent from files written before it was added, reads as `value`.
  column_map&& missing_as(double value) {
    bindings_.back().missing = value;
    return std::move(*this);
  }
  // The table is written only when it has rows (schema::table::optional).
  column_map&& optional() {
    spec_.optional = true;
    return std::move(*this);
  }
  // The fields bound after this one form a timed-only group: present exactly when the study
  // was timed (stepbench_bench --study_out), as a whole.
  column_map&& timed_only() {
    timed_ = true;
    return std::move(*this);
  }

  // The rows as the table (its timed-only fields when `timed`).
  h5::table table(std::span<const Row> rows, bool timed = false) const {
    h5::table t;
    for (const auto& b : bindings_)
      if (timed || !b.timed) {
        h5::column c = columns_detail::empty_column(b.type);
        for (const auto& r : rows) b.put(r, c);
        t.add(std::string(b.name), std::move(c));
      }
    return t;
  }
  // An optional table without rows is not written (schema::table::optional).
  void write(H5::Group& g, const std::string& dataset, std::span<const Row> rows, bool timed = false) const {
    if (spec_.optional && rows.empty()) return;
    table(rows, timed).write(g, dataset, spec());
  }

  // The rows of a table read back: every field bound, of its type (the timed-only group
  // present whole or absent); fields not bound (added by a newer build of the same format)
  // are left alone.
  std::vector<Row> read(const h5::table_data& t) const {
    std::vector<Row> out(t.rows());
    const auto first_timed = std::find_if(bindings_.begin(), bindings_.end(), [](const auto& b) { return b.timed; });
    const bool timed = first_timed != bindings_.end() && t.has(std::string(first_timed->name));
    for (const auto& b : bindings_) {
      if (!b.get || (b.timed && !timed)) continue;
      const std::string name(b.name);
      if (!t.has(name) && b.missing) {
        const std::vector<double> fill(t.rows(), *b.missing);
        for (std::size_t i = 0; i < out.size(); ++i) b.get(out[i], &fill, i);
        continue;
      }
      const auto c = columns_detail::column_of(t, name, b.type);  // throws naming a missing field
      for (std::size_t i = 0; i < out.size(); ++i) b.get(out[i], c, i);
    }
    return out;
  }
  // An optional table that is absent has no rows.
  std::vector<Row> read(const H5::Group& g, const std::string& dataset) const {
    if (!h5::is_dataset(g, dataset)) {
      if (spec_.optional) return {};
      throw std::runtime_error("missing dataset '" + dataset + "' in " + g.getObjName());
    }
    return read(h5::read_table(g.openDataSet(dataset)));
  }

 private:
  template <class>
  friend class column_map;
  using putter = std::function<void(const Row&, h5::column&)>;
  using getter = std::function<void(Row&, const columns_detail::read_column&, std::size_t)>;
  struct binding {
    std::string_view name;
    schema::field_type type;
    bool timed;
    putter put;
    getter get;  // empty: written only
    std::optional<double> missing;
  };

  template <class Get>
  static putter writer(Get get) {
    return [get](const Row& r, h5::column& c) {
      auto v = columns_detail::stored(get(r));
      std::get<std::vector<decltype(v)>>(c).push_back(std::move(v));
    };
  }
  column_map&& add(std::string_view name, schema::field_type type, putter put, getter get, bool timed) {
    bindings_.push_back({name, type, timed, std::move(put), std::move(get), std::nullopt});
    fields_.push_back({name, type});
    if (groups_.empty() || groups_.back().timed_only != timed) groups_.push_back({{}, timed});
    // The groups' spans into fields_, set again as it grows (a span keeps its size).
    groups_.back().fields = {fields_.data(), groups_.back().fields.size() + 1};
    for (std::size_t g = 0, at = 0; g < groups_.size(); at += groups_[g++].fields.size())
      groups_[g].fields = {fields_.data() + at, groups_[g].fields.size()};
    spec_.groups = groups_;
    return std::move(*this);
  }

  schema::table spec_;
  std::vector<binding> bindings_;
  std::vector<schema::field> fields_;
  std::vector<schema::field_group> groups_;
  bool timed_ = false;
};

}  // namespace stepbench
