#include "study/h5.hpp"

#include <fmt/format.h>

#include <cstring>
#include <stdexcept>

namespace stepbench::h5 {
namespace {

H5::StrType vlen_string() { return H5::StrType(H5::PredType::C_S1, H5T_VARIABLE); }

std::string object_name(const H5::H5Object& obj) {
  try {
    return obj.getObjName();
  } catch (const H5::Exception&) {
    return "?";
  }
}

[[noreturn]] void missing(const H5::H5Object& obj, const std::string& what) {
  throw std::runtime_error(fmt::format("missing {} on {}", what, object_name(obj)));
}

}  // namespace

void attr(H5::H5Object& obj, const std::string& name, const std::string& value) {
  const H5::StrType type = vlen_string();
  obj.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}
void attr(H5::H5Object& obj, const std::string& name, const char* value) { attr(obj, name, std::string(value)); }
void attr(H5::H5Object& obj, const std::string& name, double value) {
  obj.createAttribute(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_DOUBLE, &value);
}
void attr(H5::H5Object& obj, const std::string& name, long value) {
  const std::int64_t v = value;
  obj.createAttribute(name, H5::PredType::NATIVE_INT64, H5::DataSpace(H5S_SCALAR))
      .write(H5::PredType::NATIVE_INT64, &v);
}
void attr(H5::H5Object& obj, const std::string& name, int value) { attr(obj, name, static_cast<long>(value)); }
void attr(H5::H5Object& obj, const std::string& name, const std::vector<int>& values) {
  const hsize_t n = values.size();
  H5::DataSpace space = n ? H5::DataSpace(1, &n) : H5::DataSpace(H5S_NULL);
  auto a = obj.createAttribute(name, H5::PredType::NATIVE_INT, space);
  if (n) a.write(H5::PredType::NATIVE_INT, values.data());
}
void attr(H5::H5Object& obj, const std::string& name, const std::vector<double>& values) {
  const hsize_t n = values.size();
  H5::DataSpace space = n ? H5::DataSpace(1, &n) : H5::DataSpace(H5S_NULL);
  auto a = obj.createAttribute(name, H5::PredType::NATIVE_DOUBLE, space);
  if (n) a.write(H5::PredType::NATIVE_DOUBLE, values.data());
}

void dataset(H5::Group& g, const std::string& name, const std::vector<double>& v) {
  const hsize_t n = v.size();
  g.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &n)).write(v.data(), H5::PredType::NATIVE_DOUBLE);
}
void dataset(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows) {
  const hsize_t dims[2] = {rows.size(), rows.empty() ? 0 : rows.front().size()};
  std::vector<double> flat;
  for (const auto& r : rows) flat.insert(flat.end(), r.begin(), r.end());
  g.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(2, dims))
      .write(flat.data(), H5::PredType::NATIVE_DOUBLE);
}

void compressed_grid(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows) {
  const hsize_t dims[2] = {rows.size(), rows.empty() ? 0 : rows.front().size()};
  std::vector<double> flat;
  for (const auto& r : rows) flat.insert(flat.end(), r.begin(), r.end());
  H5::DSetCreatPropList props;
  props.setChunk(2, dims);
  props.setShuffle();
  props.setDeflate(6);
  g.createDataSet(name, H5::PredType::IEEE_F32LE, H5::DataSpace(2, dims), props)
      .write(flat.data(), H5::PredType::NATIVE_DOUBLE);
}

void table::add(std::string name, std::vector<double> values) {
  columns_.emplace_back(std::move(name), std::move(values));
}
void table::add(std::string name, std::vector<std::int64_t> values) {
  columns_.emplace_back(std::move(name), std::move(values));
}
void table::add(std::string name, std::vector<std::int8_t> values) {
  columns_.emplace_back(std::move(name), std::move(values));
}
void table::add(std::string name, std::vector<std::string> values) {
  columns_.emplace_back(std::move(name), std::move(values));
}

void table::check(const std::string& name, const schema::table& spec) const {
  std::size_t c = 0;
  auto type_of = [](const column& col) {
    return std::visit(
        [](const auto& v) {
          using T = typename std::decay_t<decltype(v)>::value_type;
          if constexpr (std::is_same_v<T, double>) return schema::field_type::f64;
          if constexpr (std::is_same_v<T, std::int64_t>) return schema::field_type::i64;
          if constexpr (std::is_same_v<T, std::int8_t>) return schema::field_type::i8;
          return schema::field_type::str;
        },
        col);
  };
  for (const auto& group : spec.groups) {
    const bool present = c < columns_.size() && columns_[c].first == group.fields.front().name;
    if (!present && group.timed_only) continue;
    for (const auto& f : group.fields) {
      if (c >= columns_.size() || columns_[c].first != f.name || type_of(columns_[c].second) != f.type)
        throw std::logic_error(fmt::format("table {}: column {} is not the schema's {} ({}) of table {}", name,
                                           c < columns_.size() ? columns_[c].first : "(none)", f.name,
                                           schema::to_string(f.type), spec.name));
      ++c;
    }
  }
  if (c != columns_.size())
    throw std::logic_error(
        fmt::format("table {}: column {} is not in the schema's table {}", name, columns_[c].first, spec.name));
}

void table::write(H5::Group& g, const std::string& name, const schema::table& spec) const {
  check(name, spec);
  std::size_t rows = 0, width = 0;
  std::vector<std::size_t> offset;
  for (const auto& [col_name, col] : columns_) {
    const std::size_t n = std::visit([](const auto& v) { return v.size(); }, col);
    if (!offset.empty() && n != rows)
      throw std::logic_error(fmt::format("table {}: column {} has {} rows, not {}", name, col_name, n, rows));
    rows = n;
    const std::size_t size = std::visit(
        [](const auto& v) -> std::size_t {
          using T = typename std::decay_t<decltype(v)>::value_type;
          if constexpr (std::is_same_v<T, std::string>)
            return sizeof(const char*);
          else
            return sizeof(T);
        },
        col);
    width = (width + size - 1) / size * size;  // natural alignment in memory
    offset.push_back(width);
    width += size;
  }
  width = (width + 7) / 8 * 8;
  H5::CompType memory(width);
  std::vector<unsigned char> buffer(std::max<std::size_t>(1, rows * width));
  for (std::size_t c = 0; c < columns_.size(); ++c) {
    const auto& [col_name, col] = columns_[c];
    std::visit(
        [&](const auto& v) {
          using T = typename std::decay_t<decltype(v)>::value_type;
          if constexpr (std::is_same_v<T, std::string>) {
            memory.insertMember(col_name, offset[c], vlen_string());
            for (std::size_t r = 0; r < rows; ++r) {
              const char* p = v[r].c_str();
              std::memcpy(buffer.data() + r * width + offset[c], &p, sizeof p);
            }
          } else {
            const H5::PredType& type = std::is_same_v<T, double>         ? H5::PredType::NATIVE_DOUBLE
                                       : std::is_same_v<T, std::int64_t> ? H5::PredType::NATIVE_INT64
                                                                         : H5::PredType::NATIVE_INT8;
            memory.insertMember(col_name, offset[c], type);
            for (std::size_t r = 0; r < rows; ++r) std::memcpy(buffer.data() + r * width + offset[c], &v[r], sizeof(T));
          }
        },
        col);
  }
  H5::CompType file_type;  // a copy (H5Tcopy): CompType's copy constructor shares the id
  file_type.copy(memory);
  file_type.pack();
  const hsize_t n = rows;
  g.createDataSet(name, file_type, H5::DataSpace(1, &n)).write(buffer.data(), memory);
}

bool has_link(const H5::Group& g, const std::string& name) {
  return H5Lexists(g.getId(), name.c_str(), H5P_DEFAULT) > 0;
}
bool is_group(const H5::Group& g, const std::string& name) {
  return has_link(g, name) && g.childObjType(name) == H5O_TYPE_GROUP;
}
bool is_dataset(const H5::Group& g, const std::string& name) {
  return has_link(g, name) && g.childObjType(name) == H5O_TYPE_DATASET;
}

bool has_field(const H5::DataSet& ds, const std::string& field) {
  if (ds.getTypeClass() != H5T_COMPOUND) return false;
  const H5::CompType t = ds.getCompType();
  for (int i = 0; i < t.getNmembers(); ++i)
    if (t.getMemberName(i) == field) return true;
  return false;
}

std::vector<std::string> children(const H5::Group& g) {
  std::vector<std::string> out;
  for (hsize_t i = 0; i < g.getNumObjs(); ++i) out.push_back(g.getObjnameByIdx(i));
  return out;
}

namespace {
// One field of a compound dataset, converted by HDF5 to T (fields are matched by name,
// so the reader depends neither on the writer's layout nor on the other fields).
template <class T>
std::vector<T> read_field(const H5::DataSet& ds, const std::string& field, const H5::DataType& type) {
  if (!has_field(ds, field)) missing(ds, fmt::format("field '{}'", field));
  const hssize_t n = ds.getSpace().getSimpleExtentNpoints();
  std::vector<T> out(static_cast<std::size_t>(n));
  if (n == 0) return out;
  H5::CompType mem(sizeof(T));
  mem.insertMember(field, 0, type);
  ds.read(out.data(), mem);
  return out;
}
}  // namespace

std::vector<double> read_doubles(const H5::DataSet& ds, const std::string& field) {
  return read_field<double>(ds, field, H5::PredType::NATIVE_DOUBLE);
}
std::vector<std::int64_t> read_ints(const H5::DataSet& ds, const std::string& field) {
  return read_field<std::int64_t>(ds, field, H5::PredType::NATIVE_INT64);
}
std::vector<std::string> read_strings(const H5::DataSet& ds, const std::string& field) {
  if (!has_field(ds, field)) missing(ds, fmt::format("field '{}'", field));
  const hssize_t n = ds.getSpace().getSimpleExtentNpoints();
  std::vector<char*> raw(static_cast<std::size_t>(n), nullptr);
  std::vector<std::string> out;
  if (n == 0) return out;
  H5::CompType mem(sizeof(char*));
  mem.insertMember(field, 0, vlen_string());
  ds.read(raw.data(), mem);
  for (char* p : raw) out.emplace_back(p ? p : "");
  H5::DataSet::vlenReclaim(raw.data(), mem, ds.getSpace());
  return out;
}
std::vector<double> read_vector(const H5::DataSet& ds) {
  const hssize_t n = ds.getSpace().getSimpleExtentNpoints();
  std::vector<double> out(static_cast<std::size_t>(n));
  if (n) ds.read(out.data(), H5::PredType::NATIVE_DOUBLE);
  return out;
}

std::string string_attr(const H5::H5Object& obj, const std::string& name) {
  if (!obj.attrExists(name)) missing(obj, fmt::format("attribute '{}'", name));
  const H5::Attribute a = obj.openAttribute(name);
  if (a.getTypeClass() != H5T_STRING) missing(obj, fmt::format("string attribute '{}'", name));
  std::string value;
  a.read(a.getStrType(), value);
  return value;
}
double double_attr(const H5::H5Object& obj, const std::string& name) {
  if (!obj.attrExists(name)) missing(obj, fmt::format("attribute '{}'", name));
  const H5::Attribute a = obj.openAttribute(name);
  const auto cls = a.getTypeClass();
  if ((cls != H5T_FLOAT && cls != H5T_INTEGER) || a.getSpace().getSimpleExtentNpoints() != 1)
    missing(obj, fmt::format("numeric attribute '{}'", name));
  double v = 0;
  a.read(H5::PredType::NATIVE_DOUBLE, &v);
  return v;
}
long long_attr(const H5::H5Object& obj, const std::string& name) {
  if (!obj.attrExists(name)) missing(obj, fmt::format("attribute '{}'", name));
  const H5::Attribute a = obj.openAttribute(name);
  if (a.getTypeClass() != H5T_INTEGER || a.getSpace().getSimpleExtentNpoints() != 1)
    missing(obj, fmt::format("integer attribute '{}'", name));
  std::int64_t v = 0;
  a.read(H5::PredType::NATIVE_INT64, &v);
  return static_cast<long>(v);
}
std::vector<long> int_array_attr(const H5::H5Object& obj, const std::string& name) {
  if (!obj.attrExists(name)) missing(obj, fmt::format("attribute '{}'", name));
  const H5::Attribute a = obj.openAttribute(name);
  if (a.getTypeClass() != H5T_INTEGER) missing(obj, fmt::format("integer attribute '{}'", name));
  const H5::DataSpace space = a.getSpace();
  if (space.getSimpleExtentType() == H5S_NULL) return {};
  std::vector<std::int64_t> raw(static_cast<std::size_t>(space.getSimpleExtentNpoints()));
  if (!raw.empty()) a.read(H5::PredType::NATIVE_INT64, raw.data());
  return {raw.begin(), raw.end()};
}

}  // namespace stepbench::h5
