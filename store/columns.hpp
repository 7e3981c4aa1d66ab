#pragma once
// A table's row-to-column mapping, written once for the writer and the reader alike: each
// field of a schema table (store/schema.hpp) bound by name to a member of the row struct,
// through an accessor that returns a reference to it. The writer builds an h5::table from
// rows through it, the reader builds rows from an h5::table_data through it; both follow
// the schema's table (names, order, types, timed-only groups).
//
// Member and file types: bool <-> i8, integers <-> i64, double <-> f64, std::string <->
// str. A field the file stores derived from the row (a flag or ratio of it) is written
// only (`derived`); one stored in another form is written by a getter and read by a
// setter.
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

template <class T>
constexpr schema::field_type type_of() {
  using S = decltype(stored(std::declval<T>()));
  if constexpr (std::is_same_v<S, std::int8_t>)
    return schema::field_type::i8;
  else if constexpr (std::is_same_v<S, std::int64_t>)
    return schema::field_type::i64;
  else if constexpr (std::is_same_v<S, double>)
    return schema::field_type::f64;
  else
    return schema::field_type::str;
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
  explicit column_map(std::string_view table) : spec_(&schema::find(table)) {}
  // A table the schema does not list: a study part's own (parts/part.hpp), which outlives the map.
  explicit column_map(const schema::table& spec) : spec_(&spec) {}

  // The field `name` is the member at `path` (member pointers, outermost first): row.*a.*b.
  template <class... Path>
  column_map& member(std::string_view name, Path... path) {
    static_assert((std::is_member_object_pointer_v<Path> && ...), "a path of member pointers");
    return field(
        name, [=](auto& r) -> auto& { return columns_detail::member_at(r, path...); });
  }
  // The field `name` is the member access(row) refers to; written and read.
  template <class Access>
  column_map& field(std::string_view name, Access access) {
    using M = std::remove_cvref_t<decltype(access(std::declval<Row&>()))>;
    return add(name, columns_detail::type_of<M>(), writer(access),
               [access](Row& r, const columns_detail::read_column& c, std::size_t i) {
                 access(r) = columns_detail::value_at<M>(c, i);
               });
  }
  // The field `name` is get(row), read back by set(row, value).
  template <class Get, class Set>
  column_map& field(std::string_view name, Get get, Set set) {
    using M = std::remove_cvref_t<decltype(get(std::declval<const Row&>()))>;
    return add(name, columns_detail::type_of<M>(), writer(get),
               [set](Row& r, const columns_detail::read_column& c, std::size_t i) {
                 set(r, columns_detail::value_at<M>(c, i));
               });
  }
  // The field `name` is get(row), derived from the row: written only.
  template <class Get>
  column_map& derived(std::string_view name, Get get) {
    using M = std::remove_cvref_t<decltype(get(std::declval<const Row&>()))>;
    return add(name, columns_detail::type_of<M>(), writer(get), nullptr);
  }
  // Every field of `inner`, bound to the member access(row) of this row.
  template <class Inner, class Access>
  column_map& fields(const column_map<Inner>& inner, Access access) {
    for (const auto& b : inner.bindings_) {
      getter get;
      if (b.get)
        get = [g = b.get, access](Row& r, const columns_detail::read_column& c, std::size_t i) { g(access(r), c, i); };
      add(
          b.name, b.type, [p = b.put, access](const Row& r, h5::column& c) { p(access(r), c); }, std::move(get));
      bindings_.back().missing = b.missing;
    }
    return *this;
  }
  // The last field, absent from files written before it was added, reads as `value`.
  column_map& missing_as(double value) {
    bindings_.back().missing = value;
    return *this;
  }

  // The rows as the schema's table (its timed-only groups when `timed`).
  h5::table table(std::span<const Row> rows, bool timed = false) const {
    h5::table t;
    std::size_t bound = 0;
    for (const auto& group : spec_->groups)
      for (const auto& f : group.fields) {
        const binding& b = find(f.name);
        ++bound;
        if (group.timed_only && !timed) continue;
        h5::column c = columns_detail::empty_column(f.type);
        for (const auto& r : rows) b.put(r, c);
        t.add(std::string(f.name), std::move(c));
      }
    if (bound != bindings_.size())
      throw std::logic_error(std::string("a column map binds a field its schema table ") + std::string(spec_->name) +
                             " lacks");
    return t;
  }
  void write(H5::Group& g, const std::string& dataset, std::span<const Row> rows, bool timed = false) const {
    table(rows, timed).write(g, dataset, *spec_);
  }

  // The rows of a table read back: every field the schema declares, of its type (a
  // timed-only group present whole or absent); fields the schema lacks (added by a newer
  // build of the same format) are left alone.
  std::vector<Row> read(const h5::table_data& t) const {
    std::vector<Row> out(t.rows());
    for (const auto& group : spec_->groups) {
      if (group.timed_only && !t.has(std::string(group.fields.front().name))) continue;
      for (const auto& f : group.fields) {
        const binding& b = find(f.name);
        if (!b.get) continue;
        const std::string name(f.name);
        if (!t.has(name) && b.missing) {
          const std::vector<double> fill(t.rows(), *b.missing);
          for (std::size_t i = 0; i < out.size(); ++i) b.get(out[i], &fill, i);
          continue;
        }
        const auto c = columns_detail::column_of(t, name, f.type);  // throws naming a missing field
        for (std::size_t i = 0; i < out.size(); ++i) b.get(out[i], c, i);
      }
    }
    return out;
  }
  std::vector<Row> read(const H5::Group& g, const std::string& dataset) const {
    if (!h5::is_dataset(g, dataset)) throw std::runtime_error("missing dataset '" + dataset + "' in " + g.getObjName());
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
  column_map& add(std::string_view name, schema::field_type type, putter put, getter get) {
    for (const auto& group : spec_->groups)
      for (const auto& f : group.fields)
        if (f.name == name) {
          if (f.type != type)
            throw std::logic_error(std::string("column ") + std::string(name) + " of table " +
                                   std::string(spec_->name) + " is bound to a member of another type");
          bindings_.push_back({f.name, type, std::move(put), std::move(get), std::nullopt});
          return *this;
        }
    throw std::logic_error(std::string("the schema's table ") + std::string(spec_->name) + " has no field " +
                           std::string(name));
  }
  const binding& find(std::string_view name) const {
    for (const auto& b : bindings_)
      if (b.name == name) return b;
    throw std::logic_error(std::string("no column bound to field ") + std::string(name) + " of table " +
                           std::string(spec_->name));
  }

  const schema::table* spec_;
  std::vector<binding> bindings_;
};

}  // namespace stepbench
