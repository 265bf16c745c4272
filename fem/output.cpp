#include "fem/output.h"

#include <hdf5.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <system_error>

#include "core/json.h"
#include "core/log_event.h"

// XDMF dialect. We write `<Xdmf Version="2.0">`: every ParaView reader for .xdmf
// (the legacy "Xdmf Reader" and "Xdmf3 Reader S/T") reads version-2 files, while
// XDMF-3 features (XInclude/xpointer to share one Geometry) are handled only by
// the Xdmf3 readers and differ between versions. Instead of xpointers, each
// step's Uniform grid repeats the same HDF5 references (NAME.h5:/mesh/X and
// NAME.h5:/mesh/cells): plain, supported everywhere, and the data is stored
// once. File references are relative to the .xdmf, so the output directory can
// be renamed or moved (FINAL.partial -> FINAL) without breaking them.
// "Tetrahedron_10" is accepted by both readers (Xdmf2 also knows it as "Tet_10");
// its node order is VTK_QUADRATIC_TETRA's, which is the Mesh ordering.

namespace morphfem {
namespace fs = std::filesystem;

namespace {

// ---------------------------------------------------------------- HDF5 errors

// HDF5 prints its error stack to stderr by default; while the writer runs we
// turn that off and put the stack into the exception message instead.
class QuietHdf5 {
 public:
  QuietHdf5() {
    if (H5Eget_auto2(H5E_DEFAULT, &func_, &data_) < 0) func_ = nullptr, data_ = nullptr, ok_ = false;
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() {
    if (ok_) H5Eset_auto2(H5E_DEFAULT, func_, data_);
  }
  QuietHdf5(const QuietHdf5&) = delete;
  QuietHdf5& operator=(const QuietHdf5&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
  bool ok_ = true;
};

herr_t collect_error(unsigned n, const H5E_error2_t* e, void* out) {
  auto* s = static_cast<std::string*>(out);
  if (n > 0) *s += "; ";
  *s += e->func_name ? e->func_name : "?";
  *s += ": ";
  *s += e->desc ? e->desc : "?";
  return 0;
}

[[noreturn]] void hdf5_fail(const std::string& what) {
  std::string stack;
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, collect_error, &stack);
  H5Eclear2(H5E_DEFAULT);
  throw std::runtime_error("HDF5 error: " + what + (stack.empty() ? "" : " (" + stack + ")"));
}

hid_t check_id(hid_t id, const std::string& what) {
  if (id < 0) hdf5_fail(what);
  return id;
}
void check(herr_t status, const std::string& what) {
  if (status < 0) hdf5_fail(what);
}

// Owns one HDF5 identifier and closes it with the matching H5*close.
class Handle {
 public:
  Handle(hid_t id, herr_t (*closer)(hid_t), const std::string& what) : id_(check_id(id, what)), closer_(closer) {}
  ~Handle() {
    if (id_ >= 0) closer_(id_);
  }
  Handle(Handle&& other) noexcept : id_(other.id_), closer_(other.closer_) { other.id_ = -1; }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
  Handle& operator=(Handle&&) = delete;
  hid_t get() const { return id_; }
  // Close now and report failure (the destructor cannot).
  void close(const std::string& what) {
    hid_t id = id_;
    id_ = -1;
    check(closer_(id), what);
  }

 private:
  hid_t id_;
  herr_t (*closer_)(hid_t);
};

// File access without HDF5 file locking: lets ParaView/h5py open the file while a
// run is writing.
Handle unlocked_access() {
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "H5Pcreate(file access)");
#if H5_VERSION_GE(1, 10, 7)
  check(H5Pset_file_locking(fapl.get(), 0, 1), "H5Pset_file_locking");
#endif
  return fapl;
}

// Link-creation property list that creates missing intermediate groups.
Handle make_lcpl() {
  Handle lcpl(H5Pcreate(H5P_LINK_CREATE), H5Pclose, "H5Pcreate(link create)");
  check(H5Pset_create_intermediate_group(lcpl.get(), 1), "H5Pset_create_intermediate_group");
  return lcpl;
}

void write_string_attribute(hid_t obj, const std::string& name, const std::vector<std::string>& values, bool scalar) {
  size_t len = 1;
  for (const auto& v : values) len = std::max(len, v.size() + 1);
  std::vector<char> buf(len * values.size(), '\0');
  for (size_t i = 0; i < values.size(); ++i) std::copy(values[i].begin(), values[i].end(), buf.begin() + i * len);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "H5Tcopy");
  check(H5Tset_size(type.get(), len), "H5Tset_size");
  check(H5Tset_strpad(type.get(), H5T_STR_NULLTERM), "H5Tset_strpad");
  hsize_t n = values.size();
  Handle space(scalar ? H5Screate(H5S_SCALAR) : H5Screate_simple(1, &n, nullptr), H5Sclose,
               "H5Screate for attribute " + name);
  Handle attr(H5Acreate2(obj, name.c_str(), type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "H5Acreate2 " + name);
  check(H5Awrite(attr.get(), type.get(), buf.data()), "H5Awrite " + name);
  attr.close("H5Aclose " + name);
}

void write_double_attribute(hid_t obj, const std::string& name, double value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "H5Screate");
  Handle attr(H5Acreate2(obj, name.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose,
              "H5Acreate2 " + name);
  check(H5Awrite(attr.get(), H5T_NATIVE_DOUBLE, &value), "H5Awrite " + name);
  attr.close("H5Aclose " + name);
}

// Creates dataset `path` (with missing parent groups) and writes `data` into it.
// Returns the open dataset so attributes can be added.
Handle write_dataset(hid_t file, const std::string& path, hid_t file_type, hid_t mem_type,
                     const std::vector<hsize_t>& dims, const void* data) {
  Handle space(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr), H5Sclose,
               "H5Screate_simple for " + path);
  Handle lcpl = make_lcpl();
  Handle dset(H5Dcreate2(file, path.c_str(), file_type, space.get(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Dclose,
              "H5Dcreate2 " + path);
  check(H5Dwrite(dset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), "H5Dwrite " + path);
  return dset;
}

// ---------------------------------------------------------------- text helpers

std::string number(double v) {
  char buf[64];
  auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  if (ec != std::errc()) throw std::runtime_error("cannot format number");
  return std::string(buf, end);
}

std::string xml_escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

// Names end up in HDF5 paths and XDMF text ("file.h5:/steps/000000/name"), so
// keep them to a safe set of characters.
void check_name(const std::string& name, const std::string& kind) {
  bool ok = !name.empty() && name.size() <= 128 && name[0] != '.';
  for (char c : name) {
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == '+')) ok = false;
  }
  if (!ok) {
    throw std::runtime_error("ResultWriter: invalid " + kind + " name '" + name +
                             "' (use letters, digits, '_', '-', '.', '+'; not starting with '.')");
  }
}

std::string step_label(int step) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%06d", step);
  return buf;
}

const char* attribute_type(int components) {
  switch (components) {
    case 1:
      return "Scalar";
    case 3:
      return "Vector";
    case 6:
      return "Tensor6";
    case 9:
      return "Tensor";
  }
  return "";
}

std::string dims_text(int rows, int components) {
  return components == 1 ? std::to_string(rows) : std::to_string(rows) + " " + std::to_string(components);
}

std::string data_item(const std::string& dims, const char* number_type, int precision, const std::string& ref) {
  return "<DataItem Dimensions=\"" + dims + "\" NumberType=\"" + number_type + "\" Precision=\"" +
         std::to_string(precision) + "\" Format=\"HDF\">" + xml_escape(ref) + "</DataItem>";
}

std::string attribute_xml(const std::string& name, int components, const char* center, int rows,
                          const std::string& ref) {
  return "        <Attribute Name=\"" + xml_escape(name) + "\" AttributeType=\"" + attribute_type(components) +
         "\" Center=\"" + center + "\">\n          " + data_item(dims_text(rows, components), "Float", 8, ref) +
         "\n        </Attribute>\n";
}

fs::path normalized_dir(const std::string& dir, const char* what) {
  fs::path p = fs::path(dir).lexically_normal();
  if (!p.empty() && !p.has_filename()) p = p.parent_path();  // "out/" -> "out"
  if (p.empty() || p.filename() == "." || p.filename() == ".." || p == p.root_path()) {
    throw std::runtime_error(std::string(what) + ": not a usable output directory: '" + dir + "'");
  }
  return p;
}

}  // namespace

// ---------------------------------------------------------------- ResultWriter

ResultWriter::ResultWriter(const std::string& dir, const std::string& name, const Mesh& mesh) {
  check_mesh(dir, name, mesh);
  QuietHdf5 quiet;
  file_ = check_id(H5Fcreate(h5_path_.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, unlocked_access().get()),
                   "cannot create " + h5_path_);
  fill_or_close([&] {
    std::vector<hsize_t> xdims{static_cast<hsize_t>(n_nodes_), 3};
    write_dataset(file_, "/mesh/X", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, xdims, mesh.X.data()).close("H5Dclose /mesh/X");
    std::vector<hsize_t> cdims{static_cast<hsize_t>(n_cells_), static_cast<hsize_t>(mesh.nodes_per_cell())};
    write_dataset(file_, "/mesh/cells", H5T_STD_I32LE, H5T_NATIVE_INT, cdims, mesh.cells.data())
        .close("H5Dclose /mesh/cells");
    if (have_regions_) {
      std::vector<hsize_t> rdims{static_cast<hsize_t>(n_cells_)};
      auto regions =
          write_dataset(file_, "/mesh/cell_region", H5T_STD_I32LE, H5T_NATIVE_INT, rdims, mesh.cell_region.data());
      // "names": "ID NAME" per volume region, so that scripts find a region by name.
      std::vector<std::string> names;
      for (const auto& r : mesh.regions)
        if (r.dim == 3) names.push_back(std::to_string(r.id) + " " + r.name);
      if (!names.empty()) write_string_attribute(regions.get(), "names", names, false);
      regions.close("H5Dclose /mesh/cell_region");
    }
    check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "H5Fflush " + h5_path_);
    write_xdmf();
  });
}

void ResultWriter::check_mesh(const std::string& dir, const std::string& name, const Mesh& mesh) {
  check_name(name, "output file");
  if (!fs::is_directory(dir)) throw std::runtime_error("ResultWriter: output directory '" + dir + "' does not exist");
  if (mesh.order != 1 && mesh.order != 2) {
    throw std::runtime_error("ResultWriter: mesh order must be 1 or 2, got " + std::to_string(mesh.order));
  }
  order_ = mesh.order;
  n_nodes_ = mesh.n_nodes();
  n_cells_ = mesh.n_cells();
  const int npc = mesh.nodes_per_cell();
  if (n_nodes_ == 0 || n_cells_ == 0) throw std::runtime_error("ResultWriter: empty mesh");
  if (mesh.X.cols() != 3) {
    throw std::runtime_error("ResultWriter: mesh.X has " + std::to_string(mesh.X.cols()) + " columns, expected 3");
  }
  if (mesh.cells.cols() != npc) {
    throw std::runtime_error("ResultWriter: mesh.cells has " + std::to_string(mesh.cells.cols()) +
                             " columns, expected " + std::to_string(npc) + " for order " + std::to_string(order_));
  }
  for (Eigen::Index i = 0; i < mesh.X.size(); ++i) {
    if (!std::isfinite(mesh.X.data()[i])) throw std::runtime_error("ResultWriter: non-finite mesh coordinate");
  }
  for (Eigen::Index i = 0; i < mesh.cells.size(); ++i) {
    int v = mesh.cells.data()[i];
    if (v < 0 || v >= n_nodes_) {
      throw std::runtime_error("ResultWriter: cell " + std::to_string(i / npc) + " refers to node " +
                               std::to_string(v) + " of " + std::to_string(n_nodes_));
    }
  }
  have_regions_ = static_cast<int>(mesh.cell_region.size()) == n_cells_;

  h5_name_ = name + ".h5";
  h5_path_ = (fs::path(dir) / h5_name_).string();
  xdmf_path_ = (fs::path(dir) / (name + ".xdmf")).string();
}

namespace {

// A dataset read whole as doubles or ints, with its dimensions.
template <class T>
std::vector<T> read_whole(hid_t file, const std::string& path, hid_t mem_type, std::vector<hsize_t>& dims) {
  Handle d(H5Dopen2(file, path.c_str(), H5P_DEFAULT), H5Dclose, "H5Dopen2 " + path);
  Handle space(H5Dget_space(d.get()), H5Sclose, "H5Dget_space " + path);
  const int rank = H5Sget_simple_extent_ndims(space.get());
  dims.assign(std::max(rank, 0), 0);
  if (rank > 0) H5Sget_simple_extent_dims(space.get(), dims.data(), nullptr);
  hsize_t n = 1;
  for (hsize_t k : dims) n *= k;
  std::vector<T> values(n);
  if (n > 0) check(H5Dread(d.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()), "H5Dread " + path);
  return values;
}

// Fixed-length string attribute (scalar or 1-D), as written by write_string_attribute.
std::vector<std::string> read_string_attribute(hid_t obj, const std::string& name) {
  Handle attr(H5Aopen(obj, name.c_str(), H5P_DEFAULT), H5Aclose, "H5Aopen " + name);
  Handle type(H5Aget_type(attr.get()), H5Tclose, "H5Aget_type " + name);
  Handle space(H5Aget_space(attr.get()), H5Sclose, "H5Aget_space " + name);
  const size_t len = H5Tget_size(type.get());
  const hssize_t n = std::max<hssize_t>(H5Sget_simple_extent_npoints(space.get()), 1);
  std::vector<char> buf(len * n, '\0');
  check(H5Aread(attr.get(), type.get(), buf.data()), "H5Aread " + name);
  std::vector<std::string> out;
  for (hssize_t i = 0; i < n; ++i) out.emplace_back(buf.data() + i * len, strnlen(buf.data() + i * len, len));
  return out;
}

struct StepField {
  std::string name;
  int components;
  std::string center;
};

herr_t collect_step_field(hid_t group, const char* name, const H5L_info_t*, void* out) {
  Handle d(H5Dopen2(group, name, H5P_DEFAULT), H5Dclose, std::string("H5Dopen2 ") + name);
  Handle space(H5Dget_space(d.get()), H5Sclose, "H5Dget_space");
  hsize_t dims[2] = {0, 1};
  const int rank = H5Sget_simple_extent_dims(space.get(), dims, nullptr);
  const std::string center = read_string_attribute(d.get(), "center").at(0);
  static_cast<std::vector<StepField>*>(out)->push_back({name, rank == 2 ? static_cast<int>(dims[1]) : 1, center});
  return 0;
}

herr_t collect_name(hid_t, const char* name, const H5L_info_t*, void* out) {
  static_cast<std::vector<std::string>*>(out)->push_back(name);
  return 0;
}

}  // namespace

ResultWriter::ResultWriter(const std::string& dir, const std::string& name, const Mesh& mesh, double resume_after) {
  check_mesh(dir, name, mesh);
  const std::string where = "ResultWriter: resuming " + h5_path_;
  if (!fs::exists(h5_path_)) throw std::runtime_error(where + ": no such file");
  QuietHdf5 quiet;
  file_ = check_id(H5Fopen(h5_path_.c_str(), H5F_ACC_RDWR, unlocked_access().get()), "cannot open " + h5_path_);
  fill_or_close([&] {
    // The file must hold this very mesh.
    std::vector<hsize_t> dims;
    const auto X = read_whole<double>(file_, "/mesh/X", H5T_NATIVE_DOUBLE, dims);
    const auto cells = read_whole<int>(file_, "/mesh/cells", H5T_NATIVE_INT, dims);
    if (X.size() != static_cast<size_t>(mesh.X.size()) || !std::equal(X.begin(), X.end(), mesh.X.data()) ||
        cells.size() != static_cast<size_t>(mesh.cells.size()) ||
        !std::equal(cells.begin(), cells.end(), mesh.cells.data()))
      throw std::runtime_error(where + ": its mesh differs from this run's");
    // Steps: keep those at or before resume_after, drop the rest (written after the checkpoint).
    const double eps = 1e-12 * std::max(1.0, std::abs(resume_after));
    for (int step = 0;; ++step) {
      const std::string label = step_label(step), group = "/steps/" + label;
      if (H5Lexists(file_, "/steps", H5P_DEFAULT) <= 0 || H5Lexists(file_, group.c_str(), H5P_DEFAULT) <= 0) break;
      double time = 0;
      {
        Handle g(H5Gopen2(file_, group.c_str(), H5P_DEFAULT), H5Gclose, "H5Gopen2 " + group);
        Handle attr(H5Aopen(g.get(), "time", H5P_DEFAULT), H5Aclose, "H5Aopen time " + group);
        check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &time), "H5Aread time " + group);
        if (time <= resume_after + eps && step == steps_) {
          std::vector<StepField> fields;
          hsize_t idx = 0;
          check(H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect_step_field, &fields),
                "H5Literate2 " + group);
          std::vector<Field> nodal, cell;  // names and components only
          for (const auto& f : fields) (f.center == "Node" ? nodal : cell).push_back(Field{f.name, f.components, {}});
          grids_.push_back(grid_xml(label, time, nodal, cell));
          ++steps_;
          last_time_ = time;
          continue;
        }
      }
      check(H5Ldelete(file_, group.c_str(), H5P_DEFAULT), "H5Ldelete " + group);
    }
    // Tables: rows whose time (first column) is after resume_after go.
    std::vector<std::string> tables;
    if (H5Lexists(file_, "/tables", H5P_DEFAULT) > 0) {
      hsize_t idx = 0;
      Handle g(H5Gopen2(file_, "/tables", H5P_DEFAULT), H5Gclose, "H5Gopen2 /tables");
      check(H5Literate(g.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, collect_name, &tables), "H5Literate2 /tables");
    }
    for (const auto& table : tables) {
      const std::string path = "/tables/" + table;
      const auto values = read_whole<double>(file_, path, H5T_NATIVE_DOUBLE, dims);
      if (dims.size() != 2 || dims[1] == 0) throw std::runtime_error(where + ": " + path + " is not a table");
      long rows = 0;
      while (rows < static_cast<long>(dims[0]) && values[rows * dims[1]] <= resume_after + eps) ++rows;
      Handle d(H5Dopen2(file_, path.c_str(), H5P_DEFAULT), H5Dclose, "H5Dopen2 " + path);
      hsize_t newdims[2] = {static_cast<hsize_t>(rows), dims[1]};
      check(H5Dset_extent(d.get(), newdims), "H5Dset_extent " + path);
      tables_[table] = Table{read_string_attribute(d.get(), "columns"), rows};
    }
    check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "H5Fflush " + h5_path_);
    write_xdmf();
  });
}

void ResultWriter::fill_or_close(const std::function<void()>& fill) {
  try {
    fill();
  } catch (...) {
    H5Fclose(file_);
    file_ = -1;
    throw;
  }
}

ResultWriter::~ResultWriter() {
  try {
    close();
  } catch (...) {
    // Destructors must not throw; close() explicitly to see the error.
  }
}

void ResultWriter::close() {
  if (file_ < 0) return;
  QuietHdf5 quiet;
  hid_t f = file_;
  file_ = -1;
  check(H5Fclose(f), "H5Fclose " + h5_path_);
}

void ResultWriter::write_step(double time, const std::vector<Field>& nodal, const std::vector<Field>& cell) {
  LogEventScope scope("OutputStep");
  const std::string label = step_label(steps_);
  const std::string where = "ResultWriter: step " + std::to_string(steps_) + " (t=" + number(time) + ")";
  if (file_ < 0) throw std::runtime_error(where + ": writer is closed");
  if (!std::isfinite(time)) throw std::runtime_error(where + ": time is not finite");
  if (steps_ > 0 && !(time > last_time_)) {
    throw std::runtime_error(where + ": time must increase (previous step at t=" + number(last_time_) + ")");
  }

  // Validate everything first so a rejected step writes nothing.
  std::vector<std::string> names;
  auto validate = [&](const Field& f, int rows, const char* kind) {
    check_name(f.name, std::string(kind) + " field");
    if (std::find(names.begin(), names.end(), f.name) != names.end()) {
      throw std::runtime_error(where + ": field '" + f.name + "' given twice");
    }
    names.push_back(f.name);
    if (attribute_type(f.components)[0] == '\0') {
      throw std::runtime_error(where + ": field '" + f.name + "' has " + std::to_string(f.components) +
                               " components (allowed: 1, 3, 6, 9)");
    }
    if (f.name == "displacement" && (std::string(kind) != "nodal" || f.components != 3)) {
      // ParaView's "Warp By Vector" needs a point (nodal) vector.
      throw std::runtime_error(where + ": field 'displacement' must be a nodal field with 3 components");
    }
    const size_t expected = static_cast<size_t>(rows) * f.components;
    if (f.values.size() != expected) {
      throw std::runtime_error(where + ": " + kind + " field '" + f.name + "' has " + std::to_string(f.values.size()) +
                               " values, expected " + std::to_string(rows) +
                               (std::string(kind) == "nodal" ? " nodes" : " cells") + " x " +
                               std::to_string(f.components) + " = " + std::to_string(expected));
    }
    for (size_t i = 0; i < f.values.size(); ++i) {
      if (!std::isfinite(f.values[i])) {
        throw std::runtime_error(where + ": " + kind + " field '" + f.name + "' has a non-finite value (" +
                                 number(f.values[i]) + ") at " + (std::string(kind) == "nodal" ? "node " : "cell ") +
                                 std::to_string(i / f.components) + ", component " + std::to_string(i % f.components));
      }
    }
  };
  for (const Field& f : nodal) validate(f, n_nodes_, "nodal");
  for (const Field& f : cell) validate(f, n_cells_, "cell");

  QuietHdf5 quiet;
  const std::string group = "/steps/" + label;
  {
    Handle lcpl = make_lcpl();
    Handle g(H5Gcreate2(file_, group.c_str(), lcpl.get(), H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "H5Gcreate2 " + group);
    write_double_attribute(g.get(), "time", time);
    g.close("H5Gclose " + group);
  }

  auto write_fields = [&](const std::vector<Field>& fields, int rows, const char* center) {
    for (const Field& f : fields) {
      const std::string path = group + "/" + f.name;
      std::vector<hsize_t> dims{static_cast<hsize_t>(rows)};
      if (f.components > 1) dims.push_back(static_cast<hsize_t>(f.components));
      Handle d = write_dataset(file_, path, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, dims, f.values.data());
      write_string_attribute(d.get(), "center", {center}, true);
      d.close("H5Dclose " + path);
    }
  };
  write_fields(nodal, n_nodes_, "Node");
  write_fields(cell, n_cells_, "Cell");
  std::string xml = grid_xml(label, time, nodal, cell);

  check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "H5Fflush " + h5_path_);
  grids_.push_back(std::move(xml));
  ++steps_;
  last_time_ = time;
  write_xdmf();
}

// XDMF <Grid> of one step: the mesh and the step's fields (only names and
// components are used), plus the stored regions unless the step has its own.
std::string ResultWriter::grid_xml(const std::string& label, double time, const std::vector<Field>& nodal,
                                   const std::vector<Field>& cell) const {
  const char* topology = order_ == 1 ? "Tetrahedron" : "Tetrahedron_10";
  const int npc = order_ == 1 ? 4 : 10;
  const std::string group = "/steps/" + label;
  std::string xml = "      <Grid Name=\"step_" + label + "\" GridType=\"Uniform\">\n";
  xml += "        <Time Value=\"" + number(time) + "\"/>\n";
  xml += "        <Topology TopologyType=\"" + std::string(topology) + "\" NumberOfElements=\"" +
         std::to_string(n_cells_) + "\" NodesPerElement=\"" + std::to_string(npc) + "\">\n          " +
         data_item(dims_text(n_cells_, npc), "Int", 4, h5_name_ + ":/mesh/cells") + "\n        </Topology>\n";
  xml += "        <Geometry GeometryType=\"XYZ\">\n          " +
         data_item(dims_text(n_nodes_, 3), "Float", 8, h5_name_ + ":/mesh/X") + "\n        </Geometry>\n";
  bool has_region = false;
  for (const Field& f : nodal) {
    xml += attribute_xml(f.name, f.components, "Node", n_nodes_, h5_name_ + ":" + group + "/" + f.name);
    has_region = has_region || f.name == "region";
  }
  for (const Field& f : cell) {
    xml += attribute_xml(f.name, f.components, "Cell", n_cells_, h5_name_ + ":" + group + "/" + f.name);
    has_region = has_region || f.name == "region";
  }
  if (have_regions_ && !has_region) {
    // Stored once in /mesh; 32-bit integers.
    xml += "        <Attribute Name=\"region\" AttributeType=\"Scalar\" Center=\"Cell\">\n          " +
           data_item(std::to_string(n_cells_), "Int", 4, h5_name_ + ":/mesh/cell_region") + "\n        </Attribute>\n";
  }
  xml += "      </Grid>\n";
  return xml;
}

void ResultWriter::write_xdmf() const {
  std::string s =
      "<?xml version=\"1.0\" ?>\n"
      "<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n"
      "<!-- morphfem results: reference geometry + fields per time step; data in " +
      xml_escape(h5_name_) +
      " -->\n"
      "<Xdmf Version=\"2.0\">\n"
      "  <Domain>\n";
  if (grids_.empty()) {
    // No step yet: just the mesh, so even a run that dies early can be inspected.
    const char* topology = order_ == 1 ? "Tetrahedron" : "Tetrahedron_10";
    const int npc = order_ == 1 ? 4 : 10;
    s += "    <Grid Name=\"mesh\" GridType=\"Uniform\">\n";
    s += "      <Topology TopologyType=\"" + std::string(topology) + "\" NumberOfElements=\"" +
         std::to_string(n_cells_) + "\" NodesPerElement=\"" + std::to_string(npc) + "\">\n        " +
         data_item(dims_text(n_cells_, npc), "Int", 4, h5_name_ + ":/mesh/cells") + "\n      </Topology>\n";
    s += "      <Geometry GeometryType=\"XYZ\">\n        " +
         data_item(dims_text(n_nodes_, 3), "Float", 8, h5_name_ + ":/mesh/X") + "\n      </Geometry>\n";
    if (have_regions_) {
      s += "      <Attribute Name=\"region\" AttributeType=\"Scalar\" Center=\"Cell\">\n        " +
           data_item(std::to_string(n_cells_), "Int", 4, h5_name_ + ":/mesh/cell_region") + "\n      </Attribute>\n";
    }
    s += "    </Grid>\n";
  } else {
    s += "    <Grid Name=\"TimeSeries\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
    for (const auto& g : grids_) s += g;
    s += "    </Grid>\n";
  }
  s += "  </Domain>\n</Xdmf>\n";
  write_file_atomic(xdmf_path_, s);
}

void ResultWriter::append_row(const std::string& table, const std::vector<std::string>& columns,
                              const std::vector<double>& row) {
  LogEventScope scope("OutputRow");
  const std::string where = "ResultWriter: table '" + table + "'";
  if (file_ < 0) throw std::runtime_error(where + ": writer is closed");
  check_name(table, "table");
  if (columns.empty()) throw std::runtime_error(where + ": no columns");
  if (row.size() != columns.size()) {
    throw std::runtime_error(where + ": row has " + std::to_string(row.size()) + " values for " +
                             std::to_string(columns.size()) + " columns");
  }
  auto it = tables_.find(table);
  if (it != tables_.end() && it->second.columns != columns) {
    throw std::runtime_error(where + ": columns differ from the first row's");
  }
  for (size_t i = 0; i < row.size(); ++i) {
    if (!std::isfinite(row[i])) {
      throw std::runtime_error(where + ": non-finite value (" + number(row[i]) + ") in column '" + columns[i] +
                               "' of row " + std::to_string(it == tables_.end() ? 0 : it->second.rows));
    }
  }

  QuietHdf5 quiet;
  const std::string path = "/tables/" + table;
  const hsize_t ncols = columns.size();
  if (it == tables_.end()) {
    hsize_t dims[2] = {0, ncols}, maxdims[2] = {H5S_UNLIMITED, ncols}, chunk[2] = {64, ncols};
    Handle space(H5Screate_simple(2, dims, maxdims), H5Sclose, "H5Screate_simple " + path);
    Handle dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "H5Pcreate(dataset create)");
    check(H5Pset_chunk(dcpl.get(), 2, chunk), "H5Pset_chunk " + path);
    Handle lcpl = make_lcpl();
    Handle d(H5Dcreate2(file_, path.c_str(), H5T_IEEE_F64LE, space.get(), lcpl.get(), dcpl.get(), H5P_DEFAULT),
             H5Dclose, "H5Dcreate2 " + path);
    write_string_attribute(d.get(), "columns", columns, false);
    d.close("H5Dclose " + path);
    it = tables_.emplace(table, Table{columns, 0}).first;
  }
  Table& t = it->second;
  Handle d(H5Dopen2(file_, path.c_str(), H5P_DEFAULT), H5Dclose, "H5Dopen2 " + path);
  hsize_t newdims[2] = {static_cast<hsize_t>(t.rows + 1), ncols};
  check(H5Dset_extent(d.get(), newdims), "H5Dset_extent " + path);
  Handle fspace(H5Dget_space(d.get()), H5Sclose, "H5Dget_space " + path);
  hsize_t start[2] = {static_cast<hsize_t>(t.rows), 0}, count[2] = {1, ncols};
  check(H5Sselect_hyperslab(fspace.get(), H5S_SELECT_SET, start, nullptr, count, nullptr), "H5Sselect_hyperslab");
  Handle mspace(H5Screate_simple(2, count, nullptr), H5Sclose, "H5Screate_simple");
  check(H5Dwrite(d.get(), H5T_NATIVE_DOUBLE, mspace.get(), fspace.get(), H5P_DEFAULT, row.data()), "H5Dwrite " + path);
  d.close("H5Dclose " + path);
  check(H5Fflush(file_, H5F_SCOPE_GLOBAL), "H5Fflush " + h5_path_);
  ++t.rows;
}

// ---------------------------------------------------------------- output directories

std::string temporary_output_dir(const std::string& final_dir) {
  fs::path f = normalized_dir(final_dir, "temporary_output_dir");
  fs::path tmp = f;
  tmp += ".partial";
  try {
    if (fs::exists(fs::symlink_status(tmp))) fs::remove_all(tmp);  // leftover of a crashed run
    fs::create_directories(tmp);
  } catch (const fs::filesystem_error& e) {
    throw std::runtime_error("cannot create output directory '" + tmp.string() + "': " + e.code().message());
  }
  return tmp.string();
}

void commit_output_dir(const std::string& tmp, const std::string& final_dir) {
  fs::path t = normalized_dir(tmp, "commit_output_dir");
  fs::path f = normalized_dir(final_dir, "commit_output_dir");
  if (!fs::is_directory(t)) throw std::runtime_error("commit_output_dir: '" + t.string() + "' is not a directory");
  std::error_code same_ec;
  if (t == f || fs::equivalent(t, f, same_ec)) {
    throw std::runtime_error("commit_output_dir: source and destination are the same: '" + f.string() + "'");
  }
  try {
    const auto st = fs::symlink_status(f);
    if (!fs::exists(st)) {
      fs::rename(t, f);
      return;
    }
    if (!fs::is_directory(st)) {
      throw std::runtime_error("commit_output_dir: '" + f.string() +
                               "' exists and is not a directory; refusing to replace it (results stay in '" +
                               t.string() + "')");
    }
    fs::path old = f;
    old += ".old";
    if (fs::exists(fs::symlink_status(old))) fs::remove_all(old);  // leftover of an interrupted commit
    fs::rename(f, old);
    try {
      fs::rename(t, f);
    } catch (...) {
      std::error_code ec;
      fs::rename(old, f, ec);  // put the previous results back
      throw;
    }
    std::error_code ec;
    fs::remove_all(old, ec);  // results are committed; a leftover .old is removed next time
  } catch (const fs::filesystem_error& e) {
    throw std::runtime_error("commit_output_dir: cannot move '" + t.string() + "' to '" + f.string() +
                             "': " + e.code().message());
  }
}

void discard_output_dir(const std::string& tmp) {
  fs::path t = normalized_dir(tmp, "discard_output_dir");
  std::error_code ec;
  fs::remove_all(t, ec);
  if (ec) throw std::runtime_error("cannot remove '" + t.string() + "': " + ec.message());
}

}  // namespace morphfem
