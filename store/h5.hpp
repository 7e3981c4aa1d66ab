#pragma once
// HDF5 in the shapes the study file uses (docs/study-format.md): scalar and array
// attributes, and tables (1-D compound datasets) built column by column, written and
// read by field name. Shared by the writer and every C++ reader, so the format is
// spelled in one place. Errors surface as H5::Exception; callers turn them into one line.
#include <H5Cpp.h>

#include <cstdint>
#include <map>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "store/schema.hpp"

namespace stepbench::h5 {

void attr(H5::H5Object& obj, const std::string& name, const std::string& value);
void attr(H5::H5Object& obj, const std::string& name, double value);
void attr(H5::H5Object& obj, const std::string& name, long value);
void attr(H5::H5Object& obj, const std::string& name, int value);
void attr(H5::H5Object& obj, const std::string& name, const std::vector<int>& values);
void attr(H5::H5Object& obj, const std::string& name, const std::vector<double>& values);

void dataset(H5::Group& g, const std::string& name, const std::vector<double>& v);
void dataset(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows);
// A 2-D grid for drawing (e.g. |R(z)| over the complex plane): stored as float32 with
// shuffle and deflate, a quarter of the doubles' size; readers get it converted back.
void compressed_grid(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows);

// A column of a table: f64, i64, i8 or str (variable-length strings), its index the
// schema's field type (store/schema.hpp).
using column =
    std::variant<std::vector<double>, std::vector<std::int64_t>, std::vector<std::int8_t>, std::vector<std::string>>;
inline schema::field_type type_of(const column& c) { return static_cast<schema::field_type>(c.index()); }

// A table under construction: columns of equal length, written as one compound dataset
// (packed in the file; fields in the order added).
class table {
 public:
  void add(std::string name, column values);
  // Writes the table after checking its columns against the schema's table `spec`
  // (names, order, types; a timed-only group present whole or absent): a mismatch is a
  // bug in the writer, thrown as std::logic_error before anything is written.
  void write(H5::Group& g, const std::string& dataset, const schema::table& spec) const;

 private:
  void check(const std::string& dataset, const schema::table& spec) const;
  std::vector<std::pair<std::string, column>> columns_;
};

// Readers. A file may be damaged or foreign: each dataset and attribute is checked
// (type class, sizes, a table's every field and its place in the record, rank, extent
// against the file's size) before HDF5 reads it, and one that does not hold what the
// writer writes is a std::runtime_error naming it. HDF5 is never asked to convert a type
// the file declares (a damaged compound type crashed its converter).
bool has_link(const H5::Group& g, const std::string& name);
bool is_group(const H5::Group& g, const std::string& name);
bool is_dataset(const H5::Group& g, const std::string& name);
std::vector<std::string> children(const H5::Group& g);  // link names in creation or name order

// A table read back whole, in one read: its fields in the file's order and its columns.
class table_data {
 public:
  // double; int8 or int64; variable-length string
  using values = std::variant<std::vector<double>, std::vector<std::int64_t>, std::vector<std::string>>;
  std::size_t rows() const { return rows_; }
  bool has(const std::string& field) const { return columns_.contains(field); }
  // A missing field (or one of another kind) is an error naming it and the table.
  const std::vector<double>& reals(const std::string& field) const { return column<double>(field, "real"); }
  const std::vector<std::int64_t>& ints(const std::string& field) const {
    return column<std::int64_t>(field, "integer");
  }
  const std::vector<std::string>& strings(const std::string& field) const {
    return column<std::string>(field, "string");
  }

 private:
  friend table_data read_table(const H5::DataSet& ds);
  template <class T>
  const std::vector<T>& column(const std::string& field, const char* kind) const {
    const auto it = columns_.find(field);
    const auto* column = it == columns_.end() ? nullptr : std::get_if<std::vector<T>>(&it->second);
    if (!column) throw std::runtime_error("missing " + std::string(kind) + " field '" + field + "' in " + name_);
    return *column;
  }
  std::string name_;
  std::size_t rows_ = 0;
  std::map<std::string, values> columns_;
};

table_data read_table(const H5::DataSet& ds);
std::vector<double> read_vector(const H5::DataSet& ds);  // a 1-D double dataset

// Attribute readers: throw std::runtime_error("missing attribute '<name>' on <object>",
// or "missing numeric attribute ...") when absent or of the wrong kind or shape.
std::string string_attr(const H5::H5Object& obj, const std::string& name);
double double_attr(const H5::H5Object& obj, const std::string& name);  // a float or an integer
long long_attr(const H5::H5Object& obj, const std::string& name);
std::vector<long> int_array_attr(const H5::H5Object& obj, const std::string& name);       // empty for a null dataspace
std::vector<double> double_array_attr(const H5::H5Object& obj, const std::string& name);  // a number array
// Every attribute of obj that holds one string, or one number (floats only, or integers
// too), by name; attributes of other kinds are skipped, damaged ones refused.
std::map<std::string, std::string> string_attrs(const H5::H5Object& obj);
std::map<std::string, double> number_attrs(const H5::H5Object& obj, bool floats_only);

}  // namespace stepbench::h5
