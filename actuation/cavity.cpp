#include "actuation/cavity.h"

#include <stdexcept>

#include "fem/loads.h"

namespace morphfem {

namespace {
// [v]x: the matrix with [v]x w = v x w.
Eigen::Matrix3d cross_matrix(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}
}  // namespace

double cavity_face_integral(const ShapeTable& table, const std::array<bool, 3>& axes, const Eigen::MatrixXd& x,
                            Eigen::VectorXd* g, Eigen::MatrixXd* H) {
  const int n = static_cast<int>(x.rows());
  const Eigen::Matrix3d S = Eigen::Vector3d(axes[0], axes[1], axes[2]).asDiagonal();
  if (g) g->setZero(3 * n);
  if (H) H->setZero(3 * n, 3 * n);
  double f = 0.0;
  for (size_t q = 0; q < table.points.size(); ++q) {
    const double w = table.points[q].weight;
    const Eigen::VectorXd& N = table.N[q];
    const Eigen::VectorXd Nxi = table.dN[q].col(0), Neta = table.dN[q].col(1);
    const Eigen::Vector3d a = x.transpose() * Nxi, b = x.transpose() * Neta;
    const Eigen::Vector3d v = S * (x.transpose() * N);  // v = S x
    const Eigen::Vector3d axb = a.cross(b);
    f += w * v.dot(axb);
    if (g) {
      const Eigen::Vector3d Saxb = S * axb, bxv = b.cross(v), vxa = v.cross(a);
      for (int c = 0; c < n; ++c) g->segment<3>(3 * c) += w * (N[c] * Saxb + Nxi[c] * bxv + Neta[c] * vxa);
    }
    if (H) {
      const Eigen::Matrix3d Ca = cross_matrix(a), Cb = cross_matrix(b), Cv = cross_matrix(v);
      const Eigen::Matrix3d SCa = S * Ca, SCb = S * Cb, CbS = Cb * S, CaS = Ca * S;
      for (int c = 0; c < n; ++c)
        for (int d = 0; d < n; ++d) {
          // d/dx_d of the gradient block c (see the header's formula derivation).
          Eigen::Matrix3d block = N[c] * (-Nxi[d] * SCb + Neta[d] * SCa) + Nxi[c] * (-Neta[d] * Cv + N[d] * CbS) +
                                  Neta[c] * (-N[d] * CaS + Nxi[d] * Cv);
          H->block<3, 3>(3 * c, 3 * d) += w * block;
        }
    }
  }
  return f;
}

double cavity_wall_integral(const ShapeTable& table, const std::array<bool, 3>& axes, int open_axis,
                            const Eigen::MatrixXd& X, const Eigen::MatrixXd& x, Eigen::VectorXd* g,
                            Eigen::MatrixXd* H) {
  if (open_axis < 0) return cavity_face_integral(table, axes, x, g, H);
  Eigen::MatrixXd frozen = x;
  frozen.col(open_axis) = X.col(open_axis);
  const double f = cavity_face_integral(table, axes, frozen, g, H);
  for (Eigen::Index a = 0; a < x.rows(); ++a) {
    const Eigen::Index j = 3 * a + open_axis;
    if (g) (*g)[j] = 0.0;
    if (H) {
      H->row(j).setZero();
      H->col(j).setZero();
    }
  }
  return f;
}

void check_cavity_axes(const std::string& name, const std::array<bool, 3>& axes, int open_axis) {
  if (!(axes[0] || axes[1] || axes[2]))
    throw std::invalid_argument("cavity '" + name + "': volume_axes selects no axis");
  if (open_axis < -1 || open_axis > 2) throw std::invalid_argument("cavity '" + name + "': open axis out of range");
  if (open_axis >= 0)
    for (int i = 0; i < 3; ++i)
      if (axes[i] == (i == open_axis))
        throw std::invalid_argument("cavity '" + name +
                                    "': an open sleeve's volume axes must be the two axes other than its open axis");
}

CavityPressureTerm::CavityPressureTerm(const Mesh& mesh, const Partition& partition, int rank, CavitySpec spec)
    : mesh_(mesh), spec_(std::move(spec)) {
  check_cavity_axes(spec_.name, spec_.axes, spec_.open_axis);
  std::vector<int> wall;
  for (const auto& surface : spec_.surfaces) {
    auto f = mesh.faces_of(surface);
    wall.insert(wall.end(), f.begin(), f.end());
  }
  faces_ = owned_faces(mesh, partition, rank, wall);
  // Integrand degree: x (order k) times a x b (order 2k - 2): 3k - 2; use 2k (exact).
  table_ = make_triangle_table(mesh.order, 2 * mesh.order);
  set_time(0.0);
}

void CavityPressureTerm::piece_nodes(int k, std::vector<int>& nodes) const {
  const int f = faces_[k];
  nodes.assign(mesh_.faces.row(f).data(), mesh_.faces.row(f).data() + mesh_.nodes_per_face());
}

double CavityPressureTerm::piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const {
  const double n_axes = spec_.axes[0] + spec_.axes[1] + spec_.axes[2];
  // E_face = -p V_face = (p/|S|) int (S x).(a x b)
  const double scale = pressure_ / n_axes;
  const Eigen::MatrixXd x = s.X + s.u;
  double f = cavity_wall_integral(table_, spec_.axes, spec_.open_axis, s.X, x, g, H);
  if (g) *g *= scale;
  if (H) *H *= scale;
  return scale * f;
}

double cavity_wall_volume(const EnergyTerm& wall, const Mesh& mesh, const Assembler& assembler,
                          const std::vector<double>& u_ghost, const ShapeTable& table, const std::array<bool, 3>& axes,
                          int open_axis) {
  const double n_axes = axes[0] + axes[1] + axes[2];
  std::vector<int> nodes;
  Eigen::MatrixXd X, x;
  double local = 0.0;
  for (int k = 0; k < wall.n_pieces(); ++k) {
    wall.piece_nodes(k, nodes);
    X.resize(static_cast<Eigen::Index>(nodes.size()), 3);
    x.resize(static_cast<Eigen::Index>(nodes.size()), 3);
    for (size_t a = 0; a < nodes.size(); ++a) {
      const int slot = assembler.node_slot(nodes[a]);
      for (int i = 0; i < 3; ++i) {
        X(a, i) = mesh.X(nodes[a], i);
        x(a, i) = X(a, i) + u_ghost[3 * slot + i];
      }
    }
    local -= cavity_wall_integral(table, axes, open_axis, X, x, nullptr, nullptr) / n_axes;
  }
  double total = 0.0;
  MPI_Allreduce(&local, &total, 1, MPI_DOUBLE, MPI_SUM, assembler.comm());
  return total;
}

double CavityPressureTerm::volume(Assembler& assembler, Vec u) const {
  return cavity_wall_volume(*this, mesh_, assembler, assembler.gather(u), table_, spec_.axes, spec_.open_axis);
}

}  // namespace morphfem
