// `morphfem verify [--case NAME]... [--hard] [--quick] [--json] [--out DIR]`.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include "app/commands.h"
#include "core/command_line.h"
#include "core/json.h"
#include "core/plot.h"
#include "core/strings.h"
#include "verify/verify.h"

namespace morphfem {

namespace {

void print_table(const std::vector<VerificationRecord>& records) {
  std::printf("%-11s %-48s %3s %2s %9s %8s %12s %12s %9s %6s %8s %6s\n", "case", "quantity", "lvl", "P", "h [m]",
              "dofs", "value", "reference", "rel_err", "rate", "wall_s", "newton");
  for (const auto& r : records)
    std::printf("%-11s %-48s %3d %2d %9.3g %8ld %12.6g %12.6g %9.2e %6s %8.2f %6d\n", r.case_name.c_str(),
                r.quantity.c_str(), r.level, r.order, r.h, r.dofs, r.value, r.reference, r.rel_error,
                r.rate != 0 ? std::to_string(r.rate).substr(0, 5).c_str() : "-", r.wall_s, r.newton_its);
}

}  // namespace

int verify_command(const std::vector<std::string>& args, MPI_Comm comm) {
  CommandLine cl("morphfem verify", "[options] [PETSc options]",
                 "Runs the verification cases against exact or published references: the error of each level "
                 "beside its wall time and Newton iterations, convergence rates, a JSON line per record and "
                 "PNG plots.");
  cl.repeated("--case", "NAME",
              "runs this case only (cases: " + join(verification_case_names(false), ", ") +
                  "; with --hard: " + join(verification_case_names(true), ", ") + ")")
      .flag("--hard", "the hard cases (near-incompressible, large rotation, contact, self-contact, gas)")
      .flag("--quick", "the coarse levels only")
      .flag("--json", "JSON lines on standard output instead of the table")
      .value("--out", "DIR", "where verification.jsonl and the plots go (default results/verify)")
      .petsc_options();
  if (!cl.parse(args, std::cout)) return 0;
  VerifyOptions options;
  options.cases = cl.all("--case");
  options.quick = cl.has("--quick");
  options.hard = cl.has("--hard");
  const bool json = cl.has("--json");
  const std::string out_dir = cl.get("--out", "results/verify");
  options.progress = !json;
  const auto records = run_verification(options, comm);
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  if (rank != 0) return 0;
  std::string lines;
  for (const auto& r : records) lines += r.json() + "\n";
  if (json)
    std::fputs(lines.c_str(), stdout);
  else
    print_table(records);
  std::filesystem::create_directories(out_dir);
  const std::string jsonl = out_dir + "/verification.jsonl";
  write_file_atomic(jsonl, lines);
  run_plot_script("plot_verification.py", {jsonl, out_dir}, "the verification");
  if (!json) std::printf("records: %s; plots: %s/*.png\n", jsonl.c_str(), out_dir.c_str());
  return 0;
}

}  // namespace morphfem
