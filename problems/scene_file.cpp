#include "problems/scene_file.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <map>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace stepbench {

scene_data scene::one_mass() {
  scene_data s;
  s.name = "scene";
  s.dim = 1;
  s.horizon = 1.0;
  s.masses.push_back({.name = "mass", .mass = 1.0});
  s.inverse_mass = {1.0};
  s.moving_mass = {1.0};
  s.slot = {0};
  return s;
}

namespace {

// Where a message points: a node's line and column, or a table's header.
struct place {
  long line = 1, column = 1;
};
place at(const toml::node& n) {
  return {static_cast<long>(n.source().begin.line), static_cast<long>(n.source().begin.column)};
}
place at(const toml::key& k) {
  return {static_cast<long>(k.source().begin.line), static_cast<long>(k.source().begin.column)};
}

// Levenshtein distance, for the nearest valid name of an unknown key.
std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diag = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diag = up;
    }
  }
  return row[b.size()];
}

// Printable: a key or a name quoted in a message shows no control or non-ASCII bytes.
std::string printable(std::string_view s) {
  std::string out;
  for (const unsigned char c : s.substr(0, 60))
    out += c >= 0x20 && c < 0x7f ? std::string(1, static_cast<char>(c)) : fmt::format("\\x{:02x}", c);
  return s.size() > 60 ? out + "..." : out;
}

std::string_view type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table:
      return "a table";
    case toml::node_type::array:
      return "an array";
    case toml::node_type::string:
      return "a string";
    case toml::node_type::integer:
      return "an integer";
    case toml::node_type::floating_point:
      return "a number";
    case toml::node_type::boolean:
      return "a boolean";
    default:
      return "a date or time";
  }
}

class reader {
 public:
  explicit reader(std::string path) : path_(std::move(path)) {}

  [[noreturn]] void fail(place p, std::string_view what) const {
    throw std::invalid_argument(fmt::format("{}:{}:{}: {}", path_, p.line, p.column, what));
  }

  // Refuses any key of `t` that is not one of `known`, naming the nearest valid one.
  void only(const toml::table& t, std::string_view where, std::initializer_list<std::string_view> known) const {
    for (auto&& [k, node] : t) {
      if (std::find(known.begin(), known.end(), k.str()) != known.end()) continue;
      std::string_view best;
      std::size_t best_d = std::string_view::npos;
      for (const auto name : known)
        if (const auto d = edit_distance(k.str(), name); d < best_d) best_d = d, best = name;
      fail(at(k), fmt::format("unknown key '{}' in {}{}", printable(k.str()), where,
                              best_d <= std::max<std::size_t>(2, best.size() / 3)
                                  ? fmt::format(" (did you mean '{}'?)", best)
                                  : fmt::format(" (valid: {})", fmt::join(known, ", "))));
    }
  }

  double number(const toml::node& n, std::string_view key) const {
    if (!n.is_number()) fail(at(n), fmt::format("'{}' must be a number, not {}", key, type_name(n)));
    const double v = n.is_integer() ? static_cast<double>(*n.value<std::int64_t>()) : *n.value<double>();
    if (!std::isfinite(v)) fail(at(n), fmt::format("'{}' must be finite", key));
    return v;
  }
  // A number that must satisfy `ok`; `rule` is what follows "must be".
  template <class Ok>
  double number(const toml::node& n, std::string_view key, Ok ok, std::string_view rule) const {
    const double v = number(n, key);
    if (!ok(v)) fail(at(n), fmt::format("'{}' must be {} (is {:g})", key, rule, v));
    return v;
  }
  std::array<double, 3> vector(const toml::node& n, std::string_view key, int dim) const {
    const toml::array* a = n.as_array();
    if (a == nullptr) fail(at(n), fmt::format("'{}' must be an array of {} numbers, not {}", key, dim, type_name(n)));
    if (static_cast<int>(a->size()) != dim)
      fail(at(n), fmt::format("'{}' must have {} entries (dim = {}), not {}", key, dim, dim, a->size()));
    std::array<double, 3> out{};
    for (int c = 0; c < dim; ++c) out[static_cast<std::size_t>(c)] = number((*a)[static_cast<std::size_t>(c)], key);
    return out;
  }
  std::string text(const toml::node& n, std::string_view key) const {
    if (!n.is_string()) fail(at(n), fmt::format("'{}' must be a string, not {}", key, type_name(n)));
    return std::string(*n.value<std::string_view>());
  }
  bool flag(const toml::node& n, std::string_view key) const {
    if (!n.is_boolean()) fail(at(n), fmt::format("'{}' must be true or false, not {}", key, type_name(n)));
    return *n.value<bool>();
  }
  const toml::node& need(const toml::table& t, std::string_view key, place where, std::string_view in) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) fail(where, fmt::format("missing key '{}'{}", key, in));
    return *n;
  }
  // The array of tables under `key` ([[key]]), or nullptr.
  const toml::array* tables(const toml::table& t, std::string_view key) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return nullptr;
    if (!n->is_array_of_tables())
      fail(at(*n), fmt::format("'{}' must be an array of tables ([[{}]] sections), not {}", key, key, type_name(*n)));
    return n->as_array();
  }
  const toml::table* table(const toml::table& t, std::string_view key) const {
    const toml::node* n = t.get(key);
    if (n == nullptr) return nullptr;
    if (!n->is_table())
      fail(at(*n), fmt::format("'{}' must be a table ([{}] section), not {}", key, key, type_name(*n)));
    return n->as_table();
  }

 private:
  std::string path_;
};

// [A-Za-z_][A-Za-z0-9_]{0,63}
bool identifier(std::string_view s) {
  const auto letter = [](char c) { return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || c == '_'; };
  if (s.empty() || s.size() > 64 || !letter(s[0])) return false;
  return std::all_of(s.begin(), s.end(), [&](char c) { return letter(c) || (c >= '0' && c <= '9'); });
}

}  // namespace

scene_data parse_scene(std::string_view text, const std::string& path) {
  const reader r(path);
  if (text.empty() || text.find_first_not_of(" \t\r\n") == std::string_view::npos)
    r.fail({}, "empty scene file (name, dim, horizon and at least one [[mass]] are required)");
  if (const auto nul = text.find('\0'); nul != std::string_view::npos) {
    const auto line = std::count(text.begin(), text.begin() + static_cast<long>(nul), '\n') + 1;
    const auto bol = text.rfind('\n', nul);
    r.fail({line, static_cast<long>(nul - (bol == std::string_view::npos ? 0 : bol + 1)) + 1},
           "not a text file (a NUL byte)");
  }
  toml::table doc;
  try {
    doc = toml::parse(text, path);
  } catch (const toml::parse_error& e) {
    r.fail({static_cast<long>(e.source().begin.line), static_cast<long>(e.source().begin.column)},
           fmt::format("not valid TOML: {}", printable(e.description())));
  }
  r.only(doc, "the scene",
         {"name", "description", "dim", "horizon", "gravity", "mass", "spring", "drag", "attraction", "plane"});
  scene_data s;
  s.path = path;
  const place top{};
  const auto& name = r.need(doc, "name", top, "");
  s.name = r.text(name, "name");
  s.name_line = at(name).line, s.name_column = at(name).column;
  if (!identifier(s.name))
    r.fail(at(name),
           fmt::format("'name' must be an identifier (letters, digits, _; at most 64), not \"{}\"", printable(s.name)));
  if (const auto* d = doc.get("description")) s.description = r.text(*d, "description");
  if (s.description.find('\n') != std::string::npos)
    r.fail(at(*doc.get("description")), "'description' must be one line");
  s.dim = static_cast<int>(r.number(
      r.need(doc, "dim", top, ""), "dim", [](double v) { return v == 1 || v == 2 || v == 3; }, "1, 2 or 3"));
  s.horizon = r.number(
      r.need(doc, "horizon", top, ""), "horizon", [](double v) { return v > 0; }, "positive");
  if (const auto* g = doc.get("gravity")) s.gravity = r.vector(*g, "gravity", s.dim), s.has_gravity = true;

  // Masses.
  const toml::array* masses = r.tables(doc, "mass");
  if (masses == nullptr || masses->empty()) r.fail(top, "no [[mass]]: a scene needs at least one moving mass");
  std::map<std::string, int, std::less<>> by_name;
  for (const auto& node : *masses) {
    const auto& t = *node.as_table();
    const place here = at(t);
    r.only(t, "[[mass]]", {"name", "mass", "position", "velocity", "fixed"});
    scene_data::mass_point m;
    const int index = static_cast<int>(s.masses.size());
    if (const auto* n = t.get("name")) {
      m.name = r.text(*n, "name");
      if (!identifier(m.name))
        r.fail(at(*n), fmt::format("a mass's 'name' must be an identifier, not \"{}\"", printable(m.name)));
      if (!by_name.emplace(m.name, index).second) r.fail(at(*n), fmt::format("two masses are named '{}'", m.name));
    }
    if (const auto* f = t.get("fixed")) m.fixed = r.flag(*f, "fixed");
    m.position = r.vector(r.need(t, "position", here, " in [[mass]]"), "position", s.dim);
    if (const auto* v = t.get("velocity")) {
      m.velocity = r.vector(*v, "velocity", s.dim);
      if (m.fixed && std::any_of(m.velocity.begin(), m.velocity.end(), [](double c) { return c != 0.0; }))
        r.fail(at(*v), "a fixed mass does not move: its 'velocity' must be zero or absent");
    }
    if (const auto* mm = t.get("mass"))
      m.mass = r.number(
          *mm, "mass", [](double v) { return v > 0; }, "positive");
    else if (!m.fixed)
      r.fail(here, "missing key 'mass' in [[mass]] (a moving mass needs one)");
    s.slot.push_back(m.fixed ? ~static_cast<int>(s.fixed_position.size()) : static_cast<int>(s.moving_mass.size()));
    if (m.fixed) {
      s.fixed_position.push_back(m.position);
      s.fixed_mass.push_back(m.mass);
    } else {
      s.moving_mass.push_back(m.mass);
      s.inverse_mass.push_back(1.0 / m.mass);
    }
    s.masses.push_back(m);
  }
  if (s.moving_mass.empty()) r.fail(at(*masses), "every [[mass]] is fixed: a scene needs at least one moving mass");

  // Springs.
  const auto end_of = [&](const toml::node& e) -> int {
    if (e.is_string()) {
      const auto nm = *e.value<std::string_view>();
      const auto it = by_name.find(nm);
      if (it == by_name.end()) r.fail(at(e), fmt::format("no mass is named '{}'", printable(nm)));
      return it->second;
    }
    if (e.is_integer()) {
      const auto i = *e.value<std::int64_t>();
      if (i < 0 || i >= static_cast<std::int64_t>(s.masses.size()))
        r.fail(at(e), fmt::format("mass index {} does not exist (the scene has {} masses, indices from 0)", i,
                                  s.masses.size()));
      return static_cast<int>(i);
    }
    r.fail(at(e), fmt::format("a spring's end must be a mass's name or 0-based index, not {}", type_name(e)));
  };
  if (const toml::array* springs = r.tables(doc, "spring"))
    for (const auto& node : *springs) {
      const auto& t = *node.as_table();
      const place here = at(t);
      r.only(t, "[[spring]]", {"between", "stiffness", "damping", "rest_length"});
      const auto& between = r.need(t, "between", here, " in [[spring]]");
      const toml::array* ends = between.as_array();
      if (ends == nullptr || ends->size() != 2)
        r.fail(at(between), "'between' must name two masses: [\"a\", \"b\"] or [0, 1]");
      const int a = end_of((*ends)[0]), b = end_of((*ends)[1]);
      if (a == b) r.fail(at(between), "a spring joins two different masses");
      const auto& ma = s.masses[static_cast<std::size_t>(a)];
      const auto& mb = s.masses[static_cast<std::size_t>(b)];
      if (ma.fixed && mb.fixed) r.fail(at(between), "both ends of the spring are fixed: it moves nothing");
      scene_data::spring sp{.a = s.slot[static_cast<std::size_t>(a)], .b = s.slot[static_cast<std::size_t>(b)]};
      sp.stiffness = r.number(
          r.need(t, "stiffness", here, " in [[spring]]"), "stiffness", [](double v) { return v >= 0; }, "non-negative");
      if (const auto* c = t.get("damping"))
        sp.damping = r.number(
            *c, "damping", [](double v) { return v >= 0; }, "non-negative");
      if (const auto* l = t.get("rest_length")) {
        sp.rest_length = r.number(
            *l, "rest_length", [](double v) { return v >= 0; }, "non-negative");
      } else {
        double d2 = 0.0;
        for (int c = 0; c < s.dim; ++c) d2 += (mb.position[c] - ma.position[c]) * (mb.position[c] - ma.position[c]);
        sp.rest_length = std::sqrt(d2);
      }
      s.springs.push_back(sp);
      if (sp.b < 0)
        s.anchored.push_back(sp);
      else if (sp.a < 0)  // fixed end first: its moving end becomes a (the d negated exactly)
        s.anchored.push_back(
            {.a = sp.b, .b = sp.a, .stiffness = sp.stiffness, .damping = sp.damping, .rest_length = sp.rest_length});
      else
        s.between_moving.push_back(sp);
    }
  for (auto& sp : s.anchored) sp.b = ~sp.b;  // the fixed point's index

  if (const toml::table* drag = r.table(doc, "drag")) {
    r.only(*drag, "[drag]", {"linear", "quadratic"});
    if (const auto* l = drag->get("linear"))
      s.drag_linear = r.number(
          *l, "linear", [](double v) { return v >= 0; }, "non-negative");
    if (const auto* q = drag->get("quadratic"))
      s.drag_quadratic = r.number(
          *q, "quadratic", [](double v) { return v >= 0; }, "non-negative");
    s.has_drag = s.drag_linear > 0 || s.drag_quadratic > 0;
  }
  if (const toml::table* attraction = r.table(doc, "attraction")) {
    r.only(*attraction, "[attraction]", {"G"});
    s.attraction_G = r.number(
        r.need(*attraction, "G", at(*attraction), " in [attraction]"), "G", [](double v) { return v > 0; }, "positive");
    s.has_attraction = true;
    // Two masses at one point: the attraction between them is infinite.
    for (std::size_t i = 0; i < s.masses.size(); ++i)
      for (std::size_t j = i + 1; j < s.masses.size(); ++j)
        if (s.masses[i].position == s.masses[j].position && (s.masses[i].mass > 0 && s.masses[j].mass > 0))
          r.fail(at(*attraction),
                 fmt::format("masses {} and {} start at one point: their attraction is infinite", i, j));
  }
  // The force Jacobians are band matrices (problems/scene.hpp make_jacobian): their band
  // reaches the farthest pair of moving masses a spring joins in the file's order, or
  // every mass under attraction. Their storage, 3 band + 1 rows of every coordinate, is
  // kept under 512 MiB, so that a scene cannot take the implicit methods, the references
  // or `scene check` past the memory a process may have.
  {
    long reach = s.has_attraction ? s.moving() - 1 : 0;
    for (const auto& sp : s.between_moving) reach = std::max<long>(reach, std::abs(sp.a - sp.b));
    const long coordinates = static_cast<long>(s.dim) * s.moving();
    const long band = reach == 0 ? s.dim - 1 : s.dim * reach + s.dim - 1;
    const double bytes = 8.0 * static_cast<double>(3 * band + 1) * static_cast<double>(coordinates);
    if (bytes > 512.0 * (1 << 20))
      r.fail(s.has_attraction ? at(*doc.get("attraction")) : top,
             fmt::format("the scene's force Jacobian would take {:.3g} GiB as a band matrix ({} coordinates, {} "
                         "off-diagonals; at most 0.5 GiB): {}",
                         bytes / (1 << 30), coordinates, band,
                         s.has_attraction ? "attraction couples every pair of masses; use fewer masses"
                                          : "a spring joins masses far apart in the file's order; number the masses "
                                            "along the springs"));
  }
  if (const toml::array* planes = r.tables(doc, "plane"))
    for (const auto& node : *planes) {
      const auto& t = *node.as_table();
      const place here = at(t);
      r.only(t, "[[plane]]", {"normal", "offset", "restitution", "friction", "static_friction", "tangential_loss"});
      const auto& normal = r.need(t, "normal", here, " in [[plane]]");
      const auto n = r.vector(normal, "normal", s.dim);
      double length2 = 0.0;
      for (int c = 0; c < s.dim; ++c) length2 += n[c] * n[c];
      if (!(length2 > 0.0) || !std::isfinite(length2))
        r.fail(at(normal), "'normal' must be a non-zero vector of finite length");
      const double length = std::sqrt(length2);
      scene_data::plane pl;
      for (int c = 0; c < s.dim; ++c) pl.normal[c] = length == 1.0 ? n[c] : n[c] / length;
      const double offset = t.get("offset") != nullptr ? r.number(*t.get("offset"), "offset") : 0.0;
      pl.offset = offset / length;
      if (const auto* k = t.get("restitution"))
        pl.restitution = r.number(
            *k, "restitution", [](double v) { return v >= 0 && v <= 1; }, "in [0, 1]");
      const auto non_negative = [](double v) { return v >= 0; };
      if (const auto* k = t.get("friction")) pl.friction = r.number(*k, "friction", non_negative, ">= 0");
      pl.static_friction = pl.friction;  // one coefficient unless the file gives both
      if (const auto* k = t.get("static_friction"))
        pl.static_friction = r.number(*k, "static_friction", non_negative, ">= 0");
      if (const auto* k = t.get("tangential_loss"))
        pl.tangential_loss = r.number(
            *k, "tangential_loss", [](double v) { return v >= 0 && v <= 1; }, "in [0, 1]");
      // Every moving mass starts on the plane's side, as the file writes it (before the
      // division by the normal's length, which could round a mass on the plane off it).
      for (const auto& m : s.masses) {
        if (m.fixed) continue;
        double side = 0.0;
        for (int c = 0; c < s.dim; ++c) side += n[c] * m.position[c];
        if (side < offset)
          r.fail(here, fmt::format("mass {}{} starts on the wrong side of this plane (normal . x = {:g} < offset {:g})",
                                   &m - s.masses.data(), m.name.empty() ? "" : " '" + m.name + "'", side, offset));
      }
      s.planes.push_back(pl);
    }
  return s;
}

scene_data read_scene_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot open the scene file", path));
  in.seekg(0, std::ios::end);
  const auto size = static_cast<long>(in.tellg());
  if (size < 0) throw std::invalid_argument(fmt::format("{}: cannot read the scene file (not a regular file?)", path));
  if (size > max_scene_file_bytes)
    throw std::invalid_argument(
        fmt::format("{}:1:1: the scene file has {} bytes, more than the {} a scene file may have", path, size,
                    max_scene_file_bytes));
  in.seekg(0);
  std::string text(static_cast<std::size_t>(size), '\0');
  in.read(text.data(), size);
  if (!in) throw std::invalid_argument(fmt::format("{}: cannot read the scene file", path));
  return parse_scene(text, path);
}

}  // namespace stepbench
