// ParamSet: a typed, located bag of named numeric/string parameters.
// Physics modules (materials, geometries, loads) read their parameters from a
// ParamSet and never see YAML; every value remembers where it came from so an
// error can name the file, line and key.
#pragma once
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace morphfem {

class ParamSet {
 public:
  ParamSet() = default;
  explicit ParamSet(std::string context) : context_(std::move(context)) {}

  // Building (used by the scene reader and by code that makes parameters).
  void set(const std::string& key, std::vector<double> values, std::string where = "");
  void set(const std::string& key, double value, std::string where = "") {
    set(key, std::vector<double>{value}, std::move(where));
  }
  void set_string(const std::string& key, std::string value, std::string where = "");

  // Reading. Missing keys, wrong arity or values outside [lo, hi] throw InputError
  // naming the location and the key.
  double number(const std::string& key) const;
  double number(const std::string& key, double fallback) const;
  double number_in(const std::string& key, double lo, double hi) const;
  double number_in(const std::string& key, double lo, double hi, double fallback) const;
  int integer_in(const std::string& key, int lo, int hi, int fallback) const;
  std::vector<double> list(const std::string& key) const;
  std::vector<double> list(const std::string& key, std::vector<double> fallback) const;
  std::string string(const std::string& key) const;
  std::string string(const std::string& key, const std::string& fallback) const;
  bool has(const std::string& key) const;

  // A copy without `key` (e.g. density, which belongs to the scene, not the law).
  ParamSet without(const std::string& key) const;

  // Rejects keys not in `allowed` (typos must not be silently ignored).
  void allow_only(const std::set<std::string>& allowed) const;

  // Location of a key for error messages ("file:line:col: ctx.key" or the context).
  std::string where(const std::string& key) const;
  const std::string& context() const { return context_; }
  std::vector<std::string> keys() const;

 private:
  std::string context_;
  std::map<std::string, std::vector<double>> numbers_;
  std::map<std::string, std::string> strings_;
  std::map<std::string, std::string> where_;
};

}  // namespace morphfem
