#include "render/table_render.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

namespace stepbench {

std::string column::heading() const { return unit.empty() ? label : fmt::format("{} [{}]", label, unit); }

table& table::add(std::vector<std::string> cells) {
  if (cells.size() != columns.size())
    throw std::logic_error(fmt::format("a table row of {} cells under {} columns", cells.size(), columns.size()));
  rows.push_back(std::move(cells));
  return *this;
}

void table::drop_column(std::size_t k) {
  columns.erase(columns.begin() + static_cast<std::ptrdiff_t>(k));
  for (auto& r : rows) r.erase(r.begin() + static_cast<std::ptrdiff_t>(k));
}

std::string render_text(const table& t, std::string_view indent) {
  std::vector<std::string> head;
  for (const auto& c : t.columns) head.push_back(c.heading());
  std::vector<std::size_t> width(head.size());
  for (std::size_t k = 0; k < head.size(); ++k) width[k] = head[k].size();
  for (const auto& r : t.rows)
    for (std::size_t k = 0; k < r.size(); ++k) width[k] = std::max(width[k], r[k].size());
  const auto line = [&](const std::vector<std::string>& cells) {
    std::string s(indent);
    for (std::size_t k = 0; k < cells.size(); ++k) {
      if (k > 0) s += "  ";
      s += t.columns[k].alignment == align::right ? fmt::format("{:>{}}", cells[k], width[k])
                                                  : fmt::format("{:<{}}", cells[k], width[k]);
    }
    s.erase(s.find_last_not_of(' ') + 1);
    return s + "\n";
  };
  std::string out = line(head);
  for (const auto& r : t.rows) out += line(r);
  return out;
}

namespace {

std::string md_cell(std::string_view s) {
  std::string out;
  for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
  return out.empty() ? " " : out;
}

}  // namespace

std::string render_markdown(const table& t) {
  const auto line = [](const auto& cells, auto text_of) {
    std::string s = "|";
    for (const auto& c : cells) s += " " + md_cell(text_of(c)) + " |";
    return s + "\n";
  };
  std::string out = line(t.columns, [](const column& c) { return c.heading(); }) + "|";
  for (const auto& c : t.columns) out += c.alignment == align::right ? "---:|" : "---|";
  out += "\n";
  for (const auto& r : t.rows) out += line(r, [](const std::string& s) -> const std::string& { return s; });
  return out;
}

std::string render(const table& t, table_format format, std::string_view indent) {
  return format == table_format::markdown ? render_markdown(t) : render_text(t, indent);
}

std::string wrap(std::string_view text, std::string_view first, std::string_view rest, std::size_t width) {
  std::string out(first);
  std::size_t col = first.size();
  bool line_empty = true;
  for (std::size_t start = 0, end; start <= text.size(); start = end + 1) {
    end = std::min(text.find(' ', start), text.size());
    const std::string_view word = text.substr(start, end - start);
    if (word.empty()) continue;
    if (!line_empty && col + 1 + word.size() > width) {
      (out += "\n") += rest;
      col = rest.size();
    } else if (!line_empty) {
      out += ' ';
      ++col;
    }
    out += word;
    col += word.size();
    line_empty = false;
  }
  return out + "\n";
}

}  // namespace stepbench
