// Test-machine export reader (format and dialects in test_machine_export.h).
#include "core/test_machine_export.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/errors.h"

namespace morphfem {

namespace {

struct Field {
  std::string text;  // trimmed, quotes removed
  bool quoted = false;
};

std::string trim(const std::string& s) {
  size_t a = 0, b = s.size();
  while (a < b && std::isspace(static_cast<unsigned char>(s[a]))) ++a;
  while (b > a && std::isspace(static_cast<unsigned char>(s[b - 1]))) --b;
  return s.substr(a, b - a);
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Splits a line at `sep` outside double quotes; "" inside quotes is a quote.
std::vector<Field> split(const std::string& line, char sep) {
  std::vector<Field> out;
  Field f;
  std::string raw;
  bool in_quotes = false;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (in_quotes) {
      if (c == '"' && i + 1 < line.size() && line[i + 1] == '"') {
        raw += '"';
        ++i;
      } else if (c == '"') {
        in_quotes = false;
      } else {
        raw += c;
      }
    } else if (c == '"') {
      in_quotes = true;
      f.quoted = true;
    } else if (c == sep) {
      f.text = trim(raw);
      out.push_back(f);
      f = Field{};
      raw.clear();
    } else {
      raw += c;
    }
  }
  f.text = trim(raw);
  out.push_back(f);
  return out;
}

bool all_empty(const std::vector<Field>& fields) {
  return std::all_of(fields.begin(), fields.end(), [](const Field& f) { return f.text.empty(); });
}

// Number of fields up to the last non-empty one.
size_t used_fields(const std::vector<Field>& fields) {
  size_t n = fields.size();
  while (n > 0 && fields[n - 1].text.empty()) --n;
  return n;
}

bool number_of(const Field& f, char sep, double& v) { return parse_export_number(f.text, sep != ',' || f.quoted, v); }

// A row of >= 2 fields, all numbers (trailing empty fields allowed).
bool numeric_row(const std::vector<Field>& fields, char sep) {
  const size_t n = used_fields(fields);
  if (n < 2) return false;
  double v;
  for (size_t i = 0; i < n; ++i)
    if (!number_of(fields[i], sep, v)) return false;
  return true;
}

std::string sep_name(char sep) { return sep == '\t' ? "tab" : std::string("'") + sep + "'"; }

struct UnitInfo {
  ExportQuantity quantity;
  double to_si;
};

// Unit (lower case, without brackets) -> quantity and factor to SI.
std::optional<UnitInfo> unit_info(const std::string& unit) {
  using Q = ExportQuantity;
  static const std::map<std::string, UnitInfo> table = {
      {"s", {Q::time, 1.0}},
      {"sec", {Q::time, 1.0}},
      {"ms", {Q::time, 1e-3}},
      {"min", {Q::time, 60.0}},
      {"h", {Q::time, 3600.0}},
      {"mm", {Q::displacement, 1e-3}},
      {"m", {Q::displacement, 1.0}},
      {"cm", {Q::displacement, 1e-2}},
      {"um", {Q::displacement, 1e-6}},
      {"\xc2\xb5m", {Q::displacement, 1e-6}},
      {"in", {Q::displacement, 0.0254}},
      {"n", {Q::force, 1.0}},
      {"kn", {Q::force, 1e3}},
      {"mn", {Q::force, 1e-3}},
      {"lbf", {Q::force, 4.4482216152605}},
      {"kgf", {Q::force, 9.80665}},
      {"pa", {Q::stress, 1.0}},
      {"kpa", {Q::stress, 1e3}},
      {"mpa", {Q::stress, 1e6}},
      {"gpa", {Q::stress, 1e9}},
      {"n/mm^2", {Q::stress, 1e6}},
      {"n/mm2", {Q::stress, 1e6}},
      {"n/mm\xc2\xb2", {Q::stress, 1e6}},
      {"n/m^2", {Q::stress, 1.0}},
      {"psi", {Q::stress, 6894.757293168}},
      {"%", {Q::strain, 0.01}},
      {"mm/mm", {Q::strain, 1.0}},
      {"m/m", {Q::strain, 1.0}},
      {"-", {Q::strain, 1.0}},
  };
  auto it = table.find(unit);
  if (it == table.end()) return std::nullopt;
  return it->second;
}

// Splits "Load (N)" / "Load [N]" into name and unit; unit "" if none.
void name_and_unit(const std::string& label, std::string& name, std::string& unit) {
  name = trim(label);
  unit.clear();
  if (name.empty()) return;
  const char close = name.back();
  if (close != ')' && close != ']') return;
  const char open = close == ')' ? '(' : '[';
  const size_t a = name.rfind(open);
  if (a == std::string::npos) return;
  unit = trim(name.substr(a + 1, name.size() - a - 2));
  name = trim(name.substr(0, a));
}

// A units-row entry: "(s)", "[mm]", "N", "%" (any known unit).
bool is_unit_cell(const std::string& text) {
  std::string t = trim(text);
  if (t.size() >= 2 && ((t.front() == '(' && t.back() == ')') || (t.front() == '[' && t.back() == ']')))
    t = trim(t.substr(1, t.size() - 2));
  return unit_info(lower(t)).has_value();
}

std::string strip_brackets(std::string t) {
  t = trim(t);
  if (t.size() >= 2 && ((t.front() == '(' && t.back() == ')') || (t.front() == '[' && t.back() == ']')))
    t = trim(t.substr(1, t.size() - 2));
  return t;
}

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  size_t start = 0;
  if (text.size() >= 3 && text.compare(0, 3, "\xef\xbb\xbf") == 0) start = 3;  // UTF-8 BOM
  for (size_t i = start; i < text.size(); ++i) {
    const char c = text[i];
    if (c == '\n' || c == '\r') {
      lines.push_back(line);
      line.clear();
      if (c == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    } else {
      line += c;
    }
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

char detect_separator(const std::vector<std::string>& lines, const std::string& file) {
  char best = 0;
  size_t best_count = 0;
  for (char sep : {'\t', ';', ','}) {
    size_t count = 0;
    for (const auto& line : lines)
      if (numeric_row(split(line, sep), sep)) ++count;
    if (count > best_count) {
      best = sep;
      best_count = count;
    }
  }
  if (best_count == 0)
    throw InputError(file, "no data rows: no line splits into two or more numbers with separator ';', tab or ','");
  return best;
}

// Checks one data row against the columns; throws with the reason.
void parse_data_row(const std::vector<Field>& fields, char sep, const std::string& line, const std::string& at,
                    std::vector<ExportColumn>& columns, const std::vector<std::string>& labels) {
  const size_t n_cols = columns.size();
  const size_t used = used_fields(fields);
  if (used <= 1 && n_cols > 1) {
    for (char other : {'\t', ';', ','})
      if (other != sep && numeric_row(split(line, other), other))
        throw InputError(
            at, "wrong separator: the line is separated by " + sep_name(other) + " but the file uses " + sep_name(sep));
  }
  if (used > n_cols)
    throw InputError(at, std::to_string(used) + " fields but only " + std::to_string(n_cols) +
                             " named columns (extra values or wrong separator)");
  for (size_t c = 0; c < n_cols; ++c) {
    if (c >= fields.size() || fields[c].text.empty()) {
      if (c >= used)
        throw InputError(at, "truncated line: " + std::to_string(used) + " of " + std::to_string(n_cols) +
                                 " fields (column '" + labels[c] + "' missing)");
      throw InputError(at, "empty field in column '" + labels[c] + "'");
    }
    double v;
    if (!number_of(fields[c], sep, v)) {
      std::string hint;
      const std::string& t = fields[c].text;
      for (char other : {'\t', ';', ','})
        if (other != sep && std::count(t.begin(), t.end(), other) > (other == ',' ? 1 : 0))
          hint = " (wrong separator?)";
      throw InputError(at, "text '" + fields[c].text + "' in numeric column '" + labels[c] + "'" + hint);
    }
    columns[c].values.push_back(columns[c].to_si * v);
  }
}

}  // namespace

const char* quantity_name(ExportQuantity q) {
  switch (q) {
    case ExportQuantity::time:
      return "time";
    case ExportQuantity::displacement:
      return "displacement";
    case ExportQuantity::force:
      return "force";
    case ExportQuantity::stress:
      return "stress";
    case ExportQuantity::strain:
      return "strain";
  }
  return "?";
}

bool parse_export_number(const std::string& text, bool decimal_comma, double& value) {
  std::string s = trim(text);
  if (s.empty()) return false;
  if (s.find(',') != std::string::npos) {
    if (!decimal_comma || s.find('.') != std::string::npos || std::count(s.begin(), s.end(), ',') > 1) return false;
    std::replace(s.begin(), s.end(), ',', '.');
  }
  const char first = s[0];
  if (!(std::isdigit(static_cast<unsigned char>(first)) || first == '-' || first == '+' || first == '.')) return false;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || !std::isfinite(v)) return false;
  value = v;
  return true;
}

const ExportColumn* SpecimenExport::find(ExportQuantity q, const std::string& name_hint,
                                         const std::vector<std::string>& exclude) const {
  const std::string hint = lower(name_hint);
  for (const auto& c : columns) {
    if (c.quantity != q) continue;
    const std::string n = lower(c.name);
    if (!hint.empty() && n.find(hint) == std::string::npos) continue;
    if (std::any_of(exclude.begin(), exclude.end(),
                    [&](const std::string& w) { return n.find(lower(w)) != std::string::npos; }))
      continue;
    return &c;
  }
  return nullptr;
}

std::string SpecimenExport::header_value(const std::string& key_part) const {
  const std::string want = lower(key_part);
  for (const auto& [key, value] : header)
    if (lower(key).find(want) != std::string::npos) return value;
  return "";
}

bool SpecimenExport::header_si(const std::string& key_part, double& value) const {
  const std::string want = lower(key_part);
  for (const auto& [key, text] : header) {
    if (lower(key).find(want) == std::string::npos) continue;
    std::string name, unit;
    name_and_unit(key, name, unit);
    unit = lower(unit);
    static const std::map<std::string, double> factors = {
        {"mm", 1e-3},   {"cm", 1e-2},  {"m", 1.0},   {"mm^2", 1e-6},        {"mm2", 1e-6},
        {"cm^2", 1e-4}, {"cm2", 1e-4}, {"m^2", 1.0}, {"mm/min", 1e-3 / 60}, {"mm/s", 1e-3},
        {"m/s", 1.0},   {"n", 1.0},    {"kg", 1.0},  {"g", 1e-3},           {"", 1.0}};
    auto f = factors.find(unit);
    double v;
    if (f == factors.end() || !parse_export_number(text, true, v)) return false;
    value = v * f->second;
    return true;
  }
  return false;
}

namespace {

// An export's lines split at its separator, with "FILE:LINE" locations for errors.
struct ExportText {
  const std::vector<std::string>& lines;
  char sep;
  const std::string& file;

  std::vector<Field> fields(size_t i) const { return split(lines[i], sep); }
  std::string at(size_t i) const { return file + ":" + std::to_string(i + 1); }
};

// Where one specimen block's parts are: header lines from `start`, the column names
// row, an optional units row under it, and the first data row.
struct BlockLayout {
  size_t start = 0, names_line = 0, data_start = 0;
  std::optional<size_t> units_line;
};

// The layout of the block starting at line `start`: everything up to the first numeric
// row is header, names and units; the last non-empty row before the data holds the
// names, unless every cell of it is a unit, which makes it the units row under names.
BlockLayout locate_block(const ExportText& t, size_t start) {
  BlockLayout b;
  b.start = start;
  b.data_start = start;
  while (b.data_start < t.lines.size() && !numeric_row(t.fields(b.data_start), t.sep)) ++b.data_start;
  if (b.data_start == t.lines.size())
    throw InputError(t.at(start), "specimen block without data rows (no line of numbers after it)");
  std::vector<size_t> non_empty;
  for (size_t k = start; k < b.data_start; ++k)
    if (!all_empty(t.fields(k))) non_empty.push_back(k);
  if (non_empty.empty()) throw InputError(t.at(b.data_start), "no column names row before the data");
  b.names_line = non_empty.back();
  const auto f = t.fields(b.names_line);
  const size_t n = used_fields(f);
  bool units = n > 0;
  for (size_t c = 0; c < n; ++c)
    if (!f[c].text.empty() && !is_unit_cell(f[c].text)) units = false;
  if (units) {
    if (non_empty.size() < 2) throw InputError(t.at(b.names_line), "a units row without a column names row above it");
    b.units_line = b.names_line;
    b.names_line = non_empty[non_empty.size() - 2];
  }
  return b;
}

// One column from its name cell and its units-row cell (empty without a units row):
// the unit gives the quantity and the factor to SI; only a strain may have no unit.
ExportColumn read_column(const ExportText& t, const BlockLayout& b, const Field& name, const std::string& unit_cell,
                         size_t c) {
  ExportColumn col;
  col.label = name.text;
  if (col.label.empty()) throw InputError(t.at(b.names_line), "column " + std::to_string(c + 1) + " has no name");
  name_and_unit(col.label, col.name, col.unit);
  if (b.units_line && !unit_cell.empty()) {
    col.unit = strip_brackets(unit_cell);
    col.label += " (" + col.unit + ")";
  }
  const bool strain_name = lower(col.name).find("strain") != std::string::npos;
  if (col.unit.empty()) {
    if (!strain_name)
      throw InputError(t.at(b.names_line), "column '" + col.name +
                                               "' has no unit: missing units row (units go in a row under the names "
                                               "or in the names, e.g. 'Load (N)')");
    col.quantity = ExportQuantity::strain;
    col.to_si = 1.0;
  } else {
    const auto info = unit_info(lower(col.unit));
    if (!info)
      throw InputError(t.at(b.units_line ? *b.units_line : b.names_line),
                       "column '" + col.name + "': unrecognised unit '" + col.unit +
                           "' (known: s, ms, min, h; mm, m, cm, um, in; N, kN, mN, lbf, kgf; Pa, kPa, MPa, GPa, "
                           "N/mm^2, psi; %, mm/mm, m/m, -)");
    col.quantity = info->quantity;
    col.to_si = info->to_si;
  }
  return col;
}

// The block's columns (names, units, SI factors), checked against the data rows' width.
std::vector<ExportColumn> read_columns(const ExportText& t, const BlockLayout& b) {
  const auto names = t.fields(b.names_line);
  const size_t n_cols = used_fields(names);
  const size_t data_fields = used_fields(t.fields(b.data_start));
  if (n_cols != data_fields)
    throw InputError(t.at(b.names_line), "the column names row has " + std::to_string(n_cols) + " field(s) with " +
                                             sep_name(t.sep) + " as separator but the data rows have " +
                                             std::to_string(data_fields) + " (wrong separator or missing names)");
  std::vector<Field> units;
  if (b.units_line) {
    units = t.fields(*b.units_line);
    if (used_fields(units) > n_cols)
      throw InputError(t.at(*b.units_line), "the units row has more fields than the column names row");
  }
  std::vector<ExportColumn> columns;
  for (size_t c = 0; c < n_cols; ++c)
    columns.push_back(read_column(t, b, names[c], c < units.size() ? units[c].text : std::string(), c));
  return columns;
}

// Data rows from b.data_start until a blank line followed by a non-number row (the
// next block) or the end; returns the line after the block.
size_t read_data_rows(const ExportText& t, const BlockLayout& b, std::vector<ExportColumn>& columns) {
  std::vector<std::string> labels;
  for (const auto& col : columns) labels.push_back(col.label);
  size_t k = b.data_start;
  bool blank_seen = false;
  for (; k < t.lines.size(); ++k) {
    const auto f = t.fields(k);
    if (all_empty(f)) {
      blank_seen = true;
      continue;
    }
    if (blank_seen && !(numeric_row(f, t.sep) && used_fields(f) == columns.size())) break;
    blank_seen = false;
    parse_data_row(f, t.sep, t.lines[k], t.at(k), columns, labels);
  }
  return k;
}

// The specimen's label from the first header key that names one ("" if none).
std::string specimen_label(const std::map<std::string, std::string>& header) {
  std::string label;
  for (const char* key : {"specimen label", "specimen name", "specimen", "sample", "name"}) {
    for (const auto& [hk, hv] : header)
      if (lower(hk) == key && !hv.empty()) label = hv;
    if (!label.empty()) break;
  }
  return label;
}

// The block at b: header key/value pairs above the names, columns, data rows; `next`
// is the line after it.
SpecimenExport read_block(const ExportText& t, const BlockLayout& b, size_t& next) {
  SpecimenExport block;
  block.file = t.file;
  block.first_line = static_cast<int>(b.start + 1);
  for (size_t k = b.start; k < b.names_line; ++k) {
    const auto f = t.fields(k);
    if (f.size() >= 2 && !f[0].text.empty()) block.header[f[0].text] = f[1].text;
  }
  block.columns = read_columns(t, b);
  next = read_data_rows(t, b, block.columns);
  block.label = specimen_label(block.header);
  return block;
}

}  // namespace

std::vector<SpecimenExport> parse_test_machine_export(const std::string& text, const std::string& file) {
  const std::vector<std::string> lines = split_lines(text);
  const ExportText t{lines, detect_separator(lines, file), file};
  std::vector<SpecimenExport> blocks;
  size_t i = 0;
  while (i < lines.size()) {
    // Skip blank lines between blocks.
    while (i < lines.size() && all_empty(t.fields(i))) ++i;
    if (i >= lines.size()) break;
    blocks.push_back(read_block(t, locate_block(t, i), i));
  }
  if (blocks.empty()) throw InputError(file, "no specimen blocks");
  const std::string stem = std::filesystem::path(file).stem().string();
  for (size_t b = 0; b < blocks.size(); ++b)
    if (blocks[b].label.empty()) blocks[b].label = blocks.size() > 1 ? stem + "#" + std::to_string(b + 1) : stem;
  return blocks;
}

std::vector<SpecimenExport> read_test_machine_export(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "cannot open the test-machine export");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_test_machine_export(text.str(), path);
}

std::vector<SpecimenExport> read_test_machine_exports(const std::vector<std::string>& files_or_dirs) {
  namespace fs = std::filesystem;
  std::vector<SpecimenExport> all;
  for (const auto& p : files_or_dirs) {
    std::vector<std::string> files;
    if (fs::is_directory(p)) {
      for (const auto& e : fs::directory_iterator(p)) {
        const std::string ext = lower(e.path().extension().string());
        if (e.is_regular_file() && (ext == ".csv" || ext == ".txt" || ext == ".tsv"))
          files.push_back(e.path().string());
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) throw InputError(p, "no *.csv, *.txt or *.tsv exports in the folder");
    } else {
      files.push_back(p);
    }
    for (const auto& f : files) {
      auto blocks = read_test_machine_export(f);
      all.insert(all.end(), std::make_move_iterator(blocks.begin()), std::make_move_iterator(blocks.end()));
    }
  }
  return all;
}

}  // namespace morphfem
