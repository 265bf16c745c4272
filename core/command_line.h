// One command-line dialect for every command:
//   * `--help` or `-h` anywhere prints the command's usage to standard output and the
//     command exits 0 (CommandLine::parse returns false);
//   * options are declared with their help text, which is the usage: a flag
//     (`--resume`), an option with one value (`--out DIR`), or a repeatable one
//     (`--set KEY=VALUE`, every value kept in order); `--name=value` is `--name value`;
//   * an unknown option, a missing value, a flag given a value, or a wrong number of
//     positional arguments is an InputError naming the command (exit 2);
//   * commands that run PETSc let its single-dash options through
//     (`-snes_monitor`, `-ksp_type preonly`): a single-dash token and the bare token
//     after it belong to PETSc, so positional arguments come first.
#pragma once
#include <functional>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace morphfem {

class CommandLine {
 public:
  // `command`: "morphfem robot validate"; `synopsis`: the arguments after it
  // ("SCENE.yaml [options]"); `description`: what the command does (wrapped text).
  CommandLine(std::string command, std::string synopsis, std::string description);

  CommandLine& flag(const std::string& name, const std::string& help);
  CommandLine& value(const std::string& name, const std::string& metavar, const std::string& help);
  CommandLine& repeated(const std::string& name, const std::string& metavar, const std::string& help);
  // Positional arguments: at least `min`, at most `max` (-1: any number).
  CommandLine& positionals(int min, int max, const std::string& metavar);
  // Lets PETSc's single-dash options through (they are read by PetscInitialize).
  CommandLine& petsc_options();
  // A paragraph after the options (examples, notes).
  CommandLine& epilog(const std::string& text);

  // Parses `args` (the words after the command). Returns false if help was asked for
  // (the usage went to `out`); throws InputError on a malformed command line.
  bool parse(const std::vector<std::string>& args, std::ostream& out);
  std::string usage() const;

  bool has(const std::string& name) const;  // given at least once (flags: given)
  std::string get(const std::string& name, const std::string& fallback) const;
  const std::vector<std::string>& all(const std::string& name) const;  // every value, in order
  // The value as a number in [lo, hi] (InputError naming the option otherwise).
  double number(const std::string& name, double fallback, double lo, double hi) const;
  int integer(const std::string& name, int fallback, int lo, int hi) const;
  const std::vector<std::string>& positional() const { return positional_; }
  const std::string& command() const { return command_; }

 private:
  enum class Kind { flag, value, repeated };
  struct Option {
    std::string name, metavar, help;
    Kind kind;
  };
  const Option* find(const std::string& name) const;
  const Option& declared(const std::string& name) const;
  void add(Option option);

  std::string command_, synopsis_, description_, epilog_, positional_metavar_;
  std::vector<Option> options_;
  int min_positional_ = 0, max_positional_ = 0;
  bool petsc_ = false;
  std::map<std::string, std::vector<std::string>> given_;
  std::vector<std::string> positional_;
};

// A command made of subcommands (`morphfem robot validate ...`): their names, one-line
// summaries and what runs them on the words after the name.
struct Subcommand {
  const char* name;
  const char* summary;
  std::function<int(const std::vector<std::string>&)> run;
};

// Runs the subcommand args[0] names with the words after it. No argument: the list of
// subcommands on `err`, status 2; --help or -h: the list on `out`, status 0; an unknown
// name: InputError naming `command` ("morphfem robot") with the list.
int run_subcommand(const std::string& command, const std::vector<Subcommand>& subcommands,
                   const std::vector<std::string>& args, std::ostream& out, std::ostream& err);

// A numeric option in [lo, hi]; InputError naming "calibrate COMMAND" and the option
// otherwise.
double number_option(const std::string& command, const std::string& option, const std::string& text, double lo,
                     double hi);

// A comma-separated list ("a,b,,c" -> {a, b, c}).
std::vector<std::string> split_list(const std::string& list);

}  // namespace morphfem
