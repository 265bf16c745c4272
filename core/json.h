// Minimal JSON writer for run summaries and verification lines (one object per
// line). Keys keep insertion order; non-finite numbers are written as null.
#pragma once
#include <string>
#include <utility>
#include <vector>

namespace morphfem {

class Json {
 public:
  Json& add(const std::string& key, double v);
  Json& add(const std::string& key, int v);
  Json& add(const std::string& key, long v);
  Json& add(const std::string& key, bool v);
  Json& add(const std::string& key, const char* v) { return add(key, std::string(v)); }
  Json& add(const std::string& key, const std::string& v);
  Json& add(const std::string& key, const std::vector<double>& v);
  Json& add(const std::string& key, const Json& object);
  Json& add(const std::string& key, const std::vector<Json>& objects);
  std::string str(bool pretty = false, int indent = 0) const;

 private:
  std::vector<std::pair<std::string, std::string>> fields_;  // key -> encoded value
};

std::string json_number(double v);
std::string json_string(const std::string& s);

// Writes text to `path` atomically (temporary file + rename): a reader never sees
// a half-written file and an existing file is replaced only on success.
void write_file_atomic(const std::string& path, const std::string& text);

}  // namespace morphfem
