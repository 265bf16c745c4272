// Errors that reach the user. An InputError names the file, the key or line, and
// what is wrong; the program prints it and exits non-zero without writing results.
#pragma once
#include <stdexcept>
#include <string>

namespace morphfem {

// Bad user input: a scene, mesh, schedule, data export or device reply.
// `where` is "file:line:column" or "file: key.path"; `what` says what is wrong.
class InputError : public std::runtime_error {
 public:
  InputError(const std::string& where, const std::string& what)
      : std::runtime_error(where.empty() ? what : where + ": " + what), where_(where) {}
  const std::string& where() const { return where_; }

 private:
  std::string where_;
};

// A solve that failed after all recovery (step cuts) was exhausted.
class SolveError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace morphfem
