// Result files for ParaView: one HDF5 file with the data and one XDMF (XML) file
// that describes it as a time series on the tetrahedral mesh.
//
//   DIR/NAME.h5    /mesh/X             n_nodes x 3  float64, reference coordinates [m]
//                  /mesh/cells         n_cells x 4|10 int32, VTK node ordering
//                  /mesh/cell_region   n_cells int32 (only if mesh.cell_region is complete);
//                                      attribute "names": "ID NAME" per volume region
//                  /steps/NNNNNN/<f>   n x components float64 (n for scalars);
//                                      group attribute "time"; dataset attribute "center"
//                  /tables/<t>         rows x columns float64, attribute "columns"
//   DIR/NAME.xdmf  Temporal collection of one Uniform grid per step.
//
// Open NAME.xdmf in ParaView ("Xdmf Reader" or "Xdmf3 Reader S/T"). The geometry
// is always the reference configuration; apply "Warp By Vector" with the nodal
// vector "displacement" (enforced: nodal, 3 components) for the deformed shape.
// Cell field "region" (from mesh.cell_region) works with "Threshold".
//
// The writer is SERIAL: construct it on rank 0 only; the caller gathers nodal
// and cell data (in global numbering) to rank 0 before write_step/append_row.
// The HDF5 file is opened with the default (POSIX) driver, never MPI-IO.
//
// Crash safety: after every write_step/append_row the .h5 is flushed and the
// .xdmf is rewritten atomically (temporary file + rename), so the XDMF only ever
// names flushed steps and a run that dies leaves files readable up to the last
// completed step. The .h5 is opened without HDF5 file locking so ParaView/h5py
// can read it while a run is still writing (between steps).
#pragma once
#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "mesh/mesh.h"

namespace morphfem {

struct Field {                 // one array on the mesh
  std::string name;            // e.g. "displacement", "J", "von_mises", "region"
  int components = 1;          // 1 (scalar), 3 (vector); also 6 (symmetric tensor) or 9 (tensor)
  std::vector<double> values;  // n_nodes*components (nodal) or n_cells*components (cell), row-major
};

class ResultWriter {
 public:
  // Creates (truncates) DIR/NAME.h5 and DIR/NAME.xdmf; DIR must exist. Writes the
  // geometry (reference coordinates X) and topology (Tetrahedron for P1,
  // Tetrahedron_10 for P2) once. Throws std::runtime_error on a bad mesh or I/O error.
  ResultWriter(const std::string& dir, const std::string& name, const Mesh& mesh);
  // Resumes DIR/NAME.h5 and DIR/NAME.xdmf of an earlier writer on the same mesh (a
  // run continued from a checkpoint at time resume_after [s]): checks that the file
  // holds this mesh, drops the steps and table rows after resume_after (written
  // after the checkpoint) and appends from there. Throws std::runtime_error if the
  // file is missing or holds another mesh.
  ResultWriter(const std::string& dir, const std::string& name, const Mesh& mesh, double resume_after);
  ~ResultWriter();  // closes the files; never throws (call close() to see errors)
  ResultWriter(const ResultWriter&) = delete;
  ResultWriter& operator=(const ResultWriter&) = delete;

  // Appends one time step with nodal and cell fields. Times must be finite and
  // strictly increasing. Every field is checked before anything is written:
  // a NaN/inf value, a wrong array size, a bad or duplicate name throws
  // std::runtime_error naming the field and the step, and nothing is written.
  // If the mesh has complete cell regions, a cell field "region" is added to
  // every step automatically (stored once) unless the step supplies its own.
  void write_step(double time, const std::vector<Field>& nodal, const std::vector<Field>& cell);

  // Appends one row to table /tables/TABLE (e.g. "cavities": time, pressure,
  // volume per cavity; or energies per step). The first call fixes the columns
  // (stored as attribute "columns"); later calls must pass the same columns.
  // Non-finite values are rejected like in fields.
  void append_row(const std::string& table, const std::vector<std::string>& columns, const std::vector<double>& row);

  int steps_written() const { return steps_; }
  // Closes the HDF5 file (idempotent); later writes throw.
  void close();

  const std::string& h5_path() const { return h5_path_; }
  const std::string& xdmf_path() const { return xdmf_path_; }

 private:
  struct Table {
    std::vector<std::string> columns;
    long rows = 0;
  };
  void write_xdmf() const;
  void check_mesh(const std::string& dir, const std::string& name, const Mesh& mesh);  // and sets the paths
  // Runs `fill` on the file just opened; if it throws, closes the file and rethrows.
  void fill_or_close(const std::function<void()>& fill);
  std::string grid_xml(const std::string& label, double time, const std::vector<Field>& nodal,
                       const std::vector<Field>& cell) const;

  std::string h5_name_, h5_path_, xdmf_path_;
  std::int64_t file_ = -1;  // hid_t; kept as int64 so hdf5.h stays out of this header
  int order_ = 1, n_nodes_ = 0, n_cells_ = 0;
  bool have_regions_ = false;
  int steps_ = 0;
  double last_time_ = 0;
  std::vector<std::string> grids_;  // XDMF <Grid> text of each written step
  std::map<std::string, Table> tables_;
};

// Output directories that appear only when a run ends: results are written to
// FINAL.partial/ while running and renamed to FINAL by commit_output_dir at the
// end of a successful (or gracefully failed, e.g. SolveError after the completed
// steps were written) run. An existing FINAL is left untouched until then.
//
// temporary_output_dir creates FINAL.partial (and missing parent directories),
// deleting a leftover FINAL.partial of an earlier crashed run, and returns it.
std::string temporary_output_dir(const std::string& final_dir);
// Renames TMP to FINAL. If FINAL exists (a directory), it is first moved aside
// to FINAL.old, then TMP is renamed to FINAL, then the old one is deleted; if the
// second rename fails the old FINAL is restored. Refuses to replace a non-directory.
void commit_output_dir(const std::string& tmp, const std::string& final_dir);
// Deletes TMP (for runs that stop on bad input: no partial output is left behind).
void discard_output_dir(const std::string& tmp);

}  // namespace morphfem
