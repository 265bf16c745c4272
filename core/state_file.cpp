#include "core/state_file.h"

#include <hdf5.h>

#include <filesystem>
#include <stdexcept>

#include "core/errors.h"
#include "core/log_event.h"

namespace morphfem {

long StateRecord::integer(const std::string& key, const std::string& where) const {
  auto it = integers.find(key);
  if (it == integers.end()) throw InputError(where, "missing integer '" + key + "'");
  return it->second;
}

const std::string& StateRecord::text(const std::string& key, const std::string& where) const {
  auto it = texts.find(key);
  if (it == texts.end()) throw InputError(where, "missing text '" + key + "'");
  return it->second;
}

const std::vector<double>& StateRecord::array(const std::string& key, const std::string& where,
                                              long expected_size) const {
  auto it = arrays.find(key);
  if (it == arrays.end()) throw InputError(where, "missing array '" + key + "'");
  if (expected_size >= 0 && static_cast<long>(it->second.size()) != expected_size)
    throw InputError(where, "array '" + key + "' has " + std::to_string(it->second.size()) + " values, expected " +
                                std::to_string(expected_size));
  return it->second;
}

double StateRecord::number(const std::string& key, const std::string& where) const { return array(key, where, 1)[0]; }

namespace {

// Closes an HDF5 identifier with its matching close function.
class Id {
 public:
  Id(hid_t id, herr_t (*close)(hid_t)) : id_(id), close_(close) {}
  ~Id() {
    if (id_ >= 0) close_(id_);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }
  bool ok() const { return id_ >= 0; }

 private:
  hid_t id_;
  herr_t (*close_)(hid_t);
};

// Turns HDF5's error printing off for the lifetime of the object.
class QuietHdf5 {
 public:
  QuietHdf5() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~QuietHdf5() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

void check(bool ok, const std::string& what) {
  if (!ok) throw std::runtime_error("state file: HDF5 call failed: " + what);
}

void write_state(hid_t file, const StateRecord& state) {
  Id scalar(H5Screate(H5S_SCALAR), H5Sclose);
  check(scalar.ok(), "H5Screate");
  for (const auto& [key, value] : state.integers) {
    Id attr(H5Acreate2(file, key.c_str(), H5T_STD_I64LE, scalar.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    check(attr.ok(), "H5Acreate2 " + key);
    const long long v = value;
    check(H5Awrite(attr.get(), H5T_NATIVE_LLONG, &v) >= 0, "H5Awrite " + key);
  }
  for (const auto& [key, value] : state.texts) {
    Id type(H5Tcopy(H5T_C_S1), H5Tclose);
    check(type.ok() && H5Tset_size(type.get(), value.size() + 1) >= 0, "string type " + key);
    Id attr(H5Acreate2(file, key.c_str(), type.get(), scalar.get(), H5P_DEFAULT, H5P_DEFAULT), H5Aclose);
    check(attr.ok(), "H5Acreate2 " + key);
    check(H5Awrite(attr.get(), type.get(), value.c_str()) >= 0, "H5Awrite " + key);
  }
  Id dcpl(H5Pcreate(H5P_DATASET_CREATE), H5Pclose);
  check(dcpl.ok() && H5Pset_obj_track_times(dcpl.get(), 0) >= 0, "dataset creation properties");
  for (const auto& [key, values] : state.arrays) {
    const hsize_t n = values.size();
    Id space(n == 0 ? H5Screate(H5S_NULL) : H5Screate_simple(1, &n, nullptr), H5Sclose);
    check(space.ok(), "H5Screate " + key);
    Id set(H5Dcreate2(file, key.c_str(), H5T_IEEE_F64LE, space.get(), H5P_DEFAULT, dcpl.get(), H5P_DEFAULT), H5Dclose);
    check(set.ok(), "H5Dcreate2 " + key);
    if (n > 0) check(H5Dwrite(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) >= 0, key);
  }
}

struct ReadContext {
  StateRecord* state;
  std::string error;
};

herr_t read_attribute(hid_t loc, const char* name, const H5A_info_t*, void* data) {
  auto* ctx = static_cast<ReadContext*>(data);
  Id attr(H5Aopen(loc, name, H5P_DEFAULT), H5Aclose);
  Id type(attr.ok() ? H5Aget_type(attr.get()) : -1, H5Tclose);
  if (!type.ok()) return ctx->error = std::string("cannot open attribute ") + name, -1;
  if (H5Tget_class(type.get()) == H5T_INTEGER) {
    long long v = 0;
    if (H5Aread(attr.get(), H5T_NATIVE_LLONG, &v) < 0) return ctx->error = std::string("cannot read ") + name, -1;
    ctx->state->integers[name] = static_cast<long>(v);
  } else if (H5Tget_class(type.get()) == H5T_STRING) {
    std::string s(H5Tget_size(type.get()), '\0');
    if (H5Aread(attr.get(), type.get(), s.data()) < 0) return ctx->error = std::string("cannot read ") + name, -1;
    s.resize(s.find('\0') == std::string::npos ? s.size() : s.find('\0'));
    ctx->state->texts[name] = s;
  } else {
    return ctx->error = std::string("attribute ") + name + " is neither an integer nor a string", -1;
  }
  return 0;
}

herr_t read_dataset(hid_t loc, const char* name, const H5L_info_t*, void* data) {
  auto* ctx = static_cast<ReadContext*>(data);
  Id set(H5Dopen2(loc, name, H5P_DEFAULT), H5Dclose);
  Id space(set.ok() ? H5Dget_space(set.get()) : -1, H5Sclose);
  if (!space.ok()) return ctx->error = std::string("cannot open dataset ") + name, -1;
  const hssize_t n = H5Sget_simple_extent_npoints(space.get());
  std::vector<double> values(n > 0 ? n : 0);
  if (n > 0 && H5Dread(set.get(), H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, values.data()) < 0)
    return ctx->error = std::string("cannot read dataset ") + name, -1;
  ctx->state->arrays[name] = std::move(values);
  return 0;
}

}  // namespace

void write_state_file(const std::string& path, const StateRecord& record) {
  LogEventScope scope("StateFileWrite");
  const std::string tmp = path + ".tmp";
  {
    QuietHdf5 quiet;
    Id file(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT), H5Fclose);
    check(file.ok(), "H5Fcreate " + tmp);
    write_state(file.get(), record);
    check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL) >= 0, "H5Fflush " + tmp);
  }
  std::filesystem::rename(tmp, path);
}

StateRecord read_state_file(const std::string& path) {
  QuietHdf5 quiet;
  if (!std::filesystem::exists(path)) throw InputError(path, "no such file");
  if (H5Fis_hdf5(path.c_str()) <= 0) throw InputError(path, "not an HDF5 file");
  Id file(H5Fopen(path.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT), H5Fclose);
  if (!file.ok()) throw InputError(path, "cannot open the file");
  StateRecord state;
  ReadContext ctx{&state, ""};
  hsize_t idx = 0;
  if (H5Aiterate2(file.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, read_attribute, &ctx) < 0)
    throw InputError(path, ctx.error.empty() ? "cannot read the attributes" : ctx.error);
  idx = 0;
  if (H5Literate(file.get(), H5_INDEX_NAME, H5_ITER_INC, &idx, read_dataset, &ctx) < 0)
    throw InputError(path, ctx.error.empty() ? "cannot read the datasets" : ctx.error);
  return state;
}

namespace {
void broadcast_text(std::string& s, MPI_Comm comm, int root) {
  long n = static_cast<long>(s.size());
  MPI_Bcast(&n, 1, MPI_LONG, root, comm);
  s.resize(n);
  MPI_Bcast(s.data(), static_cast<int>(n), MPI_CHAR, root, comm);
}
}  // namespace

void broadcast_state(StateRecord& record, MPI_Comm comm, int root) {
  int rank = 0;
  MPI_Comm_rank(comm, &rank);
  long counts[3] = {static_cast<long>(record.integers.size()), static_cast<long>(record.texts.size()),
                    static_cast<long>(record.arrays.size())};
  MPI_Bcast(counts, 3, MPI_LONG, root, comm);
  StateRecord received;
  auto integer = record.integers.begin();
  for (long i = 0; i < counts[0]; ++i) {
    std::string key = rank == root ? integer->first : "";
    long value = rank == root ? (integer++)->second : 0;
    broadcast_text(key, comm, root);
    MPI_Bcast(&value, 1, MPI_LONG, root, comm);
    received.integers[key] = value;
  }
  auto text = record.texts.begin();
  for (long i = 0; i < counts[1]; ++i) {
    std::string key = rank == root ? text->first : "", value = rank == root ? (text++)->second : "";
    broadcast_text(key, comm, root);
    broadcast_text(value, comm, root);
    received.texts[key] = value;
  }
  auto array = record.arrays.begin();
  for (long i = 0; i < counts[2]; ++i) {
    std::string key = rank == root ? array->first : "";
    std::vector<double> values = rank == root ? (array++)->second : std::vector<double>{};
    broadcast_text(key, comm, root);
    long n = static_cast<long>(values.size());
    MPI_Bcast(&n, 1, MPI_LONG, root, comm);
    values.resize(n);
    MPI_Bcast(values.data(), static_cast<int>(n), MPI_DOUBLE, root, comm);
    received.arrays[key] = std::move(values);
  }
  record = std::move(received);
}

}  // namespace morphfem
