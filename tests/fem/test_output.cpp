// ResultWriter (XDMF + HDF5 time series) and the output-directory helpers.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "fem/output.h"

namespace fs = std::filesystem;
using namespace morphfem;

namespace {

// A fresh directory per test, removed afterwards.
struct TempDir {
  fs::path path;
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path = fs::temp_directory_path() / ("morphfem_output_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path, ec);
  }
  std::string str() const { return path.string(); }
};

// Two P1 tets sharing the face (1,2,3).
Mesh p1_mesh() {
  Mesh m;
  m.order = 1;
  m.X.resize(5, 3);
  m.X << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 1, 1, 1;
  m.cells.resize(2, 4);
  m.cells << 0, 1, 2, 3, 1, 4, 2, 3;
  m.cell_region = {0, 1};
  m.regions = {{"skin", 3, 0}, {"inner", 3, 1}};
  return m;
}

// One P2 tet: vertices then edge mid-nodes (0,1) (1,2) (0,2) (0,3) (1,3) (2,3).
Mesh p2_mesh() {
  Mesh m;
  m.order = 2;
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> v;
  v << 0, 0, 0, 2, 0, 0, 0, 2, 0, 0, 0, 2;
  const int edges[6][2] = {{0, 1}, {1, 2}, {0, 2}, {0, 3}, {1, 3}, {2, 3}};
  m.X.resize(10, 3);
  for (int i = 0; i < 4; ++i) m.X.row(i) = v.row(i);
  for (int e = 0; e < 6; ++e) m.X.row(4 + e) = 0.5 * (v.row(edges[e][0]) + v.row(edges[e][1]));
  m.cells.resize(1, 10);
  for (int i = 0; i < 10; ++i) m.cells(0, i) = i;
  return m;  // no cell_region: no automatic "region" attribute
}

Field make_field(const std::string& name, int components, int rows, double seed) {
  Field f{name, components, {}};
  for (int i = 0; i < rows * components; ++i) f.values.push_back(seed + 0.25 * i - 1.0 / (i + 3));
  return f;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// ---- HDF5 reading helpers (C API, every call checked)

struct H5Data {
  std::vector<hsize_t> dims;
  H5T_class_t type_class = H5T_NO_CLASS;
  size_t type_size = 0;
  std::vector<double> values;  // converted to double by HDF5
};

H5Data read_dataset(hid_t file, const std::string& path) {
  H5Data out;
  hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  EXPECT_GE(d, 0) << path;
  if (d < 0) return out;
  hid_t space = H5Dget_space(d);
  EXPECT_GE(space, 0);
  int rank = H5Sget_simple_extent_ndims(space);
  EXPECT_GE(rank, 0);
  out.dims.resize(rank);
  EXPECT_GE(H5Sget_simple_extent_dims(space, out.dims.data(), nullptr), 0);
  hid_t type = H5Dget_type(d);
  EXPECT_GE(type, 0);
  out.type_class = H5Tget_class(type);
  out.type_size = H5Tget_size(type);
  hsize_t n = 1;
  for (auto x : out.dims) n *= x;
  out.values.resize(n);
  if (n > 0) {
    EXPECT_GE(H5Dread(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, out.values.data()), 0);
  }
  EXPECT_GE(H5Tclose(type), 0);
  EXPECT_GE(H5Sclose(space), 0);
  EXPECT_GE(H5Dclose(d), 0);
  return out;
}

// Fixed-length string attribute (scalar or 1-D array).
std::vector<std::string> read_string_attribute(hid_t file, const std::string& obj, const std::string& name) {
  std::vector<std::string> out;
  hid_t a = H5Aopen_by_name(file, obj.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << obj << "@" << name;
  if (a < 0) return out;
  hid_t type = H5Aget_type(a);
  hid_t space = H5Aget_space(a);
  hssize_t n = H5Sget_simple_extent_npoints(space);
  size_t len = H5Tget_size(type);
  EXPECT_FALSE(H5Tis_variable_str(type));
  std::vector<char> buf(len * n + 1, '\0');
  EXPECT_GE(H5Aread(a, type, buf.data()), 0);
  for (hssize_t i = 0; i < n; ++i) out.emplace_back(buf.data() + i * len, strnlen(buf.data() + i * len, len));
  EXPECT_GE(H5Sclose(space), 0);
  EXPECT_GE(H5Tclose(type), 0);
  EXPECT_GE(H5Aclose(a), 0);
  return out;
}

double read_double_attribute(hid_t file, const std::string& obj, const std::string& name) {
  double v = std::numeric_limits<double>::quiet_NaN();
  hid_t a = H5Aopen_by_name(file, obj.c_str(), name.c_str(), H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << obj << "@" << name;
  if (a < 0) return v;
  EXPECT_GE(H5Aread(a, H5T_NATIVE_DOUBLE, &v), 0);
  EXPECT_GE(H5Aclose(a), 0);
  return v;
}

herr_t collect_dataset(hid_t, const char* name, const H5O_info_t* info, void* out) {
  if (info->type == H5O_TYPE_DATASET) {
    std::string path = "/";
    path += name;  // (not "/" + std::string: GCC 12 -Wrestrict false positive)
    static_cast<std::set<std::string>*>(out)->insert(path);
  }
  return 0;
}

std::set<std::string> all_datasets(hid_t file) {
  std::set<std::string> out;
  EXPECT_GE(H5Ovisit(file, H5_INDEX_NAME, H5_ITER_NATIVE, collect_dataset, &out), 0);
  return out;
}

hid_t open_readonly(const std::string& path) {
  hid_t f = H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  EXPECT_GE(f, 0) << path;
  return f;
}

// ---- XDMF checks

struct XdmfRef {
  std::vector<hsize_t> dims;
  std::string number_type;
  int precision = 0;
  std::string file, path;
};

std::vector<XdmfRef> xdmf_refs(const std::string& xml) {
  std::vector<XdmfRef> out;
  std::regex item(
      R"re(<DataItem Dimensions="([0-9 ]+)" NumberType="(\w+)" Precision="(\d+)" Format="HDF">([^<:]+):([^<]+)</DataItem>)re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), item), end; it != end; ++it) {
    XdmfRef r;
    std::istringstream dims((*it)[1].str());
    for (hsize_t d; dims >> d;) r.dims.push_back(d);
    r.number_type = (*it)[2];
    r.precision = std::stoi((*it)[3]);
    r.file = (*it)[4];
    r.path = (*it)[5];
    out.push_back(r);
  }
  return out;
}

std::vector<double> xdmf_times(const std::string& xml) {
  std::vector<double> out;
  std::regex time(R"re(<Time Value="([^"]+)"/>)re");
  for (std::sregex_iterator it(xml.begin(), xml.end(), time), end; it != end; ++it) {
    out.push_back(std::stod((*it)[1]));
  }
  return out;
}

int count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

// Every HDF reference in the XDMF exists in the .h5 with matching dimensions and
// type, every dataset under /mesh and /steps is referenced, and the times match.
void check_xdmf_against_h5(const std::string& dir, const std::string& name, const std::vector<double>& times) {
  const std::string xml = read_text(dir + "/" + name + ".xdmf");
  ASSERT_NE(xml.find("<Xdmf Version=\"2.0\">"), std::string::npos);
  EXPECT_EQ(xdmf_times(xml), times);
  // Before the first step the file holds just the mesh grid, without a time.
  EXPECT_EQ(count(xml, "GridType=\"Uniform\""), std::max<int>(1, times.size()));
  EXPECT_EQ(count(xml, "CollectionType=\"Temporal\""), times.empty() ? 0 : 1);
  EXPECT_EQ(count(xml, "<Grid"), count(xml, "</Grid>"));
  EXPECT_EQ(count(xml, "<Attribute"), count(xml, "</Attribute>"));
  hid_t f = open_readonly(dir + "/" + name + ".h5");
  ASSERT_GE(f, 0);
  std::set<std::string> referenced;
  for (const auto& r : xdmf_refs(xml)) {
    EXPECT_EQ(r.file, name + ".h5");
    referenced.insert(r.path);
    H5Data d = read_dataset(f, r.path);
    EXPECT_EQ(d.dims, r.dims) << r.path;
    if (r.number_type == "Float") {
      EXPECT_EQ(d.type_class, H5T_FLOAT) << r.path;
    } else {
      EXPECT_EQ(r.number_type, "Int");
      EXPECT_EQ(d.type_class, H5T_INTEGER) << r.path;
    }
    EXPECT_EQ(static_cast<int>(d.type_size), r.precision) << r.path;
  }
  for (const auto& path : all_datasets(f)) {
    if (path.rfind("/tables/", 0) == 0) continue;  // tables are not part of the mesh description
    EXPECT_TRUE(referenced.count(path)) << path << " is not referenced by the XDMF";
  }
  EXPECT_GE(H5Fclose(f), 0);
}

void expect_throw_containing(const std::function<void()>& fn, const std::vector<std::string>& parts) {
  try {
    fn();
    ADD_FAILURE() << "no exception";
  } catch (const std::runtime_error& e) {
    for (const auto& p : parts) EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

// Writes 3 steps on `mesh` and returns the fields written per step.
std::vector<std::pair<std::vector<Field>, std::vector<Field>>> write_three_steps(const std::string& dir,
                                                                                 const std::string& name,
                                                                                 const Mesh& mesh) {
  std::vector<std::pair<std::vector<Field>, std::vector<Field>>> steps;
  ResultWriter w(dir, name, mesh);
  EXPECT_EQ(w.steps_written(), 0);
  const double times[3] = {0.0, 0.1, 0.35};
  for (int s = 0; s < 3; ++s) {
    std::vector<Field> nodal = {make_field("displacement", 3, mesh.n_nodes(), s),
                                make_field("J", 1, mesh.n_nodes(), 10 + s)};
    std::vector<Field> cell = {make_field("von_mises", 1, mesh.n_cells(), 100 + s),
                               make_field("stretch", 3, mesh.n_cells(), 200 + s)};
    w.write_step(times[s], nodal, cell);
    w.append_row("cavities", {"time", "pressure", "volume"}, {times[s], 1000.0 * s, 1e-6 * (s + 1)});
    w.append_row("energy", {"time", "elastic"}, {times[s], 0.5 * s});
    steps.emplace_back(nodal, cell);
  }
  EXPECT_EQ(w.steps_written(), 3);
  return steps;
}

void check_three_steps(const std::string& dir, const std::string& name, const Mesh& mesh,
                       const std::vector<std::pair<std::vector<Field>, std::vector<Field>>>& steps) {
  hid_t f = open_readonly(dir + "/" + name + ".h5");
  ASSERT_GE(f, 0);
  H5Data X = read_dataset(f, "/mesh/X");
  EXPECT_EQ(X.dims, (std::vector<hsize_t>{static_cast<hsize_t>(mesh.n_nodes()), 3}));
  EXPECT_EQ(X.values, std::vector<double>(mesh.X.data(), mesh.X.data() + mesh.X.size()));
  H5Data cells = read_dataset(f, "/mesh/cells");
  EXPECT_EQ(cells.type_class, H5T_INTEGER);
  EXPECT_EQ(cells.dims,
            (std::vector<hsize_t>{static_cast<hsize_t>(mesh.n_cells()), static_cast<hsize_t>(mesh.nodes_per_cell())}));
  EXPECT_EQ(cells.values, std::vector<double>(mesh.cells.data(), mesh.cells.data() + mesh.cells.size()));
  if (!mesh.cell_region.empty()) {  // region ids and names, so that scripts can find a region by name
    H5Data region = read_dataset(f, "/mesh/cell_region");
    EXPECT_EQ(region.values, std::vector<double>(mesh.cell_region.begin(), mesh.cell_region.end()));
    std::vector<std::string> names;
    for (const auto& r : mesh.regions) names.push_back(std::to_string(r.id) + " " + r.name);
    EXPECT_EQ(read_string_attribute(f, "/mesh/cell_region", "names"), names);
  }
  const double times[3] = {0.0, 0.1, 0.35};
  for (int s = 0; s < 3; ++s) {
    char group[32];
    std::snprintf(group, sizeof group, "/steps/%06d", s);
    EXPECT_EQ(read_double_attribute(f, group, "time"), times[s]);
    for (int kind = 0; kind < 2; ++kind) {
      const auto& fields = kind == 0 ? steps[s].first : steps[s].second;
      const int rows = kind == 0 ? mesh.n_nodes() : mesh.n_cells();
      for (const Field& field : fields) {
        const std::string path = std::string(group) + "/" + field.name;
        H5Data d = read_dataset(f, path);
        std::vector<hsize_t> dims{static_cast<hsize_t>(rows)};
        if (field.components > 1) dims.push_back(field.components);
        EXPECT_EQ(d.dims, dims) << path;
        EXPECT_EQ(d.values, field.values) << path;
        EXPECT_EQ(read_string_attribute(f, path, "center"), std::vector<std::string>{kind == 0 ? "Node" : "Cell"});
      }
    }
  }
  H5Data cav = read_dataset(f, "/tables/cavities");
  EXPECT_EQ(cav.dims, (std::vector<hsize_t>{3, 3}));
  EXPECT_EQ(cav.values, (std::vector<double>{0.0, 0.0, 1e-6, 0.1, 1000.0, 2e-6, 0.35, 2000.0, 3e-6}));
  EXPECT_EQ(read_string_attribute(f, "/tables/cavities", "columns"),
            (std::vector<std::string>{"time", "pressure", "volume"}));
  H5Data energy = read_dataset(f, "/tables/energy");
  EXPECT_EQ(energy.dims, (std::vector<hsize_t>{3, 2}));
  EXPECT_EQ(read_string_attribute(f, "/tables/energy", "columns"), (std::vector<std::string>{"time", "elastic"}));
  EXPECT_GE(H5Fclose(f), 0);
}

}  // namespace

TEST(ResultWriter, P1ThreeStepsRoundTrip) {
  TempDir dir;
  Mesh mesh = p1_mesh();
  auto steps = write_three_steps(dir.str(), "run", mesh);
  check_three_steps(dir.str(), "run", mesh, steps);
  check_xdmf_against_h5(dir.str(), "run", {0.0, 0.1, 0.35});

  const std::string xml = read_text(dir.str() + "/run.xdmf");
  EXPECT_EQ(count(xml, "TopologyType=\"Tetrahedron\" NumberOfElements=\"2\" NodesPerElement=\"4\""), 3);
  EXPECT_EQ(count(xml, "<Attribute Name=\"displacement\" AttributeType=\"Vector\" Center=\"Node\">"), 3);
  EXPECT_EQ(count(xml, "<Attribute Name=\"J\" AttributeType=\"Scalar\" Center=\"Node\">"), 3);
  EXPECT_EQ(count(xml, "<Attribute Name=\"von_mises\" AttributeType=\"Scalar\" Center=\"Cell\">"), 3);
  EXPECT_EQ(count(xml, "<Attribute Name=\"stretch\" AttributeType=\"Vector\" Center=\"Cell\">"), 3);
  // Regions come from the mesh, stored once.
  EXPECT_EQ(count(xml, "<Attribute Name=\"region\" AttributeType=\"Scalar\" Center=\"Cell\">"), 3);
  EXPECT_EQ(count(xml, "run.h5:/mesh/cell_region"), 3);
  EXPECT_FALSE(fs::exists(dir.path / "run.xdmf.tmp"));
}

TEST(ResultWriter, P2ThreeStepsRoundTrip) {
  TempDir dir;
  Mesh mesh = p2_mesh();
  auto steps = write_three_steps(dir.str(), "p2", mesh);
  check_three_steps(dir.str(), "p2", mesh, steps);
  check_xdmf_against_h5(dir.str(), "p2", {0.0, 0.1, 0.35});
  const std::string xml = read_text(dir.str() + "/p2.xdmf");
  EXPECT_EQ(count(xml, "TopologyType=\"Tetrahedron_10\" NumberOfElements=\"1\" NodesPerElement=\"10\""), 3);
  EXPECT_EQ(count(xml, "Name=\"region\""), 0);
}

TEST(ResultWriter, MeshOnlyBeforeFirstStep) {
  TempDir dir;
  ResultWriter w(dir.str(), "m", p1_mesh());
  const std::string xml = read_text(dir.str() + "/m.xdmf");
  EXPECT_EQ(count(xml, "<Grid Name=\"mesh\" GridType=\"Uniform\">"), 1);
  EXPECT_EQ(count(xml, "Temporal"), 0);
  w.close();
  check_xdmf_against_h5(dir.str(), "m", {});
}

TEST(ResultWriter, RejectsNonFiniteValues) {
  TempDir dir;
  Mesh mesh = p1_mesh();
  ResultWriter w(dir.str(), "nan", mesh);
  w.write_step(0.0, {make_field("displacement", 3, 5, 0)}, {});

  Field bad = make_field("displacement", 3, 5, 1);
  bad.values[7] = std::nan("");
  expect_throw_containing(
      [&] {
        w.write_step(1.0, {make_field("J", 1, 5, 0), bad}, {});
      },
      {"'displacement'", "step 1", "node 2", "component 1"});
  Field inf = make_field("von_mises", 1, 2, 0);
  inf.values[1] = -std::numeric_limits<double>::infinity();
  expect_throw_containing([&] { w.write_step(1.0, {}, {inf}); }, {"'von_mises'", "step 1", "cell 1"});
  expect_throw_containing([&] { w.write_step(std::nan(""), {}, {}); }, {"step 1", "time"});
  expect_throw_containing(
      [&] {
        w.append_row("cavities", {"time", "volume"}, {1.0, std::nan("")});
      },
      {"cavities", "'volume'"});
  EXPECT_EQ(w.steps_written(), 1);

  // Nothing of the rejected steps was written; the next good step is step 1.
  w.write_step(1.0, {make_field("displacement", 3, 5, 2)}, {});
  EXPECT_EQ(w.steps_written(), 2);
  w.close();
  check_xdmf_against_h5(dir.str(), "nan", {0.0, 1.0});
  hid_t f = open_readonly(dir.str() + "/nan.h5");
  ASSERT_GE(f, 0);
  std::set<std::string> ds = all_datasets(f);
  EXPECT_EQ(ds, (std::set<std::string>{"/mesh/X", "/mesh/cells", "/mesh/cell_region", "/steps/000000/displacement",
                                       "/steps/000001/displacement"}));
  EXPECT_EQ(read_dataset(f, "/steps/000001/displacement").values, make_field("displacement", 3, 5, 2).values);
  EXPECT_GE(H5Fclose(f), 0);
}

TEST(ResultWriter, RejectsWrongSizesAndNames) {
  TempDir dir;
  ResultWriter w(dir.str(), "sizes", p1_mesh());
  expect_throw_containing([&] { w.write_step(0.0, {make_field("displacement", 3, 4, 0)}, {}); },
                          {"'displacement'", "12 values", "expected 5 nodes x 3 = 15"});
  expect_throw_containing([&] { w.write_step(0.0, {}, {make_field("J", 1, 5, 0)}); },
                          {"'J'", "5 values", "expected 2 cells x 1 = 2"});
  expect_throw_containing([&] { w.write_step(0.0, {make_field("u", 2, 5, 0)}, {}); }, {"'u'", "2 components"});
  expect_throw_containing([&] { w.write_step(0.0, {make_field("displacement", 1, 5, 0)}, {}); },
                          {"'displacement'", "nodal field with 3 components"});
  expect_throw_containing([&] { w.write_step(0.0, {}, {make_field("displacement", 3, 2, 0)}); },
                          {"'displacement'", "nodal field with 3 components"});
  expect_throw_containing([&] { w.write_step(0.0, {make_field("a/b", 1, 5, 0)}, {}); }, {"'a/b'"});
  expect_throw_containing([&] { w.write_step(0.0, {make_field("", 1, 5, 0)}, {}); }, {"invalid"});
  expect_throw_containing([&] { w.write_step(0.0, {make_field("J", 1, 5, 0)}, {make_field("J", 1, 2, 0)}); },
                          {"'J'", "twice"});
  w.write_step(0.5, {}, {});
  expect_throw_containing([&] { w.write_step(0.5, {}, {}); }, {"time must increase"});
  expect_throw_containing([&] { w.append_row("t", {"a", "b"}, {1.0}); }, {"'t'", "1 values for 2 columns"});
  w.append_row("t", {"a", "b"}, {1.0, 2.0});
  expect_throw_containing([&] { w.append_row("t", {"a", "c"}, {1.0, 2.0}); }, {"'t'", "columns differ"});
  EXPECT_EQ(w.steps_written(), 1);

  Mesh broken = p1_mesh();
  broken.cells(1, 2) = 5;
  expect_throw_containing([&] { ResultWriter(dir.str(), "broken", broken); }, {"cell 1", "node 5"});
  Mesh wrong_order = p1_mesh();
  wrong_order.order = 2;
  expect_throw_containing([&] { ResultWriter(dir.str(), "order", wrong_order); }, {"columns", "expected 10"});
  expect_throw_containing([&] { ResultWriter((dir.path / "missing").string(), "x", p1_mesh()); }, {"does not exist"});
}

// A run that dies leaves files readable up to the last completed step. The files
// are copied while the writer is still open (not closed, not destroyed): the copy
// holds exactly what a crash at that moment would leave on disk. (No fork(): the
// test binary may have MPI initialised.)
TEST(ResultWriter, ReadableAfterCrash) {
  TempDir dir;
  const fs::path crashed = dir.path / "crashed";
  fs::create_directories(crashed);
  {
    ResultWriter w(dir.str(), "crash", p1_mesh());
    w.write_step(0.0, {make_field("displacement", 3, 5, 0)}, {});
    w.write_step(0.25, {make_field("displacement", 3, 5, 1)}, {make_field("J", 1, 2, 0)});
    w.append_row("energy", {"time", "elastic"}, {0.25, 3.0});
    fs::copy_file(dir.path / "crash.h5", crashed / "crash.h5");
    fs::copy_file(dir.path / "crash.xdmf", crashed / "crash.xdmf");
    w.write_step(0.5, {make_field("displacement", 3, 5, 2)}, {});
  }
  check_xdmf_against_h5(crashed.string(), "crash", {0.0, 0.25});
  hid_t f = open_readonly((crashed / "crash.h5").string());
  ASSERT_GE(f, 0);
  EXPECT_EQ(read_dataset(f, "/steps/000001/displacement").values, make_field("displacement", 3, 5, 1).values);
  EXPECT_EQ(read_dataset(f, "/steps/000001/J").values, make_field("J", 1, 2, 0).values);
  EXPECT_EQ(read_dataset(f, "/tables/energy").values, (std::vector<double>{0.25, 3.0}));
  EXPECT_GE(H5Fclose(f), 0);
  check_xdmf_against_h5(dir.str(), "crash", {0.0, 0.25, 0.5});
}

// A resumed writer keeps the steps and table rows up to the checkpoint time, drops
// the later ones (written after the checkpoint), appends after them, and refuses a
// file of another mesh.
TEST(ResultWriter, ResumesAfterACheckpoint) {
  TempDir dir;
  const Mesh mesh = p1_mesh();
  auto steps = write_three_steps(dir.str(), "run", mesh);  // t = 0, 0.1, 0.35
  {
    ResultWriter w(dir.str(), "run", mesh, 0.1);
    EXPECT_EQ(w.steps_written(), 2);
  }
  check_xdmf_against_h5(dir.str(), "run", {0.0, 0.1});
  {
    ResultWriter w(dir.str(), "run", mesh, 0.1);  // again: nothing more to drop
    EXPECT_EQ(w.steps_written(), 2);
    expect_throw_containing([&] { w.write_step(0.1, {make_field("displacement", 3, 5, 7)}, {}); },
                            {"time must increase"});
    w.write_step(0.2, {make_field("displacement", 3, 5, 7)}, {});
    w.append_row("energy", {"time", "elastic"}, {0.2, 9.0});
    expect_throw_containing([&] { w.append_row("energy", {"time", "kinetic"}, {0.3, 1.0}); }, {"columns differ"});
  }
  check_xdmf_against_h5(dir.str(), "run", {0.0, 0.1, 0.2});
  hid_t f = open_readonly(dir.str() + "/run.h5");
  ASSERT_GE(f, 0);
  EXPECT_EQ(read_dataset(f, "/steps/000001/displacement").values, steps[1].first[0].values);
  EXPECT_EQ(read_dataset(f, "/steps/000002/displacement").values, make_field("displacement", 3, 5, 7).values);
  EXPECT_EQ(read_dataset(f, "/tables/energy").values, (std::vector<double>{0.0, 0.0, 0.1, 0.5, 0.2, 9.0}));
  EXPECT_EQ(read_dataset(f, "/tables/cavities").dims, (std::vector<hsize_t>{2, 3}));
  EXPECT_GE(H5Fclose(f), 0);

  expect_throw_containing([&] { ResultWriter w(dir.str(), "run", p2_mesh(), 0.1); }, {"mesh differs"});
  Mesh moved = mesh;
  moved.X(0, 0) += 1e-9;
  expect_throw_containing([&] { ResultWriter w(dir.str(), "run", moved, 0.1); }, {"mesh differs"});
  expect_throw_containing([&] { ResultWriter w(dir.str(), "none", mesh, 0.1); }, {"no such file"});
}

TEST(OutputDir, PartialThenCommitAndReplace) {
  TempDir dir;
  const std::string final_dir = (dir.path / "results").string();

  // First run: FINAL does not exist yet.
  std::string tmp = temporary_output_dir(final_dir + "/");  // trailing slash is fine
  EXPECT_EQ(tmp, final_dir + ".partial");
  ASSERT_TRUE(fs::is_directory(tmp));
  { std::ofstream(tmp + "/a.txt") << "first"; }
  EXPECT_FALSE(fs::exists(final_dir));
  commit_output_dir(tmp, final_dir);
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_EQ(read_text(final_dir + "/a.txt"), "first");

  // A crashed run leaves FINAL.partial behind; the next run starts clean.
  tmp = temporary_output_dir(final_dir);
  { std::ofstream(tmp + "/stale.txt") << "crashed"; }
  tmp = temporary_output_dir(final_dir);
  EXPECT_TRUE(fs::is_empty(tmp));
  EXPECT_EQ(read_text(final_dir + "/a.txt"), "first");  // untouched during the run

  // Second run replaces FINAL as a whole.
  { std::ofstream(tmp + "/b.txt") << "second"; }
  commit_output_dir(tmp, final_dir);
  EXPECT_FALSE(fs::exists(final_dir + "/a.txt"));
  EXPECT_EQ(read_text(final_dir + "/b.txt"), "second");
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_FALSE(fs::exists(final_dir + ".old"));

  // Bad input: the partial directory is discarded, FINAL is kept.
  tmp = temporary_output_dir(final_dir);
  discard_output_dir(tmp);
  EXPECT_FALSE(fs::exists(tmp));
  EXPECT_EQ(read_text(final_dir + "/b.txt"), "second");

  // A ResultWriter inside the partial directory survives the rename.
  tmp = temporary_output_dir(final_dir);
  {
    ResultWriter w(tmp, "run", p1_mesh());
    w.write_step(0.0, {make_field("displacement", 3, 5, 0)}, {});
  }
  commit_output_dir(tmp, final_dir);
  check_xdmf_against_h5(final_dir, "run", {0.0});
  EXPECT_FALSE(fs::exists(final_dir + "/b.txt"));
}

TEST(OutputDir, RefusesToReplaceAFile) {
  TempDir dir;
  const std::string final_dir = (dir.path / "results").string();
  { std::ofstream(final_dir) << "not a directory"; }
  std::string tmp = temporary_output_dir(final_dir);
  expect_throw_containing([&] { commit_output_dir(tmp, final_dir); }, {"not a directory"});
  EXPECT_TRUE(fs::is_directory(tmp));
  EXPECT_EQ(read_text(final_dir), "not a directory");
  expect_throw_containing([&] { commit_output_dir((dir.path / "nothing").string(), final_dir); }, {"not a directory"});
  expect_throw_containing([&] { temporary_output_dir(""); }, {"not a usable output directory"});
}

// Optional cross-check with h5py (skipped when /usr/bin/python3 has no h5py).
TEST(ResultWriter, PythonCheckerAgrees) {
  if (std::system("/usr/bin/python3 -c 'import h5py' >/dev/null 2>&1") != 0) GTEST_SKIP() << "no h5py";
  TempDir dir;
  Mesh p1 = p1_mesh(), p2 = p2_mesh();
  write_three_steps(dir.str(), "p1", p1);
  write_three_steps(dir.str(), "p2", p2);
  const std::string script = std::string(MORPHFEM_SOURCE_DIR) + "/scripts/check_xdmf.py";
  const std::string log = dir.str() + "/check.log";
  const std::string cmd =
      "/usr/bin/python3 " + script + " " + dir.str() + "/p1.xdmf " + dir.str() + "/p2.xdmf >" + log + " 2>&1";
  EXPECT_EQ(std::system(cmd.c_str()), 0) << read_text(log);

  // And it notices a wrong dimension (so the check above means something).
  std::string xml = read_text(dir.str() + "/p1.xdmf");
  const std::string good = "Dimensions=\"5 3\"";
  ASSERT_NE(xml.find(good), std::string::npos);
  xml.replace(xml.find(good), good.size(), "Dimensions=\"6 3\"");
  std::ofstream(dir.str() + "/p1.xdmf") << xml;
  EXPECT_NE(std::system(cmd.c_str()), 0);
  EXPECT_NE(read_text(log).find("shape (5, 3), XDMF says (6, 3)"), std::string::npos) << read_text(log);
}
