#include "core/json.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace morphfem {

std::string json_number(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

Json& Json::add(const std::string& key, double v) {
  fields_.emplace_back(key, json_number(v));
  return *this;
}
Json& Json::add(const std::string& key, int v) {
  fields_.emplace_back(key, std::to_string(v));
  return *this;
}
Json& Json::add(const std::string& key, long v) {
  fields_.emplace_back(key, std::to_string(v));
  return *this;
}
Json& Json::add(const std::string& key, bool v) {
  fields_.emplace_back(key, v ? "true" : "false");
  return *this;
}
Json& Json::add(const std::string& key, const std::string& v) {
  fields_.emplace_back(key, json_string(v));
  return *this;
}
Json& Json::add(const std::string& key, const std::vector<double>& v) {
  std::string s = "[";
  for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + json_number(v[i]);
  fields_.emplace_back(key, s + "]");
  return *this;
}
Json& Json::add(const std::string& key, const Json& object) {
  fields_.emplace_back(key, object.str());
  return *this;
}
Json& Json::add(const std::string& key, const std::vector<Json>& objects) {
  std::string s = "[";
  for (size_t i = 0; i < objects.size(); ++i) s += (i ? ", " : "") + objects[i].str();
  fields_.emplace_back(key, s + "]");
  return *this;
}

std::string Json::str(bool pretty, int indent) const {
  std::string pad(pretty ? indent + 2 : 0, ' ');
  std::string s = "{";
  for (size_t i = 0; i < fields_.size(); ++i) {
    if (i) s += ",";
    if (pretty) {
      s += '\n';
      s += pad;
    } else if (i) {
      s += ' ';
    }
    s += json_string(fields_[i].first) + ": " + fields_[i].second;
  }
  if (pretty && !fields_.empty()) {
    s += '\n';
    s.append(indent, ' ');
  }
  return s + "}";
}

void write_file_atomic(const std::string& path, const std::string& text) {
  std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("cannot write " + tmp);
    f << text;
    if (!f.flush()) throw std::runtime_error("cannot write " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

}  // namespace morphfem
