#include "store/columns.hpp"

namespace stepbench::columns_detail {

h5::column empty_column(schema::field_type type) {
  static const h5::column empty[] = {std::vector<double>{}, std::vector<std::int64_t>{}, std::vector<std::int8_t>{},
                                     std::vector<std::string>{}};  // in field_type's order, as h5::column's
  return empty[static_cast<int>(type)];
}

read_column column_of(const h5::table_data& t, const std::string& field, schema::field_type type) {
  if (type == schema::field_type::f64) return &t.reals(field);
  if (type == schema::field_type::str) return &t.strings(field);
  return &t.ints(field);  // i64 or i8
}

}  // namespace stepbench::columns_detail
