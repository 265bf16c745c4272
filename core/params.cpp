#include "core/params.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/strings.h"

namespace morphfem {

void ParamSet::set(const std::string& key, std::vector<double> values, std::string where) {
  numbers_[key] = std::move(values);
  strings_.erase(key);
  where_[key] = std::move(where);
}

void ParamSet::set_string(const std::string& key, std::string value, std::string where) {
  strings_[key] = std::move(value);
  numbers_.erase(key);
  where_[key] = std::move(where);
}

bool ParamSet::has(const std::string& key) const { return numbers_.count(key) > 0 || strings_.count(key) > 0; }

std::string ParamSet::where(const std::string& key) const {
  auto it = where_.find(key);
  std::string loc = (it != where_.end() && !it->second.empty()) ? it->second + ": " : "";
  return loc + (context_.empty() ? key : context_ + "." + key);
}

ParamSet ParamSet::without(const std::string& key) const {
  ParamSet out = *this;
  out.numbers_.erase(key);
  out.strings_.erase(key);
  out.where_.erase(key);
  return out;
}

std::vector<std::string> ParamSet::keys() const {
  std::vector<std::string> out;
  for (auto& [k, v] : numbers_) out.push_back(k);
  for (auto& [k, v] : strings_) out.push_back(k);
  return out;
}

std::vector<double> ParamSet::list(const std::string& key) const {
  auto it = numbers_.find(key);
  if (it == numbers_.end()) {
    if (strings_.count(key)) throw InputError(where(key), "expected a number, got text");
    throw InputError(context_, "missing required key '" + key + "'");
  }
  for (double v : it->second)
    if (!std::isfinite(v)) throw InputError(where(key), "value is not a finite number");
  return it->second;
}

std::vector<double> ParamSet::list(const std::string& key, std::vector<double> fallback) const {
  return has(key) ? list(key) : fallback;
}

double ParamSet::number(const std::string& key) const {
  auto v = list(key);
  if (v.size() != 1) throw InputError(where(key), "expected one number, got " + std::to_string(v.size()));
  return v[0];
}

double ParamSet::number(const std::string& key, double fallback) const { return has(key) ? number(key) : fallback; }

double ParamSet::number_in(const std::string& key, double lo, double hi) const {
  double v = number(key);
  if (v < lo || v > hi) {
    std::ostringstream s;
    s << "value " << v << " is outside the allowed range [" << lo << ", " << hi << "]";
    throw InputError(where(key), s.str());
  }
  return v;
}

double ParamSet::number_in(const std::string& key, double lo, double hi, double fallback) const {
  return has(key) ? number_in(key, lo, hi) : fallback;
}

int ParamSet::integer_in(const std::string& key, int lo, int hi, int fallback) const {
  if (!has(key)) return fallback;
  double v = number_in(key, lo, hi);
  if (v != std::floor(v)) throw InputError(where(key), "expected an integer");
  return static_cast<int>(v);
}

std::string ParamSet::string(const std::string& key) const {
  auto it = strings_.find(key);
  if (it == strings_.end()) {
    if (numbers_.count(key)) throw InputError(where(key), "expected text, got a number");
    throw InputError(context_, "missing required key '" + key + "'");
  }
  return it->second;
}

std::string ParamSet::string(const std::string& key, const std::string& fallback) const {
  return has(key) ? string(key) : fallback;
}

void ParamSet::allow_only(const std::set<std::string>& allowed) const {
  for (const auto& k : keys()) {
    if (!allowed.count(k)) {
      throw InputError(where(k), "unknown key '" + k + "' (allowed: " + join(allowed, ", ") + ")");
    }
  }
}

}  // namespace morphfem
