#include "core/command_line.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/errors.h"
#include "core/json.h"
#include "core/strings.h"
#include "core/test_machine_export.h"

namespace morphfem {

namespace {

// "-snes_monitor", "-ksp_type" (a letter after one dash), not "-1.5" nor "--out".
bool is_petsc_option(const std::string& word) {
  return word.size() > 1 && word[0] == '-' && word[1] != '-' && std::isalpha(static_cast<unsigned char>(word[1]));
}

bool is_long_option(const std::string& word) { return word.size() > 2 && word.compare(0, 2, "--") == 0; }

// Wraps `text` at 88 columns with every line indented by `indent` spaces.
std::string wrapped(const std::string& text, int indent) {
  std::string out, line;
  std::istringstream words(text);
  for (std::string word; words >> word;) {
    if (!line.empty() && line.size() + 1 + word.size() + indent > 88) {
      out += std::string(indent, ' ') + line + "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) out += std::string(indent, ' ') + line + "\n";
  return out;
}

}  // namespace

CommandLine::CommandLine(std::string command, std::string synopsis, std::string description)
    : command_(std::move(command)), synopsis_(std::move(synopsis)), description_(std::move(description)) {}

void CommandLine::add(Option option) {
  if (option.name.size() < 3 || option.name.compare(0, 2, "--") != 0 || find(option.name))
    throw std::logic_error(command_ + ": option '" + option.name + "' is malformed or declared twice");
  options_.push_back(std::move(option));
}

CommandLine& CommandLine::flag(const std::string& name, const std::string& help) {
  add({name, "", help, Kind::flag});
  return *this;
}

CommandLine& CommandLine::value(const std::string& name, const std::string& metavar, const std::string& help) {
  add({name, metavar, help, Kind::value});
  return *this;
}

CommandLine& CommandLine::repeated(const std::string& name, const std::string& metavar, const std::string& help) {
  add({name, metavar, help + " (repeatable)", Kind::repeated});
  return *this;
}

CommandLine& CommandLine::positionals(int min, int max, const std::string& metavar) {
  min_positional_ = min;
  max_positional_ = max;
  positional_metavar_ = metavar;
  return *this;
}

CommandLine& CommandLine::petsc_options() {
  petsc_ = true;
  return *this;
}

CommandLine& CommandLine::epilog(const std::string& text) {
  epilog_ = text;
  return *this;
}

const CommandLine::Option* CommandLine::find(const std::string& name) const {
  for (const Option& o : options_)
    if (o.name == name) return &o;
  return nullptr;
}

const CommandLine::Option& CommandLine::declared(const std::string& name) const {
  const Option* o = find(name);
  if (!o) throw std::logic_error(command_ + ": option '" + name + "' read but never declared");
  return *o;
}

std::string CommandLine::usage() const {
  std::string out = "usage: " + command_ + (synopsis_.empty() ? "" : " " + synopsis_) + "\n";
  out += wrapped(description_, 2);
  if (!options_.empty()) out += "options:\n";
  for (const Option& o : options_) {
    const std::string head = "  " + o.name + (o.metavar.empty() ? "" : " " + o.metavar);
    out += head + "\n" + wrapped(o.help, 8);
  }
  out += "  -h, --help\n        this text\n";
  if (petsc_) out += "PETSc options (-snes_monitor, -ksp_type preonly, ...) follow the arguments above.\n";
  if (!epilog_.empty()) out += wrapped(epilog_, 0);
  return out;
}

bool CommandLine::parse(const std::vector<std::string>& args, std::ostream& out) {
  given_.clear();
  positional_.clear();
  if (std::find(args.begin(), args.end(), "--help") != args.end() ||
      std::find(args.begin(), args.end(), "-h") != args.end()) {
    out << usage();
    return false;
  }
  const std::string see = " (see " + command_ + " --help)";
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& word = args[i];
    if (is_long_option(word)) {
      const auto eq = word.find('=');
      const std::string name = word.substr(0, eq);
      const Option* o = find(name);
      if (!o) throw InputError(command_, "unknown option '" + name + "'" + see);
      if (o->kind == Kind::flag) {
        if (eq != std::string::npos) throw InputError(command_, name + " takes no value" + see);
        given_[name].push_back("");
        continue;
      }
      if (eq != std::string::npos) {
        given_[name].push_back(word.substr(eq + 1));
        continue;
      }
      if (i + 1 >= args.size() || is_long_option(args[i + 1]))
        throw InputError(command_, name + " needs a value (" + name + " " + o->metavar + ")");
      given_[name].push_back(args[++i]);
      if (o->kind == Kind::value && given_[name].size() > 1) throw InputError(command_, name + " given more than once");
    } else if (petsc_ && is_petsc_option(word)) {
      if (i + 1 < args.size() && !args[i + 1].empty() && args[i + 1][0] != '-') ++i;  // its value
    } else if (!word.empty() && word[0] == '-' && word.size() > 1 &&
               !std::isdigit(static_cast<unsigned char>(word[1]))) {
      throw InputError(command_, "unknown option '" + word + "'" + see);
    } else {
      positional_.push_back(word);
    }
  }
  const int n = static_cast<int>(positional_.size());
  if (n < min_positional_)
    throw InputError(command_, "missing " + positional_metavar_ + " (usage: " + command_ + " " + synopsis_ + ")");
  if (max_positional_ >= 0 && n > max_positional_)
    throw InputError(command_, "unexpected argument '" + positional_[max_positional_] + "'" + see);
  return true;
}

bool CommandLine::has(const std::string& name) const {
  declared(name);
  return given_.count(name) > 0;
}

std::string CommandLine::get(const std::string& name, const std::string& fallback) const {
  const std::vector<std::string>& values = all(name);
  return values.empty() ? fallback : values.back();
}

const std::vector<std::string>& CommandLine::all(const std::string& name) const {
  static const std::vector<std::string> none;
  declared(name);
  const auto it = given_.find(name);
  return it == given_.end() ? none : it->second;
}

double CommandLine::number(const std::string& name, double fallback, double lo, double hi) const {
  if (!has(name)) return fallback;
  double v = 0;
  const std::string text = get(name, "");
  if (!parse_export_number(text, false, v) || !(v >= lo && v <= hi))
    throw InputError(command_,
                     name + " '" + text + "' must be a number in [" + json_number(lo) + ", " + json_number(hi) + "]");
  return v;
}

int CommandLine::integer(const std::string& name, int fallback, int lo, int hi) const {
  const double v = number(name, fallback, lo, hi);
  if (v != std::floor(v)) throw InputError(command_, name + " '" + get(name, "") + "' must be a whole number");
  return static_cast<int>(v);
}

namespace {

std::string subcommand_usage(const std::string& command, const std::vector<Subcommand>& subcommands) {
  size_t width = 0;
  for (const Subcommand& s : subcommands) width = std::max(width, std::string(s.name).size());
  std::string out = "usage: " + command + " COMMAND [options]\ncommands:\n";
  for (const Subcommand& s : subcommands)
    out += "  " + std::string(s.name) + std::string(width + 2 - std::string(s.name).size(), ' ') + s.summary + "\n";
  return out + command + " COMMAND --help tells a command's options.\n";
}

}  // namespace

int run_subcommand(const std::string& command, const std::vector<Subcommand>& subcommands,
                   const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  if (args.empty()) {
    err << subcommand_usage(command, subcommands);
    return 2;
  }
  if (args[0] == "--help" || args[0] == "-h") {
    out << subcommand_usage(command, subcommands);
    return 0;
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  for (const Subcommand& s : subcommands)
    if (args[0] == s.name) return s.run(rest);
  throw InputError(command, "unknown command '" + args[0] + "'\n" + subcommand_usage(command, subcommands));
}

double number_option(const std::string& command, const std::string& option, const std::string& text, double lo,
                     double hi) {
  double v;
  if (!parse_export_number(text, false, v) || v < lo || v > hi)
    throw InputError("calibrate " + command,
                     option + " '" + text + "' must be a number in [" + json_number(lo) + ", " + json_number(hi) + "]");
  return v;
}

std::vector<std::string> split_list(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream s(list);
  for (std::string item; std::getline(s, item, ',');)
    if (!item.empty()) out.push_back(item);
  return out;
}

}  // namespace morphfem
