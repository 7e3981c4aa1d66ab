#include "store/h5.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <memory>
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
template <class T>
static void array_attr(H5::H5Object& obj, const std::string& name, const std::vector<T>& values,
                       const H5::PredType& type) {
  const hsize_t n = values.size();
  auto a = obj.createAttribute(name, type, n ? H5::DataSpace(1, &n) : H5::DataSpace(H5S_NULL));
  if (n) a.write(type, values.data());
}
void attr(H5::H5Object& obj, const std::string& name, const std::vector<int>& values) {
  array_attr(obj, name, values, H5::PredType::NATIVE_INT);
}
void attr(H5::H5Object& obj, const std::string& name, const std::vector<double>& values) {
  array_attr(obj, name, values, H5::PredType::NATIVE_DOUBLE);
}

void dataset(H5::Group& g, const std::string& name, const std::vector<double>& v) {
  const hsize_t n = v.size();
  g.createDataSet(name, H5::PredType::NATIVE_DOUBLE, H5::DataSpace(1, &n)).write(v.data(), H5::PredType::NATIVE_DOUBLE);
}
// A 2-D dataset of `rows`, stored as `type` (converted from double), chunked and deflated when `compressed`.
static void write_grid(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows,
                       const H5::PredType& type, bool compressed) {
  const hsize_t dims[2] = {rows.size(), rows.empty() ? 0 : rows.front().size()};
  std::vector<double> flat;
  for (const auto& r : rows) flat.insert(flat.end(), r.begin(), r.end());
  H5::DSetCreatPropList props;
  if (compressed) {
    props.setChunk(2, dims);
    props.setShuffle();
    props.setDeflate(6);
  }
  g.createDataSet(name, type, H5::DataSpace(2, dims), compressed ? props : H5::DSetCreatPropList::DEFAULT)
      .write(flat.data(), H5::PredType::NATIVE_DOUBLE);
}
void dataset(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows) {
  write_grid(g, name, rows, H5::PredType::NATIVE_DOUBLE, false);
}
void compressed_grid(H5::Group& g, const std::string& name, const std::vector<std::vector<double>>& rows) {
  write_grid(g, name, rows, H5::PredType::IEEE_F32LE, true);
}

void table::add(std::string name, column values) { columns_.emplace_back(std::move(name), std::move(values)); }

void table::check(const std::string& name, const schema::table& spec) const {
  std::size_t c = 0;
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
    // In the memory record, in h5::column's order of types: a string as its char*.
    constexpr std::size_t sizes[] = {sizeof(double), sizeof(std::int64_t), sizeof(std::int8_t), sizeof(const char*)};
    const std::size_t size = sizes[col.index()];
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

std::vector<std::string> children(const H5::Group& g) {
  std::vector<std::string> out;
  for (hsize_t i = 0; i < g.getNumObjs(); ++i) out.push_back(g.getObjnameByIdx(i));
  return out;
}

namespace {

// The size of the file holding obj: no dataset or attribute of a whole file holds more
// bytes than the file, so a larger extent is damage, refused before memory is sized by it.
hsize_t file_size(const H5::H5Object& obj) {
  const hid_t file = H5Iget_file_id(obj.getId());
  if (file < 0) throw std::runtime_error(fmt::format("cannot find the file of {}", object_name(obj)));
  hsize_t size = 0;
  const herr_t status = H5Fget_filesize(file, &size);
  H5Fclose(file);  // only the reference H5Iget_file_id took
  if (status < 0) throw std::runtime_error(fmt::format("cannot size the file of {}", object_name(obj)));
  return size;
}

// The number types the writer uses. A stored type is read only when it equals one of
// them: a damaged type (a float with a bogus exponent field, an integer of 3 bytes) is
// refused instead of handed to HDF5's converters.
bool is_known_number(const H5::DataType& t) {
  for (const H5::PredType* known :
       {&H5::PredType::NATIVE_DOUBLE, &H5::PredType::NATIVE_FLOAT, &H5::PredType::NATIVE_INT8,
        &H5::PredType::NATIVE_INT16, &H5::PredType::NATIVE_INT32, &H5::PredType::NATIVE_INT64,
        &H5::PredType::NATIVE_UINT8, &H5::PredType::NATIVE_UINT16, &H5::PredType::NATIVE_UINT32,
        &H5::PredType::NATIVE_UINT64})
    if (t == *known) return true;
  return false;
}

bool is_vlen_string(const H5::DataType& t) {
  return t.getClass() == H5T_STRING && H5Tis_variable_str(t.getId()) > 0 && t.getSize() == sizeof(char*);
}

// The number of elements of a 1-D dataspace whose n * element_size bytes fit in a file
// of file_bytes; throws naming `what` otherwise.
hsize_t checked_extent(const H5::DataSpace& space, std::size_t element_size, hsize_t file_bytes,
                       const std::string& what) {
  if (space.getSimpleExtentType() != H5S_SIMPLE || space.getSimpleExtentNdims() != 1)
    throw std::runtime_error(fmt::format("{} is not one-dimensional", what));
  hsize_t n = 0;
  space.getSimpleExtentDims(&n);
  if (element_size == 0 || n > file_bytes / element_size)
    throw std::runtime_error(fmt::format("{} claims {} elements, more than its file holds", what, n));
  return n;
}

// A field of a table as the reader takes it from the raw record.
struct member {
  std::string name;
  table_data::values kind;  // its column, empty
  std::size_t offset, size;
};

// The fields of a table's stored record type, checked: each a double, an int8 or int64,
// or a variable-length string, named once, lying inside the record and overlapping no
// other. (HDF5 hands back the record as laid out in memory, strings as char*; the
// layout on disk is the same up to the strings' sizes, so damage to it shows here.)
std::vector<member> checked_members(const H5::CompType& type, const std::string& what) {
  const std::size_t record = type.getSize();
  const int count = type.getNmembers();
  if (record == 0 || count <= 0) throw std::runtime_error(fmt::format("{} has an empty record type", what));
  std::vector<member> out;
  for (int i = 0; i < count; ++i) {
    const std::string name = type.getMemberName(static_cast<unsigned>(i));
    const H5::DataType t = type.getMemberDataType(static_cast<unsigned>(i));
    const std::size_t offset = type.getMemberOffset(static_cast<unsigned>(i)), size = t.getSize();
    table_data::values kind;
    if (t == H5::PredType::NATIVE_DOUBLE)
      kind = std::vector<double>{};
    else if (t == H5::PredType::NATIVE_INT64 || t == H5::PredType::NATIVE_INT8)
      kind = std::vector<std::int64_t>{};
    else if (is_vlen_string(t))
      kind = std::vector<std::string>{};
    else
      throw std::runtime_error(fmt::format("{}: field '{}' is of a type this reader does not read", what, name));
    if (offset > record || size > record - offset)
      throw std::runtime_error(fmt::format("{}: field '{}' lies outside its {}-byte record", what, name, record));
    if (std::any_of(out.begin(), out.end(), [&](const member& m) { return m.name == name; }))
      throw std::runtime_error(fmt::format("{}: field '{}' appears twice", what, name));
    out.push_back({name, kind, offset, size});
  }
  std::vector<const member*> by_offset;
  for (const auto& m : out) by_offset.push_back(&m);
  std::sort(by_offset.begin(), by_offset.end(), [](auto* a, auto* b) { return a->offset < b->offset; });
  for (std::size_t i = 1; i < by_offset.size(); ++i)
    if (by_offset[i - 1]->offset + by_offset[i - 1]->size > by_offset[i]->offset)
      throw std::runtime_error(
          fmt::format("{}: fields '{}' and '{}' overlap", what, by_offset[i - 1]->name, by_offset[i]->name));
  return out;
}

// The allocator of the strings a table read returns: a damaged length (stored beside the
// string, unchecked by HDF5) would have it allocate and fill gigabytes; no string of a
// file is longer than the file, so a longer one fails the read instead.
void* bounded_malloc(std::size_t size, void* longest) {
  return size <= *static_cast<const hsize_t*>(longest) ? std::malloc(size) : nullptr;
}
void release(void* p, void*) { std::free(p); }

template <class T>
T at(const unsigned char* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

}  // namespace

table_data read_table(const H5::DataSet& ds) {
  table_data out;
  out.name_ = object_name(ds);
  if (ds.getTypeClass() != H5T_COMPOUND) throw std::runtime_error(fmt::format("{} is not a table", out.name_));
  // The stored record type as HDF5 lays it out in memory (variable-length strings as
  // char*), checked, then the whole dataset read into it once: no conversion between
  // record types, one pass over the file.
  const H5::CompType type = ds.getCompType();
  const auto members = checked_members(type, out.name_);
  const H5::DataSpace space = ds.getSpace();
  const std::size_t record = type.getSize();
  out.rows_ = checked_extent(space, record, file_size(ds), out.name_);
  // Every field has its column, empty in a table of no rows (a shard without points).
  for (const auto& m : members) out.columns_.emplace(m.name, m.kind);
  if (out.rows_ == 0) return out;
  std::vector<unsigned char> raw(out.rows_ * record, 0);
  // HDF5 converts through a buffer of 1 MiB by default, allocated and freed on each read:
  // glibc handed it back to the system and faulted it in again every time (73,000 page
  // faults reading a full study, most of its time). Room for the disk records instead, at
  // most twice the memory ones (a string's heap ID is 16 bytes, its char* 8).
  H5::DSetMemXferPropList sized;
  sized.setBuffer(2 * raw.size(), nullptr, nullptr);
  hsize_t longest = file_size(ds);
  sized.setVlenMemManager(bounded_malloc, &longest, release, nullptr);
  {
    // HDF5 allocates the strings of a read; this hands them back however the read ended.
    const auto reclaim = [&](void* buffer) { H5Dvlen_reclaim(type.getId(), space.getId(), sized.getId(), buffer); };
    const std::unique_ptr<void, decltype(reclaim)> strings(raw.data(), reclaim);
    ds.read(raw.data(), type, H5::DataSpace::ALL, H5::DataSpace::ALL, sized);
    for (const auto& m : members)
      std::visit(
          [&]<class T>(std::vector<T>& column) {
            for (std::size_t r = 0; r < out.rows_; ++r) {
              const unsigned char* p = raw.data() + r * record + m.offset;
              if constexpr (std::is_same_v<T, std::string>) {
                const char* s = at<const char*>(p);
                column.emplace_back(s ? s : "");
              } else if constexpr (std::is_same_v<T, std::int64_t>) {
                column.push_back(m.size == 1 ? at<std::int8_t>(p) : at<std::int64_t>(p));
              } else {
                column.push_back(at<double>(p));
              }
            }
          },
          out.columns_.at(m.name));
  }
  return out;
}

std::vector<double> read_vector(const H5::DataSet& ds) {
  const std::string what = object_name(ds);
  if (ds.getDataType() != H5::PredType::NATIVE_DOUBLE)
    throw std::runtime_error(fmt::format("{} is not a dataset of doubles", what));
  std::vector<double> out(checked_extent(ds.getSpace(), sizeof(double), file_size(ds), what));
  if (!out.empty()) ds.read(out.data(), H5::PredType::NATIVE_DOUBLE);
  return out;
}

namespace {

enum class attr_kind { string, number, integer };

// Whether attribute a holds what `kind` reads: a string (variable-length, or fixed and
// no longer than the file), or a number of a type this reader knows (an integer one for
// `integer`).
bool holds(const H5::Attribute& a, attr_kind kind, hsize_t file_bytes) {
  const H5::DataType t = a.getDataType();
  switch (kind) {
    case attr_kind::string:
      return t.getClass() == H5T_STRING && (is_vlen_string(t) || t.getSize() <= file_bytes);
    case attr_kind::number:
      return is_known_number(t);
    case attr_kind::integer:
      return t.getClass() == H5T_INTEGER && is_known_number(t);
  }
  return false;
}

bool holds_one(const H5::Attribute& a) {
  const H5::DataSpace space = a.getSpace();
  return space.getSimpleExtentType() != H5S_NULL && space.getSimpleExtentNpoints() == 1;
}

const char* kind_name(attr_kind kind) {
  constexpr const char* names[] = {"string", "numeric", "integer"};  // in attr_kind's order
  return names[static_cast<int>(kind)];
}

// The attribute `name` of obj, checked to hold what `kind` reads (one value unless `one` is false).
H5::Attribute checked_attr(const H5::H5Object& obj, const std::string& name, attr_kind kind, bool one = true) {
  if (!obj.attrExists(name)) missing(obj, fmt::format("attribute '{}'", name));
  H5::Attribute a = obj.openAttribute(name);
  if (!holds(a, kind, file_size(obj)) || (one && !holds_one(a)))
    missing(obj, fmt::format("{} attribute '{}'", kind_name(kind), name));
  return a;
}

std::string read_string(const H5::Attribute& a) {
  std::string value;
  a.read(a.getStrType(), value);
  return value;
}

double read_double(const H5::Attribute& a) {
  double v = 0;
  a.read(H5::PredType::NATIVE_DOUBLE, &v);
  return v;
}

// Every attribute of obj holding one value of a class `wanted` accepts, checked as
// `kind` and read by `read`; attributes of other classes or shapes are skipped.
template <class T, class Read>
std::map<std::string, T> scan_attrs(const H5::H5Object& obj, bool (*wanted)(H5T_class_t), attr_kind kind, Read read) {
  std::map<std::string, T> out;
  const hsize_t file_bytes = file_size(obj);
  for (int i = 0; i < obj.getNumAttrs(); ++i) {
    const H5::Attribute a = obj.openAttribute(static_cast<unsigned>(i));
    if (!wanted(a.getTypeClass()) || !holds_one(a)) continue;
    const std::string name = a.getName();
    if (!holds(a, kind, file_bytes)) missing(obj, fmt::format("{} attribute '{}'", kind_name(kind), name));
    out[name] = read(a);
  }
  return out;
}

}  // namespace

std::string string_attr(const H5::H5Object& obj, const std::string& name) {
  return read_string(checked_attr(obj, name, attr_kind::string));
}
double double_attr(const H5::H5Object& obj, const std::string& name) {
  return read_double(checked_attr(obj, name, attr_kind::number));
}
long long_attr(const H5::H5Object& obj, const std::string& name) {
  const H5::Attribute a = checked_attr(obj, name, attr_kind::integer);
  std::int64_t v = 0;
  a.read(H5::PredType::NATIVE_INT64, &v);
  return static_cast<long>(v);
}
// The array attribute `name` of obj, checked as `kind` and read as `type` (empty for a null dataspace).
template <class T>
static std::vector<T> read_array_attr(const H5::H5Object& obj, const std::string& name, attr_kind kind,
                                      const H5::PredType& type) {
  const H5::Attribute a = checked_attr(obj, name, kind, false);
  const H5::DataSpace space = a.getSpace();
  if (space.getSimpleExtentType() == H5S_NULL) return {};
  const std::string what = fmt::format("attribute '{}' on {}", name, object_name(obj));
  std::vector<T> out(checked_extent(space, a.getDataType().getSize(), file_size(obj), what));
  if (!out.empty()) a.read(type, out.data());
  return out;
}
std::vector<long> int_array_attr(const H5::H5Object& obj, const std::string& name) {
  const auto raw = read_array_attr<std::int64_t>(obj, name, attr_kind::integer, H5::PredType::NATIVE_INT64);
  return {raw.begin(), raw.end()};
}
std::vector<double> double_array_attr(const H5::H5Object& obj, const std::string& name) {
  return read_array_attr<double>(obj, name, attr_kind::number, H5::PredType::NATIVE_DOUBLE);
}

std::map<std::string, std::string> string_attrs(const H5::H5Object& obj) {
  return scan_attrs<std::string>(
      obj, [](H5T_class_t c) { return c == H5T_STRING; }, attr_kind::string, read_string);
}
std::map<std::string, double> number_attrs(const H5::H5Object& obj, bool floats_only) {
  const auto wanted = floats_only ? +[](H5T_class_t c) { return c == H5T_FLOAT; }
                                  : +[](H5T_class_t c) { return c == H5T_FLOAT || c == H5T_INTEGER; };
  return scan_attrs<double>(obj, wanted, attr_kind::number, read_double);
}

}  // namespace stepbench::h5
