// Every key a scene file may hold, declared once: its path, type, unit, default,
// allowed range or values and a one-line description. The scene readers
// (sim/scene_reader.h) refuse keys the table does not declare and check each
// declared simple bound on a number; docs/scene-keys.md is printed from the same
// table (`morphfem scene-keys`).
//
// Paths are dotted as in the error messages ("contact.ground.kappa"); the keys of
// the mappings inside a list are under the list's path ("loads.cavities.pressure"
// for each cavity's pressure), and a segment in angle brackets stands for a name
// the scene chooses ("materials.<region>.model").
#pragma once
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace morphfem {

enum class KeyType {
  number,         // a real number
  integer,        // a whole number
  boolean,        // true or false
  text,           // a name or other text
  choice,         // one of the listed names
  file,           // a file name, relative to the scene's folder
  names,          // a name or a list of names
  axis,           // x, y or z
  axes,           // a list of axes, e.g. [x, y]
  vector3,        // [x, y, z]
  mapping,        // a mapping of the keys below it
  list,           // a list of mappings of the keys below it
  time_function,  // a number ramped 0 -> value over the run, or a table [[t, value], ...]
  calibrated,     // a number or {calibration: FILE, parameter: NAME}
  coefficient,    // a number, a table [[t, value], ...] or a calibrated value (held constant)
  table,          // a table [[t, value], ...] (piecewise linear)
  pairs,          // a list of pairs of names [[a, b], ...]
  schedule,       // a schedule file, or the schedule inline (a mapping)
  parameters,     // a mapping of parameters (numbers, lists of numbers, text, calibrated values)
};
const char* key_type_name(KeyType type);

// A simple bound on a number, lo < x or lo <= x, and x < hi or x <= hi.
struct KeyRange {
  double lo = -std::numeric_limits<double>::infinity();
  double hi = std::numeric_limits<double>::infinity();
  bool lo_open = false, hi_open = false;

  bool contains(double v) const;
  std::string text() const;  // "> 0", ">= 1", "[-90, 90]"
};

struct SceneKey {
  std::string path;
  KeyType type = KeyType::number;
  std::string unit;                  // "[Pa]", "[-]" for a pure number, "" for what is not a number
  std::string fallback;              // the value if absent, "required", or "" (absent: not used)
  std::optional<KeyRange> range;     // checked on every value read (integers must also be whole)
  std::vector<std::string> choices;  // the allowed values of a choice, in order
  std::string limits;                // a constraint beyond a simple bound, for the documentation
  std::string doc;

  // The requirement a value outside `range` breaks: "must be positive [Pa]".
  std::string requirement() const;
};

// The table, in the order of the documentation.
const std::vector<SceneKey>& scene_keys();
// The declared key `path` matches (its bracketed segments match any name), or null.
const SceneKey* find_scene_key(const std::string& path);
// The names of the keys a mapping at `path` may hold ("" for the scene's top level),
// sorted; a mapping of chosen names (materials, actuation.bladders) has none.
std::vector<std::string> scene_key_children(const std::string& path);
// docs/scene-keys.md: the table as Markdown, one section per top-level key.
std::string scene_keys_markdown();

}  // namespace morphfem
