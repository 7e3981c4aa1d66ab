#pragma once
// The one table renderer of the command line: every command that prints a table
// (compare, ratios, list, advise, stability, loop, energy) builds a `table` and has it
// drawn here, as aligned text or as Markdown, so that no command formats its own
// columns. A table is a header of labelled columns (with a unit where the column has
// one, and an alignment) and rows of cells, already formatted as text by the command
// (the number formats belong to what is shown, the layout to this file).
#include <cstddef>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/text.hpp"

namespace stepbench {

enum class align { left, right };

struct column {
  std::string label;
  std::string unit;  // shown as "label [unit]"; empty: none
  align alignment = align::left;

  column(std::string label_, std::string unit_ = {}, align alignment_ = align::left)
      : label(std::move(label_)), unit(std::move(unit_)), alignment(alignment_) {}
  // A left-aligned column of no unit, written as its label: {"method", right_column("cost")}.
  column(const char* label_) : column(std::string(label_)) {}
  std::string heading() const;
};
// A right-aligned column (numbers).
inline column right_column(std::string label, std::string unit = {}) {
  return column(std::move(label), std::move(unit), align::right);
}

struct table {
  std::vector<column> columns;
  std::vector<std::vector<std::string>> rows;

  // One row, a cell per column (throws std::logic_error when the count differs).
  table& add(std::vector<std::string> cells);
  bool empty() const { return rows.empty(); }
  // Removes column k and its cells (a note column that no row uses, say).
  void drop_column(std::size_t k);
};

enum class table_format { text, markdown };

// Aligned text: each line after `indent`, columns two spaces apart, left- or
// right-aligned as declared, no trailing spaces.
std::string render_text(const table& t, std::string_view indent = "  ");
// A GitHub-flavoured Markdown table: right-aligned columns marked `---:`, a '|' in a
// cell escaped, an empty cell written as one space.
std::string render_markdown(const table& t);
std::string render(const table& t, table_format format, std::string_view indent = "  ");

// The text around the tables. A paragraph's words filled to `width` columns, the first
// line after `first`, the rest after `rest`, ending in a newline.
std::string wrap(std::string_view text, std::string_view first, std::string_view rest, std::size_t width = 100);

}  // namespace stepbench
