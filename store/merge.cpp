#include "store/merge.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <stdexcept>

#include "core/text.hpp"
#include "run/machine.hpp"
#include "store/columns.hpp"
#include "store/h5.hpp"
#include "store/schema.hpp"
#include "store/study_file.hpp"

namespace stepbench {
namespace {

bool has_attr(const H5::H5Object& obj, const std::string& name) { return H5Aexists(obj.getId(), name.c_str()) > 0; }

void check(herr_t status, const char* what) {
  if (status < 0) throw std::runtime_error(fmt::format("HDF5: {} failed", what));
}

// Copies one attribute as the file stores it (type and shape), replacing one of the same
// name on `dst`.
void copy_attr(hid_t src, hid_t dst, const char* name) {
  const hid_t a = H5Aopen(src, name, H5P_DEFAULT);
  check(a, "H5Aopen");
  const hid_t ftype = H5Aget_type(a), space = H5Aget_space(a);
  const hid_t mtype = H5Tget_native_type(ftype, H5T_DIR_DEFAULT);
  const hssize_t n = H5Sget_simple_extent_npoints(space);
  std::vector<unsigned char> buf(
      std::max<std::size_t>(1, static_cast<std::size_t>(std::max<hssize_t>(n, 0)) * H5Tget_size(mtype)));
  const bool variable = H5Tdetect_class(mtype, H5T_VLEN) > 0 || H5Tis_variable_str(mtype) > 0;
  herr_t status = n > 0 ? H5Aread(a, mtype, buf.data()) : 0;
  if (status >= 0 && H5Aexists(dst, name) > 0) status = H5Adelete(dst, name);
  hid_t b = -1;
  if (status >= 0) {
    b = H5Acreate2(dst, name, ftype, space, H5P_DEFAULT, H5P_DEFAULT);
    if (b < 0) status = -1;
  }
  if (status >= 0 && n > 0) status = H5Awrite(b, mtype, buf.data());
  if (variable && n > 0) H5Dvlen_reclaim(mtype, space, H5P_DEFAULT, buf.data());
  if (b >= 0) H5Aclose(b);
  H5Tclose(mtype);
  H5Tclose(ftype);
  H5Sclose(space);
  H5Aclose(a);
  check(status, "copying an attribute");
}

herr_t copy_attr_cb(hid_t loc, const char* name, const H5A_info_t*, void* dst) {
  copy_attr(loc, *static_cast<hid_t*>(dst), name);
  return 0;
}

// Every attribute of `src` onto `dst`.
void copy_attrs(const H5::H5Object& src, H5::H5Object& dst) {
  hid_t to = dst.getId();
  hsize_t idx = 0;
  check(H5Aiterate2(src.getId(), H5_INDEX_NAME, H5_ITER_INC, &idx, copy_attr_cb, &to), "H5Aiterate2");
}

template <class T>
void replace_attr(H5::H5Object& obj, const std::string& name, const T& value) {
  if (has_attr(obj, name)) obj.removeAttr(name);
  h5::attr(obj, name, value);
}

// The object at `path` in `src`, copied whole (attributes, datasets, subgroups) to the
// same path in `dst`.
void copy_object(const H5::H5File& src, H5::H5File& dst, const std::string& path) {
  if (H5Ocopy(src.getId(), path.c_str(), dst.getId(), path.c_str(), H5P_DEFAULT, H5P_DEFAULT) < 0)
    throw std::runtime_error(
        fmt::format("cannot copy /{} from study shard '{}': HDF5: H5Ocopy failed (truncated or corrupt?)", path,
                    src.getFileName()));
}

struct shard_file {
  std::string path;
  H5::H5File file;
  held_shards held;
  std::string selection, options;
  std::vector<std::pair<std::string, std::string>> timing;  // the timing settings, as text
  std::vector<std::string> problems;
  double wall_seconds = 0.0, benchmark_wall_seconds = 0.0;
};

shard_file open_shard(const std::string& path) {
  shard_file s;
  s.path = path;
  s.file.openFile(path, H5F_ACC_RDONLY);
  const auto& f = s.file;
  // A partial merge holds the shards it was merged from; a shard or a whole study its own.
  if (has_attr(f, "merged_shards")) {
    s.held.indices = h5::int_array_attr(f, "merged_shards");
    s.held.count = h5::long_attr(f, "merged_shard_count");
  } else {
    s.held.indices = {h5::long_attr(f, "shard_index")};
    s.held.count = h5::long_attr(f, "shard_count");
  }
  std::set<long> seen;
  for (long k : s.held.indices)
    if (k < 0 || k >= s.held.count || !seen.insert(k).second)
      throw std::runtime_error(fmt::format("it says it holds shard {} of {}", k + 1, s.held.count));
  if (s.held.indices.empty()) throw std::runtime_error("its merged_shards is empty");
  std::sort(s.held.indices.begin(), s.held.indices.end());
  s.selection = h5::string_attr(f, "selection");
  s.options = h5::string_attr(f, "sweep_options");
  s.wall_seconds = h5::double_attr(f, "wall_seconds");
  const long timed = h5::long_attr(f, "timing");
  s.timing.emplace_back("timing", timed ? "timed" : "untimed");
  if (timed) {
    s.timing.emplace_back("benchmark mode", h5::string_attr(f, "benchmark_mode"));
    s.timing.emplace_back("benchmark min time", fmt::format("{} s", h5::double_attr(f, "benchmark_min_time_s")));
    s.timing.emplace_back("benchmark repetitions", fmt::format("{}", h5::long_attr(f, "benchmark_repetitions")));
    s.timing.emplace_back("case budget", fmt::format("{} s", h5::double_attr(f, "benchmark_case_budget_s")));
    s.benchmark_wall_seconds = h5::double_attr(f, "benchmark_wall_seconds");
  }
  if (h5::is_group(f, "problems")) s.problems = h5::children(f.openGroup("problems"));
  s.held.problems = s.problems.size();
  return s;
}

// read() with its HDF5 and runtime errors as one line: "<failing>: <error>".
template <class Read>
auto one_line_errors(const std::string& failing, Read read) {
  H5::Exception::dontPrint();
  try {
    return read();
  } catch (const H5::Exception& e) {
    throw std::runtime_error(fmt::format("{}: {}", failing, e.getDetailMsg()));
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("{}: {}", failing, e.what()));
  }
}

// open_shard with its errors as one line naming the file.
shard_file read_shard(const std::string& path) {
  return one_line_errors(fmt::format("cannot read study shard '{}'", path), [&] { return open_shard(path); });
}

// The first line where two `sweep_options` texts differ, from each.
std::pair<std::string, std::string> first_difference(const std::string& a, const std::string& b) {
  const auto la = stored_list(a, '\n'), lb = stored_list(b, '\n');
  for (std::size_t i = 0; i < std::max(la.size(), lb.size()); ++i) {
    const std::string x = i < la.size() ? la[i] : "(none)", y = i < lb.size() ? lb[i] : "(none)";
    if (x != y) return {x, y};
  }
  return {a, b};
}

// A study-level table (/verdict/<name>), a row per problem, joined from the shards in the
// study's problem order, each problem's rows in its shard's order; fields by the schema.
void join_table(const std::vector<shard_file>& shards, H5::Group& dst, const std::string& where,
                const std::string& name, const schema::table& spec, const std::vector<std::string>& order) {
  // An optional table (schema::table::optional) is joined from the shards that have it: a
  // shard without its rows (no problem, or none a plugin's method ran on) has none.
  std::vector<h5::table_data> parts;
  std::vector<const shard_file*> from;  // the shard of each part
  for (const auto& s : shards)
    if (!spec.optional || h5::is_dataset(s.file.openGroup(where), name)) {
      parts.push_back(h5::read_table(s.file.openDataSet(where + "/" + name)));
      from.push_back(&s);
    }
  if (parts.empty()) return;
  std::map<std::string, std::size_t> rank;
  for (std::size_t i = 0; i < order.size(); ++i) rank[order[i]] = i;
  std::vector<std::tuple<std::size_t, std::size_t, std::size_t>> rows;  // (problem rank, part, row)
  for (std::size_t k = 0; k < parts.size(); ++k) {
    const auto& problem = parts[k].strings("problem");
    for (std::size_t i = 0; i < parts[k].rows(); ++i) {
      const auto it = rank.find(problem[i]);
      if (it == rank.end())
        throw std::runtime_error(fmt::format("'{}': {}/{} has a row of problem '{}', which it does not hold",
                                             from[k]->path, where, name, problem[i]));
      rows.emplace_back(it->second, k, i);
    }
  }
  std::stable_sort(rows.begin(), rows.end(),
                   [](const auto& a, const auto& b) { return std::get<0>(a) < std::get<0>(b); });
  h5::table t;
  for (const auto& group : spec.groups) {
    if (group.timed_only && !parts.front().has(std::string(group.fields.front().name))) continue;
    for (const auto& f : group.fields) {
      const std::string field(f.name);
      // The field's values in the merged order, from each part's column.
      std::vector<columns_detail::read_column> columns;
      for (const auto& p : parts) columns.push_back(columns_detail::column_of(p, field, f.type));
      h5::column joined = columns_detail::empty_column(f.type);
      std::visit(
          [&]<class T>(std::vector<T>& v) {
            v.reserve(rows.size());
            for (const auto& [r, k, i] : rows) v.push_back(columns_detail::value_at<T>(columns[k], i));
          },
          joined);
      t.add(field, std::move(joined));
    }
  }
  t.write(dst, name, spec);
}

// A group whose children are problems (`g`, its own attributes the first shard's): each
// copied from the shard that ran it, in the study's order; the group's wall_seconds summed.
void merge_per_problem(const std::vector<const shard_file*>& having, H5::H5File& dst, H5::Group& g,
                       const std::string& top, const std::vector<std::string>& problems,
                       const std::map<std::string, const shard_file*>& owner) {
  if (has_attr(g, "wall_seconds")) {
    double sum = 0.0;
    for (const auto* s : having) sum += h5::double_attr(s->file.openGroup(top), "wall_seconds");
    replace_attr(g, "wall_seconds", sum);
  }
  for (const auto& p : problems)
    if (const auto& s = *owner.at(p); h5::is_group(s.file, top + "/" + p)) copy_object(s.file, dst, top + "/" + p);
  for (const auto* s : having)
    for (const auto& child : h5::children(s->file.openGroup(top)))
      if (!owner.count(child) || owner.at(child) != s)
        throw std::runtime_error(fmt::format("'{}': /{}/{} is not one of its problems", s->path, top, child));
}

}  // namespace

bool is_study_file(const std::string& path) {
  return one_line_errors(fmt::format("cannot read '{}'", path), [&] {
    if (!std::filesystem::exists(path)) throw std::runtime_error("no such file");
    if (!H5::H5File::isHdf5(path)) throw std::runtime_error("not an HDF5 file");
    const H5::H5File file(path, H5F_ACC_RDONLY);
    return has_attr(file, "selection");
  });
}

held_shards held_shards_of(const std::string& path) { return read_shard(path).held; }

study_merge_result merge_studies(const std::vector<std::string>& paths, const std::string& out, bool partial,
                                 const std::vector<merged_group>& groups, const std::function<void()>& before_write) {
  H5::Exception::dontPrint();
  std::vector<shard_file> shards;
  for (const auto& path : paths) shards.push_back(read_shard(path));
  const auto& first = shards.front();
  // One study: the same selection, shard count, options and timing settings.
  for (const auto& s : shards) {
    const auto differ = [&](std::string_view what, const std::string& a, const std::string& b) {
      throw std::invalid_argument(fmt::format("merge: the shards differ in their {}: '{}' has {}, '{}' has {}", what,
                                              first.path, a, s.path, b));
    };
    if (s.selection != first.selection) differ("selection of problems", first.selection, s.selection);
    if (s.held.count != first.held.count)
      differ("shard count", fmt::format("{}", first.held.count), fmt::format("{}", s.held.count));
    if (s.options != first.options) {
      const auto [a, b] = first_difference(first.options, s.options);
      differ("options", a, b);
    }
    if (s.timing != first.timing)
      for (std::size_t i = 0; i < std::max(s.timing.size(), first.timing.size()); ++i) {
        const auto a = i < first.timing.size() ? first.timing[i] : std::pair<std::string, std::string>{"", "none"};
        const auto b = i < s.timing.size() ? s.timing[i] : std::pair<std::string, std::string>{"", "none"};
        if (a != b) differ(a.first.empty() ? b.first : a.first, a.second, b.second);
      }
  }
  // Every selected problem once.
  const auto selection = stored_list(first.selection, ',');
  std::map<long, const shard_file*> by_index;
  std::map<std::string, const shard_file*> owner;
  for (const auto& s : shards) {
    for (long k : s.held.indices)
      if (auto [it, fresh] = by_index.emplace(k, &s); !fresh)
        throw std::invalid_argument(fmt::format("merge: '{}' and '{}' both hold shard {} of {} (overlapping shards)",
                                                it->second->path, s.path, k + 1, s.held.count));
    for (const auto& p : s.problems) {
      if (std::find(selection.begin(), selection.end(), p) == selection.end())
        throw std::invalid_argument(
            fmt::format("merge: '{}' holds problem {}, which is not in the study's selection", s.path, p));
      if (auto [it, fresh] = owner.emplace(p, &s); !fresh)
        throw std::invalid_argument(fmt::format(
            "merge: problem {} is in two shards, '{}' and '{}' (overlapping shards)", p, it->second->path, s.path));
    }
  }
  study_merge_result result;
  result.shards = by_index.size();
  for (const auto& p : selection) (owner.count(p) ? result.problems : result.missing).push_back(p);
  if (!result.missing.empty() && !partial) {
    std::vector<std::string> absent;
    for (long k = 0; k < first.held.count; ++k)
      if (!by_index.count(k)) absent.push_back(fmt::format("{}", k + 1));
    throw std::invalid_argument(
        fmt::format("merge: {} of the {} selected problems {} in no shard ({}){}; --partial merges what there is",
                    result.missing.size(), selection.size(), result.missing.size() == 1 ? "is" : "are",
                    fmt::join(result.missing, ", "),
                    absent.empty() ? ""
                                   : fmt::format(": shard{} {} of {} not given", absent.size() == 1 ? "" : "s",
                                                 fmt::join(absent, ", "), first.held.count)));
  }
  const auto fill = [&](H5::H5File& dst) {
    // The root's build and machine from the lowest shard that holds a problem (a timed
    // shard with none has no benchmark context: 0 CPUs at 0 MHz).
    const shard_file* root = nullptr;
    for (const auto& [index, s] : by_index)
      if (!root && !s->problems.empty()) root = s;
    copy_attrs((root ? *root : first).file, dst);
    // A partial merge names what it lacks and the shards it holds, so that merging it with
    // the missing shards completes the study; a whole merge is shard 0 of 1 and no more.
    if (!result.missing.empty()) {
      replace_attr(dst, "missing_problems", fmt::format("{}", fmt::join(result.missing, ",")));
      std::vector<int> held;
      for (const auto& [k, s] : by_index) held.push_back(static_cast<int>(k));
      replace_attr(dst, "merged_shards", held);
      replace_attr(dst, "merged_shard_count", first.held.count);
    } else {
      for (const char* name : {"missing_problems", "merged_shards", "merged_shard_count"})
        if (has_attr(dst, name)) dst.removeAttr(name);
    }
    double wall = 0.0, bench_wall = 0.0;
    for (const auto& s : shards) wall += s.wall_seconds, bench_wall += s.benchmark_wall_seconds;
    result.wall_seconds = wall;
    replace_attr(dst, "shard_index", 0L);
    replace_attr(dst, "shard_count", 1L);
    replace_attr(dst, "wall_seconds", wall);
    if (has_attr(dst, "benchmark_wall_seconds")) replace_attr(dst, "benchmark_wall_seconds", bench_wall);
    replace_attr(dst, "created_utc", utc_now_iso8601());
    // Each part's group by its rule, in the study's order.
    for (const merged_group& part : groups) {
      const std::string top(part.name);
      std::vector<const shard_file*> having;
      for (const auto& s : shards)
        if (h5::is_group(s.file, top)) having.push_back(&s);
      if (having.empty()) continue;
      if (part.rule == merge_rule::same_in_every_shard) {  // identical in every shard of one build: the first's
        copy_object(having.front()->file, dst, top);
        continue;
      }
      // The group's own attributes from the first shard that has it.
      H5::Group g = dst.createGroup(top);
      copy_attrs(having.front()->file.openGroup(top), g);
      switch (part.rule) {
        case merge_rule::same_in_every_shard:  // copied whole above
          break;
        case merge_rule::per_problem:
          merge_per_problem(having, dst, g, top, result.problems, owner);
          break;
        case merge_rule::in_one_shard:
          for (const auto* s : having)
            for (const auto& name : h5::children(s->file.openGroup(top))) {
              if (h5::has_link(g, name))
                throw std::invalid_argument(
                    fmt::format("merge: {} '{}' is in two shards (overlapping shards)", top, name));
              copy_object(s->file, dst, top + "/" + name);
            }
          break;
        case merge_rule::judged_again: {
          std::vector<const schema::table*> tables;
          for (const auto& t : schema::tables()) tables.push_back(&t);
          for (const auto& t : part.tables) tables.push_back(&t);
          for (const auto* table : tables)
            if (table->where.starts_with("/" + top + "/"))
              join_table(shards, g, top, std::string(table->where.substr(top.size() + 2)), *table, selection);
          if (part.judge_again) part.judge_again(dst, result.problems);
          break;
        }
      }
    }
    // The machines: each problem records its own; the root names every CPU model when
    // the shards ran on more than one.
    {
      std::vector<std::pair<std::string, std::vector<std::string>>> machines;
      std::vector<std::string> cpus;
      for (const auto& p : result.problems) {
        const H5::Group g = dst.openGroup("problems/" + p);
        const std::string m = fmt::format("{} ({} cores)", h5::string_attr(g, "cpu"), h5::long_attr(g, "cores"));
        auto it = std::find_if(machines.begin(), machines.end(), [&](const auto& e) { return e.first == m; });
        if (it == machines.end()) it = machines.insert(it, {m, {}});
        it->second.push_back(p);
        if (const auto cpu = h5::string_attr(g, "cpu"); std::find(cpus.begin(), cpus.end(), cpu) == cpus.end())
          cpus.push_back(cpu);
      }
      if (machines.size() > 1) result.machines = machines;
      if (cpus.size() > 1) replace_attr(dst, "cpu", fmt::format("{}", fmt::join(cpus, "; ")));
      // Frequency scaling on for any problem's timings is on for the study (the report warns).
      if (has_attr(dst, "cpu_scaling_enabled")) {
        long scaling = -1;
        for (const auto& p : result.problems)
          if (const H5::Group g = dst.openGroup("problems/" + p); has_attr(g, "cpu_scaling_enabled"))
            scaling = std::max(scaling, h5::long_attr(g, "cpu_scaling_enabled"));
        if (scaling >= 0) replace_attr(dst, "cpu_scaling_enabled", static_cast<int>(scaling));
      }
    }
  };
  write_study_file(out, fill, "cannot merge into", before_write);
  return result;
}

}  // namespace stepbench
