#include "optim/search_partial.h"

#include <algorithm>
#include <filesystem>
#include <regex>

#include "core/errors.h"
#include "core/state_file.h"
#include "optim/checkpoint.h"

namespace morphfem {

namespace {
// Every partial file in `dir`, sorted (the same order on every rank).
std::vector<std::string> partial_files(const std::string& dir) {
  static const std::regex name(R"(partial_team_\d+\.h5)");
  std::vector<std::string> files;
  if (!std::filesystem::is_directory(dir)) return files;
  for (const auto& entry : std::filesystem::directory_iterator(dir))
    if (std::regex_match(entry.path().filename().string(), name)) files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}
}  // namespace

std::string partial_step_path(const std::string& dir, int team) {
  return dir + "/partial_team_" + std::to_string(team) + ".h5";
}

void write_partial_step(const std::string& path, const SearchState& meta, long step, const std::vector<Genome>& batch,
                        const BatchSpeeds& speeds) {
  SearchState s = meta;
  s.integers["step"] = step;
  s.integers["batch"] = static_cast<long>(batch.size());
  std::vector<double> index, genes, value;
  for (const auto& [i, v] : speeds) {
    if (i >= batch.size()) throw std::logic_error("write_partial_step: index outside the batch");
    index.push_back(static_cast<double>(i));
    const auto g = genome_to_vector(batch[i]);
    genes.insert(genes.end(), g.begin(), g.end());
    value.push_back(v);
  }
  s.arrays["index"] = index;
  s.arrays["genes"] = genes;
  s.arrays["speed"] = value;
  write_state_file(path, s);
}

PartialSteps read_partial_steps(const std::string& dir, const SearchState& meta, long step,
                                const std::vector<Genome>& batch) {
  PartialSteps out;
  out.files = partial_files(dir);
  for (const auto& path : out.files) {
    const SearchState s = read_state_file(path);
    check_metadata(s, meta, path);
    const auto& index = s.array("index", path);
    const long n = static_cast<long>(index.size());
    const auto& genes = s.array("genes", path, n * kGenomeLength);
    const auto& speed = s.array("speed", path, n);
    if (s.integer("step", path) != step || s.integer("batch", path) != static_cast<long>(batch.size())) {
      out.stale += n;  // a finished step's leftovers (killed between checkpoint and clean-up)
      continue;
    }
    for (long k = 0; k < n; ++k) {
      const double x = index[k];
      if (!(x >= 0) || x >= static_cast<double>(batch.size()) || x != static_cast<double>(static_cast<long>(x)))
        throw InputError(path, "evaluation " + std::to_string(k + 1) + " has index " + std::to_string(x) +
                                   ", outside the batch of " + std::to_string(batch.size()));
      const auto i = static_cast<std::size_t>(x);
      const auto g = genome_to_vector(batch[i]);
      if (!std::equal(g.begin(), g.end(), genes.begin() + k * kGenomeLength)) {
        ++out.stale;  // the method proposes another genome here (e.g. a longer run's last CMA-ES iteration)
        continue;
      }
      auto [it, inserted] = out.speeds.emplace(i, speed[k]);
      // Bitwise: -inf (a failed evaluation) equals itself, and no NaN is ever saved.
      if (!inserted && it->second != speed[k])
        throw InputError(path, "evaluation " + std::to_string(i) + " of step " + std::to_string(step) + " has speed " +
                                   std::to_string(speed[k]) + " here and " + std::to_string(it->second) +
                                   " in another partial file");
    }
  }
  return out;
}

void remove_partial_steps(const std::string& dir) {
  for (const auto& path : partial_files(dir)) std::filesystem::remove(path);
}

}  // namespace morphfem
