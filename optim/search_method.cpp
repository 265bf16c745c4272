#include "optim/search_method.h"

#include <functional>

#include "core/errors.h"
#include "core/strings.h"
#include "optim/cmaes.h"
#include "optim/hill_climber.h"

namespace morphfem {

namespace {
using Factory = std::function<std::unique_ptr<SearchMethod>(const SearchSetup&)>;

const std::map<std::string, Factory>& methods() {
  static const std::map<std::string, Factory> m = {
      {"hill", [](const SearchSetup& s) { return std::make_unique<HillClimber>(s); }},
      {"cmaes", [](const SearchSetup& s) { return std::make_unique<CmaEs>(s); }},
  };
  return m;
}
}  // namespace

std::unique_ptr<SearchMethod> make_search_method(const std::string& name, const SearchSetup& setup) {
  auto it = methods().find(name);
  if (it == methods().end()) {
    throw InputError("--method",
                     "unknown search method '" + name + "' (known: " + join(search_method_names(), ", ") + ")");
  }
  return it->second(setup);
}

std::vector<std::string> search_method_names() {
  std::vector<std::string> names;
  for (const auto& [n, f] : methods()) names.push_back(n);
  return names;
}

std::vector<double> genomes_to_array(const std::vector<Genome>& genomes) {
  std::vector<double> a;
  for (const auto& g : genomes) {
    const auto v = genome_to_vector(g);
    a.insert(a.end(), v.begin(), v.end());
  }
  return a;
}

std::vector<Genome> genomes_from_array(const std::vector<double>& a, const std::string& where) {
  if (a.size() % kGenomeLength != 0) throw InputError(where, "genome array length is not a multiple of 22");
  std::vector<Genome> out;
  for (size_t i = 0; i < a.size(); i += kGenomeLength) {
    std::array<double, kGenomeLength> v;
    std::copy(a.begin() + i, a.begin() + i + kGenomeLength, v.begin());
    out.push_back(genome_from_vector(v, where + ": genome " + std::to_string(i / kGenomeLength + 1)));
  }
  return out;
}

std::vector<double> history_to_array(const std::vector<std::vector<double>>& history) {
  std::vector<double> a;
  for (const auto& row : history) a.insert(a.end(), row.begin(), row.end());
  return a;
}

std::vector<std::vector<double>> history_from_array(const std::vector<double>& a, int runs, const std::string& where) {
  if (runs < 1 || a.size() % runs != 0) throw InputError(where, "history length is not a multiple of the runs");
  std::vector<std::vector<double>> h;
  for (size_t i = 0; i < a.size(); i += runs) h.emplace_back(a.begin() + i, a.begin() + i + runs);
  return h;
}

}  // namespace morphfem
