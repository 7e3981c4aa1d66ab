#include "store/bench_merge.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>

#include "store/merge.hpp"

namespace stepbench {
namespace {

using json = nlohmann::ordered_json;  // each object's keys in Google Benchmark's order

// Google Benchmark writes a non-finite double as a bare NaN, Infinity or -Infinity
// (json_reporter.cc), which Python's json (so compare.py) reads and JSON does not: each
// is read as a string marked by a leading U+0001 and written back bare.
constexpr std::string_view nonfinite[] = {"-Infinity", "Infinity", "-NaN", "NaN"};

std::string mark_nonfinite(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  bool in_string = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (in_string) {
      out += c;
      if (c == '\\' && i + 1 < text.size())
        out += text[++i];
      else if (c == '"')
        in_string = false;
      continue;
    }
    if (c == '"') {
      in_string = true;
      out += c;
      continue;
    }
    const auto word = std::find_if(std::begin(nonfinite), std::end(nonfinite),
                                   [&](std::string_view w) { return std::string_view(text).substr(i, w.size()) == w; });
    if (word == std::end(nonfinite)) {
      out += c;
      continue;
    }
    out += fmt::format("\"\\u0001{}\"", *word);
    i += word->size() - 1;
  }
  return out;
}

std::string unmark_nonfinite(std::string text) {
  for (const std::string_view w : nonfinite) {
    const std::string marked = fmt::format("\"\\u0001{}\"", w);
    for (auto at = text.find(marked); at != std::string::npos; at = text.find(marked, at + w.size()))
      text.replace(at, marked.size(), w);
  }
  return text;
}

// A file's JSON; nullopt for an empty file.
std::optional<json> read_bench(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read '{}': {}", path, std::strerror(errno)));
  std::ostringstream text;
  text << in.rdbuf();
  if (text.str().find_first_not_of(" \t\r\n") == std::string::npos) return std::nullopt;
  json doc;
  try {
    doc = json::parse(mark_nonfinite(text.str()));
  } catch (const json::parse_error& e) {
    const std::string_view what = e.what();  // "[json.exception.parse_error.101] parse error at ..."
    throw std::runtime_error(
        fmt::format("cannot read '{}': not JSON ({})", path, what.substr(std::min(what.find("] ") + 2, what.size()))));
  }
  const auto bad = [&](std::string_view why) {
    return std::runtime_error(fmt::format("cannot read '{}': not Google Benchmark's JSON ({})", path, why));
  };
  if (!doc.is_object() || !doc.contains("context") || !doc["context"].is_object()) throw bad("no \"context\" object");
  if (!doc.contains("benchmarks") || !doc["benchmarks"].is_array()) throw bad("no \"benchmarks\" array");
  for (const auto& b : doc["benchmarks"])
    if (!b.is_object() || !b.contains("name") || !b["name"].is_string()) throw bad("a benchmark without a name");
  return doc;
}

struct shard_id {
  long index = 0, count = 1;  // 0-based
  auto operator<=>(const shard_id&) const = default;
};

std::string name_of(const shard_id& s) { return fmt::format("{}/{}", s.index + 1, s.count); }
std::string text_of(const shard_id& s) { return fmt::format("shard {} of {}", s.index + 1, s.count); }

// "K/N", 1 <= K <= N, as --shard=K/N names a shard.
std::optional<shard_id> parse_shard_id(const json& v) {
  if (!v.is_string()) return std::nullopt;
  const auto& text = v.get_ref<const std::string&>();
  long k = 0, n = 0;
  const char *p = text.data(), *end = p + text.size();
  auto r = std::from_chars(p, end, k);
  if (r.ec != std::errc() || r.ptr == end || *r.ptr != '/') return std::nullopt;
  r = std::from_chars(r.ptr + 1, end, n);
  if (r.ec != std::errc() || r.ptr != end || k < 1 || k > n) return std::nullopt;
  return shard_id{k - 1, n};
}

// "shard 2 of 4", "shards 1, 3 of 4".
std::string shards_text(const std::vector<shard_id>& ids) {
  std::vector<long> numbers;
  for (const auto& s : ids) numbers.push_back(s.index + 1);
  std::vector<long> counts;
  for (const auto& s : ids)
    if (std::find(counts.begin(), counts.end(), s.count) == counts.end()) counts.push_back(s.count);
  return fmt::format("shard{} {} of {}", ids.size() == 1 ? "" : "s", fmt::join(numbers, ", "), fmt::join(counts, ", "));
}

bool machine_benchmark(std::string_view name) {
  return std::any_of(std::begin(machine_benchmarks), std::end(machine_benchmarks), [&](std::string_view family) {
    return name.substr(0, family.size()) == family &&
           (name.size() == family.size() || name[family.size()] == '/' || name[family.size()] == '_');
  });
}

// One shard's part of a file: its context (none when the shard timed nothing) and where from.
struct shard_json {
  shard_id id;
  std::string path;
  std::optional<json> context;
};

}  // namespace

bench_join_result join_bench_json(const std::vector<std::string>& paths, const std::vector<std::string>& study_paths) {
  if (paths.size() != study_paths.size())
    throw std::invalid_argument(fmt::format(
        "merge: {} benchmark JSON file{} (--bench) for {} study file{}; give one for each study file, in the "
        "same order",
        paths.size(), paths.size() == 1 ? "" : "s", study_paths.size(), study_paths.size() == 1 ? "" : "s"));
  std::map<long, shard_json> shards;  // by shard index
  std::vector<std::pair<shard_id, json>> rows;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const std::string& path = paths[i];
    const held_shards held = held_shards_of(study_paths[i]);
    std::vector<shard_id> want;
    for (long k : held.indices) want.push_back({k, held.count});
    std::optional<json> doc = read_bench(path);
    // The shards this file holds: a merged file's list, a shard's own (named by its
    // context or, unnamed, its study file's); an empty file, its study file's.
    std::vector<shard_json> own;
    if (!doc) {
      if (held.problems > 0)
        throw std::runtime_error(
            fmt::format("cannot read '{}': it is empty, and its study file '{}' holds {} problem{}", path,
                        study_paths[i], held.problems, held.problems == 1 ? "" : "s"));
      for (const auto& id : want) own.push_back({id, path, std::nullopt});
    } else if (json& context = (*doc)["context"]; context.contains(bench_shards_key)) {
      const json& list = context[bench_shards_key];
      if (!list.is_array() || list.empty())
        throw std::runtime_error(
            fmt::format("cannot read '{}': its {} is not a list of shards", path, bench_shards_key));
      for (const auto& c : list) {
        const auto id =
            c.is_object() && c.contains(bench_shard_key) ? parse_shard_id(c[bench_shard_key]) : std::nullopt;
        if (!id)
          throw std::runtime_error(
              fmt::format("cannot read '{}': an entry of its {} names no shard (K/N)", path, bench_shards_key));
        // An entry of the key alone is a shard that timed nothing.
        own.push_back({*id, path, c.size() > 1 ? std::optional<json>(c) : std::nullopt});
      }
    } else if (context.contains(bench_shard_key)) {
      const auto id = parse_shard_id(context[bench_shard_key]);
      if (!id)
        throw std::runtime_error(fmt::format("cannot read '{}': its context's {} is not K/N", path, bench_shard_key));
      own.push_back({*id, path, context});
    } else if (want.size() == 1) {
      own.push_back({want.front(), path, context});
    } else {
      throw std::invalid_argument(fmt::format("merge: '{}' names no shard, and its study file '{}' holds {}", path,
                                              study_paths[i], shards_text(want)));
    }
    std::vector<shard_id> have;
    for (const auto& s : own) have.push_back(s.id);
    std::sort(have.begin(), have.end());
    if (have != want)
      throw std::invalid_argument(
          fmt::format("merge: '{}' is the benchmark JSON of {}, and its study file '{}' holds {}; give --bench in the "
                      "order of the study files",
                      path, shards_text(have), study_paths[i], shards_text(want)));
    for (auto& s : own)
      if (const auto [it, fresh] = shards.emplace(s.id.index, s); !fresh)
        throw std::invalid_argument(
            fmt::format("merge: '{}' and '{}' both hold the benchmarks of {} (overlapping shards)", it->second.path,
                        path, text_of(s.id)));
    if (!doc) continue;
    for (auto& b : (*doc)["benchmarks"]) {
      std::optional<shard_id> id = own.size() == 1 ? std::optional<shard_id>(own.front().id) : std::nullopt;
      if (b.contains(bench_shard_key)) id = parse_shard_id(b[bench_shard_key]);
      if (!id || std::find(have.begin(), have.end(), *id) == have.end())
        throw std::runtime_error(fmt::format("cannot read '{}': benchmark '{}' names no shard the file holds", path,
                                             b["name"].get<std::string>()));
      rows.emplace_back(*id, std::move(b));
    }
  }
  // A benchmark in one shard, but the machine's own.
  std::map<std::string, shard_id> owner;
  for (const auto& [id, b] : rows) {
    const auto& name = b["name"].get_ref<const std::string&>();
    if (machine_benchmark(name)) continue;
    if (const auto [it, fresh] = owner.emplace(name, id); !fresh && it->second != id)
      throw std::invalid_argument(
          fmt::format("merge: benchmark '{}' is in {} ('{}') and {} ('{}') (overlapping shards)", name,
                      text_of(it->second), shards.at(it->second.index).path, text_of(id), shards.at(id.index).path));
  }
  // In shard order, each shard's families after the previous shards'.
  std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  std::map<long, std::pair<long, long>> families;  // shard -> its lowest and highest family_index
  for (const auto& [id, b] : rows)
    if (b.contains("family_index") && b["family_index"].is_number_integer()) {
      const long f = b["family_index"].get<long>();
      const auto [it, fresh] = families.emplace(id.index, std::pair{f, f});
      it->second = {std::min(it->second.first, f), std::max(it->second.second, f)};
    }
  std::map<long, long> shift;
  long next = 0;
  for (const auto& [shard, span] : families) {
    shift[shard] = next - span.first;
    next += span.second - span.first + 1;
  }
  json benchmarks = json::array();
  for (auto& [id, b] : rows) {
    if (b.contains("family_index") && b["family_index"].is_number_integer())
      b["family_index"] = b["family_index"].get<long>() + shift.at(id.index);
    b[bench_shard_key] = name_of(id);
    benchmarks.push_back(std::move(b));
  }
  // The context: the lowest shard's that timed anything, and every shard's own.
  const auto first = std::find_if(shards.begin(), shards.end(), [](const auto& s) { return s.second.context; });
  json context = first == shards.end() ? json::object() : *first->second.context, list = json::array();
  context.erase(bench_shard_key);
  context.erase(bench_shards_key);
  for (const auto& [index, s] : shards) {
    json c = s.context.value_or(json::object());
    c.erase(bench_shards_key);
    c[bench_shard_key] = name_of(s.id);
    list.push_back(std::move(c));
  }
  context[bench_shards_key] = std::move(list);
  bench_join_result out;
  out.benchmarks = benchmarks.size();
  out.shards = shards.size();
  const json doc = {{"context", std::move(context)}, {"benchmarks", std::move(benchmarks)}};
  out.text = unmark_nonfinite(doc.dump(2)) + "\n";
  return out;
}

}  // namespace stepbench
