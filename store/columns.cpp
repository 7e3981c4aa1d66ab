#include "store/columns.hpp"

namespace stepbench::columns_detail {

h5::column empty_column(schema::field_type type) {
  static const h5::column empty[] = {std::vector<double>{}, std::vector<std::int64_t>{}, std::vector<std::int8_t>{},
                                     std::vector<std::string>{}};  // in field_type's order, as h5::column's
  return empty[static_cast<int>(type)];
}

read_column column_of(const h5::table_data& t, const std::string& field, schema::field_type type) {
  switch (type) {
    case schema::field_type::f64:
      return &t.reals(field);
    case schema::field_type::i64:
    case schema::field_type::i8:
      return &t.ints(field);
    case schema::field_type::str:
      break;
  }
  return &t.strings(field);
}

}  // namespace stepbench::columns_detail
