// Reader for materials-testing-machine exports (Instron Bluehill "RawData" CSV,
// the Soft Robotics Materials Database exports, and hand-made tables of the same
// shape). One file holds one or several specimen blocks; each block is
//
//   header block   key<sep>value[<sep>...] lines: specimen parameters
//                  ("Specimen Length (mm);33", "Surface;wood", "Foot state;inflated")
//   (blank line)   optional
//   names row      column names, units in the names ("Time (s)", "Load [N]") ...
//   units row      ... or a separate row of units under the names ("(s)", "mm", "[N]")
//   data rows      numbers, one per column
//
// Blocks are separated by a blank line followed by a line that is not a number row
// (Bluehill's one-file-per-specimen folders `Specimen_RawData_N.csv` are read as
// one block per file; pass a folder to read them all).
//
// Dialect, detected per file: separator ';', tab or ',' (the one that splits the
// most lines into all-numeric rows of >= 2 fields; ties: tab, ';', ','); decimal
// comma ("1,25") accepted when the separator is not ',' or the value is quoted;
// double-quoted fields with "" escapes; CRLF line ends; a UTF-8 BOM.
//
// Columns are recognised by their units and converted to SI:
//   time         s, ms, min, h                        -> s
//   displacement mm, m, cm, um (µm), in               -> m
//   force        N, kN, mN, lbf, kgf                  -> N
//   stress       Pa, kPa, MPa, GPa, N/mm^2, psi       -> Pa
//   strain       %, mm/mm, m/m, -, or none if the name says "strain"  -> [-]
// A column without a unit whose name is not a strain is an error ("missing units
// row"), as is an unknown unit.
//
// Malformed input -> InputError("file:line", reason): no data rows, missing or
// unknown units, a data row with fewer fields than columns (truncated line) or
// with an empty field, a row that splits with another separator than the file's
// (wrong separator), text in a numeric column, a names row whose field count does
// not match the data.
#pragma once
#include <map>
#include <string>
#include <vector>

namespace morphfem {

enum class ExportQuantity { time, displacement, force, stress, strain };

const char* quantity_name(ExportQuantity q);

struct ExportColumn {
  std::string name;   // as written, without the unit ("Extension")
  std::string label;  // as written in the names row ("Extension (mm)")
  std::string unit;   // as written ("mm"; "" for a unitless strain)
  ExportQuantity quantity = ExportQuantity::time;
  double to_si = 1.0;          // SI value = to_si * written value
  std::vector<double> values;  // SI: s, m, N, Pa, [-]
};

struct SpecimenExport {
  std::string file;                           // source file
  int first_line = 1;                         // 1-based line where the block starts
  std::string label;                          // header "Specimen"/"Specimen label"/"Sample", else file stem (#k)
  std::map<std::string, std::string> header;  // specimen parameters as written, key -> value
  std::vector<ExportColumn> columns;
  size_t rows() const { return columns.empty() ? 0 : columns.front().values.size(); }

  // First column of quantity q whose name contains `name_hint` (case-insensitive;
  // "" matches any) and none of the words in `exclude`; nullptr if none.
  const ExportColumn* find(ExportQuantity q, const std::string& name_hint = "",
                           const std::vector<std::string>& exclude = {}) const;
  // The header value whose key contains `key_part` (case-insensitive), "" if none.
  std::string header_value(const std::string& key_part) const;
  // A header number with a length / area / speed unit in its key, in SI
  // ("Specimen Length (mm)" -> m); returns false if absent or not a number.
  bool header_si(const std::string& key_part, double& value) const;
  // "file:line" of the block, for error messages.
  std::string where() const { return file + ":" + std::to_string(first_line); }
};

// Parses the text of one export (`file` only names it in errors).
std::vector<SpecimenExport> parse_test_machine_export(const std::string& text, const std::string& file);
// Reads one file.
std::vector<SpecimenExport> read_test_machine_export(const std::string& path);
// Reads files and folders (every *.csv, *.txt, *.tsv in a folder, sorted by name).
std::vector<SpecimenExport> read_test_machine_exports(const std::vector<std::string>& files_or_dirs);

// Number in an export: '.' or (if allowed) ',' as decimal mark; false if not a number.
bool parse_export_number(const std::string& text, bool decimal_comma, double& value);

}  // namespace morphfem
