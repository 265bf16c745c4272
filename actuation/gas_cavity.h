// Cavities whose pressure is not prescribed but follows from what they hold:
//
//  * GasCavityTerm: n moles of isothermal ideal gas at temperature T, optionally
//    fed through a valve from a pressure supply or a vacuum source;
//  * VolumeControlledCavityTerm: a prescribed enclosed volume V*(t), the pressure
//    being its multiplier (augmented Lagrangian). This traces a balloon through its
//    pressure maximum, where pressure control has no nearby equilibrium.
//
// Both share the enclosed volume of actuation/cavity.h (divergence theorem over the
// wall faces with the axes mask S, kernel cavity_face_integral). With symmetry the
// mesh holds a fraction of the cavity: `symmetry_factor` s is the number of copies
// of the meshed part in the whole cavity (8 for an octant, 4 for a quarter, 1 for
// none), so the physical volume is V = s V_m, V_m the meshed part's volume.
// Gas amounts, prescribed volumes and reported volumes are of the whole cavity.
//
// Energy of a term: E_m(V_m) = Phi(s V_m) / s, Phi the whole cavity's energy [J].
// Then dE_m/du = Phi'(V) dV_m/du and
//   d2E_m/du2 = Phi'(V) d2V_m/du2  (sparse: per wall face)
//             + s Phi''(V) (dV_m/du)(dV_m/du)^T  (dense rank 1: low_rank()).
// V is a global sum over faces on every rank: prepare() reduces it before each
// sweep; the face pieces read the cached value.
#pragma once
#include <array>
#include <limits>
#include <string>
#include <vector>

#include "fem/assembly.h"
#include "fem/element.h"
#include "fem/energy.h"
#include "fem/time_function.h"

namespace morphfem {

constexpr double kGasConstant = 8.314462618;  // R [J/(mol K)]

// ------------------------------------------------------------- shared geometry
struct CavityWallSpec {
  std::string name;
  std::vector<std::string> surfaces;           // wall surface regions (normals into the cavity)
  std::array<bool, 3> axes{true, true, true};  // S: which coordinates enter V (see cavity.h)
  double symmetry_factor = 1.0;                // s >= 1: copies of the meshed part in the cavity
  int open_axis = -1;                          // an open sleeve along this axis (see cavity.h)
};

// Volume machinery common to both terms: owned wall faces, cached volume, the
// volume gradient as a global vector, and the largest step keeping V > 0.
class CavityVolumeTerm : public EnergyTerm {
 public:
  CavityVolumeTerm(const Mesh& mesh, const Partition& partition, int rank, CavityWallSpec wall);
  int n_pieces() const override { return static_cast<int>(faces_.size()); }
  void piece_nodes(int k, std::vector<int>& nodes) const override;
  // Reduces the whole cavity's volume V = s V_m over all ranks (collective).
  void prepare(const Assembler& assembler, const std::vector<double>& u_local) override;
  double max_step(Assembler& assembler, Vec u, Vec du) override;
  bool has_low_rank() const override { return true; }
  void low_rank(Assembler& assembler, Vec u, std::vector<LowRank>& out) override;
  double piece(int k, const PieceState& s, Eigen::VectorXd* g, Eigen::MatrixXd* H) const override;

  const CavityWallSpec& wall() const { return wall_; }
  // Whole cavity's volume at u = 0 [m^3] (from the mesh; no communication).
  double reference_volume() const { return reference_volume_; }
  // Whole cavity's volume [m^3] at the last converged state (end_step; the
  // reference volume before the first step).
  double cavity_volume() const { return converged_volume_; }
  // Volume of the meshed part at u (collective), as CavityPressureTerm::volume.
  double volume(Assembler& assembler, Vec u) const;
  // Sets the whole-cavity volume V [m^3] the pieces use (prepare() does this after
  // its reduction; single-process tests call it directly).
  void set_cavity_volume(double V) { volume_ = V; }
  // Meshed part's volume from a full displacement field (n_nodes x 3), over this
  // term's faces only (no communication; for tests and serial checks).
  double local_model_volume(const RowMatrixXd& u_all) const;
  // dV_m/du over this term's faces, dense over all 3 n_nodes dofs (for tests).
  Eigen::VectorXd local_volume_gradient(const RowMatrixXd& u_all) const;
  // The dense rank-1 coefficient c of H += c v v^T, v = dV_m/du, at the cached V.
  double low_rank_coefficient() const { return wall_.symmetry_factor * energy_second_derivative(volume_); }
  // Gauge pressure [Pa] at the last converged state.
  virtual double pressure() const = 0;
  // The cavity's own state beside p and V, for result tables: its name with unit
  // (a column suffix) and value at the last converged state.
  virtual std::string state_column() const = 0;
  virtual double state_value() const = 0;
  // Whole-cavity energy Phi(V) [J] and its derivatives [Pa], [Pa/m^3], at the
  // term's current parameters; Phi(V) = +inf outside the domain (V <= 0).
  virtual double energy_of_volume(double V) const = 0;
  virtual double energy_derivative(double V) const = 0;  // = -(gauge pressure) [Pa]
  virtual double energy_second_derivative(double V) const = 0;

 protected:
  double meshed_volume(const Assembler& assembler, const std::vector<double>& u_local) const;
  double face_volume(int k, const Eigen::MatrixXd& x, Eigen::VectorXd* g, Eigen::MatrixXd* H) const;
  double model_volume_at(Assembler& assembler, Vec u) const;  // collective
  // The volumes and time of the last converged state (for the derived terms' save_state).
  void save_volumes(const std::string& prefix, StateRecord& state) const;
  void load_volumes(const std::string& prefix, const StateRecord& state);

  const Mesh& mesh_;
  CavityWallSpec wall_;
  std::vector<int> faces_;
  ShapeTable table_;
  double n_axes_ = 3.0;
  double reference_volume_ = 0.0;  // whole cavity at u = 0 [m^3]
  double volume_ = 0.0;            // whole cavity at the state of the last sweep [m^3]
  double converged_volume_ = 0.0;  // whole cavity at the last converged state [m^3]
  double converged_time_ = 0.0;    // time of the last converged state [s]
};

// ------------------------------------------------------------- gas-filled cavity
// Isothermal ideal gas, n moles at temperature T: absolute pressure p = n R T / V.
// Whole-cavity energy (gas free energy at constant T plus the outside atmosphere's
// work; the constant terms only shift E):
//   Phi(V) = -n R T ln(V / V_0) + p_atm (V - V_0)                              [J]
//   Phi'(V) = -(p - p_atm)   (the gauge pressure loads the wall)
//   Phi''(V) = n R T / V^2   (the gas stiffness: dense rank 1)
//
// Valve: gas flows from a supply at gauge pressure p_s(t) (> 0: line pressure,
// < 0: vacuum source; absolute p_atm + p_s >= 0) through a linear conductance C(t):
//   dn/dt = C (p_atm + p_s - p)      C [mol/(s Pa)]
// (a laminar / linearised-orifice law; C = 0 seals the cavity). The line and the
// vacuum pump reach the cavity through different paths (regulator, tubing, pump):
// while the source is a vacuum (p_s(t1) < 0) the conductance is C_vac(t) if given,
// else C(t). Integrated with
// backward Euler over each step t0 -> t1 (dt = t1 - t0), p_s and C at t1:
//   n1 = n0 + dt C (p_atm + p_s - n1 R T / V1)
//   =>  n1 = m V1 / (V1 + V_r),   m = n0 + dt C (p_atm + p_s),   V_r = dt C R T,
//   p1 = n1 R T / V1 = m R T / (V1 + V_r).
// p1 depends on V1 alone, so the implicit step IS a potential: the gas amount m
// in the cavity plus a virtual reservoir of volume V_r,
//   Phi_step(V) = -m R T ln((V + V_r) / V_0) + p_atm (V - V_0),
// minimised together with the structure (no lagging, no splitting error between
// flow and deformation). Backward Euler is L-stable and monotone: for any dt, n1
// lies between n0 and the amount in equilibrium with the supply; it is first
// order, so the step size controls the accuracy of the fill history (a rigid
// cavity fills with time constant tau = V / (C R T); dt <= tau/10 gives the
// fill time to a few percent). The sealed cavity (C = 0) is the special case
// m = n0, V_r = 0.
struct GasCavitySpec {
  CavityWallSpec wall;
  double temperature = 293.15;             // T [K]
  double atmospheric_pressure = 101325.0;  // p_atm [Pa], absolute outside pressure
  // Initial gas amount [mol]; NaN: the amount at initial_gauge_pressure [Pa] in the
  // reference (undeformed) cavity, n0 = (p_atm + p0) V_ref / (R T).
  double initial_amount = std::numeric_limits<double>::quiet_NaN();
  double initial_gauge_pressure = 0.0;
  TimeFunction supply_gauge_pressure = TimeFunction::constant(0.0);  // p_s(t) [Pa]
  TimeFunction conductance = TimeFunction::constant(0.0);            // C(t) [mol/(s Pa)]
  // Instead of C: the fill time constant tau [s] of the rigid cavity at its
  // reference volume, C = V_ref / (tau R T) (constant; NaN: use `conductance`).
  // A valve sized by how fast it fills the chamber, whatever the chamber's size.
  double fill_time = std::numeric_limits<double>::quiet_NaN();
  bool has_vacuum_conductance = false;                            // false: C(t) for vacuum too
  TimeFunction vacuum_conductance = TimeFunction::constant(0.0);  // C_vac(t) [mol/(s Pa)]
  // The conductance of the step ending at t1 (C or C_vac by the sign of p_s(t1)).
  double conductance_at(double t1) const {
    return has_vacuum_conductance && supply_gauge_pressure(t1) < 0 ? vacuum_conductance(t1) : conductance(t1);
  }
};

class GasCavityTerm : public CavityVolumeTerm {
 public:
  GasCavityTerm(const Mesh& mesh, const Partition& partition, int rank, GasCavitySpec spec);
  std::string name() const override { return "gas_cavity:" + spec_.wall.name; }
  // At the converged time (after a failed step) the step's parameters return to
  // the converged state (m = n, V_r = 0).
  void set_time(double t) override;
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  void end_step(Assembler& assembler, Vec u1, double t1) override;
  // n, the last step's flow rate and the converged volume.
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;

  double energy_of_volume(double V) const override;
  double energy_derivative(double V) const override;
  double energy_second_derivative(double V) const override;

  // The valve step without the FE state (begin_step/end_step forward to these):
  // begin sets m and V_r for the step t0 -> t1; end takes the converged whole-
  // cavity volume V1 [m^3] and updates n. Public for single-process tests.
  void begin_valve_step(double t0, double t1);
  void end_valve_step(double V1, double t1);

  // At the last converged state (last converged state after end_step):
  double absolute_pressure() const;                                                              // p [Pa]
  double pressure() const override { return absolute_pressure() - spec_.atmospheric_pressure; }  // gauge [Pa]
  double amount() const { return amount_; }                                                      // n [mol]
  std::string state_column() const override { return "amount_mol"; }
  double state_value() const override { return amount_; }
  double molar_flow_rate() const { return flow_rate_; }  // (n1 - n0)/dt of the last step [mol/s]
  // Sets the gas amount [mol] (e.g. a sealed cavity filled to a given state).
  void set_amount(double n);
  const GasCavitySpec& spec() const { return spec_; }
  // Rigid-cavity fill time constant tau = V / (C R T) [s] at volume V [m^3], conductance C.
  double time_constant(double V, double C) const { return V / (C * kGasConstant * spec_.temperature); }

 private:
  GasCavitySpec spec_;
  double amount_ = 0.0;       // n at the last converged state [mol]
  double step_amount_ = 0.0;  // m of the current step [mol]
  double reservoir_ = 0.0;    // V_r of the current step [m^3]
  double step_dt_ = 0.0, flow_rate_ = 0.0;
};

// ------------------------------------------------------ volume-controlled cavity
// Prescribed whole-cavity volume V*(t) [m^3]; the gauge pressure is the multiplier.
// Augmented Lagrangian with multiplier lambda [Pa] and penalty k [Pa/m^3]:
//   Phi(V) = -lambda (V - V*) + k/2 (V - V*)^2,   p = lambda - k (V - V*)  (gauge)
//   Phi' = -p,  Phi'' = k  (dense rank 1 via low_rank()).
// After each converged solve, update_after_solve sets lambda <- p and asks for a
// re-solve while |V - V*| > tolerance V* (from the second update of a step on, a
// secant step on lambda -> V(lambda) through the last two solves replaces it). Linearising the structure's equilibrium
// pressure-volume curve p = P(V) with slope K_s = dP/dV, the multiplier error
// shrinks by K_s / (K_s + k) per update, and the inner problem is convex in the
// volume direction while k + K_s > 0 (past a pressure maximum K_s < 0: k must
// exceed |K_s|).
// Choice of k: k = max(k_0, 10 |K_s|) with k_0 = penalty_modulus / V_ref, and K_s
// the secant slope of the last two converged (V, p) points (updated each step).
// penalty_modulus [Pa] is the pressure that a 100 % volume change would cost: take
// about 10x the structure's small-strain volume stiffness V dP/dV, e.g. for a
// thick incompressible neo-Hookean sphere (4/3) mu (1 - (A/B)^3), for a thin
// balloon 4 mu H/R. Each step also starts from the secant prediction
// lambda = p_1 + K_s (V*(t1) - V_1), so most steps need 1-3 updates.
struct VolumeControlSpec {
  CavityWallSpec wall;
  TimeFunction volume;           // V*(t) [m^3], whole cavity (or V*/V_ref, see below)
  bool volume_is_ratio = false;  // true: `volume` is V*(t) / V_ref (the reference volume from the mesh)
  double penalty_modulus = 0.0;  // [Pa], > 0 (see above)
  double tolerance = 1e-6;       // |V - V*| <= tolerance V*
};

class VolumeControlledCavityTerm : public CavityVolumeTerm {
 public:
  VolumeControlledCavityTerm(const Mesh& mesh, const Partition& partition, int rank, VolumeControlSpec spec);
  std::string name() const override { return "volume_cavity:" + spec_.wall.name; }
  // Sets V*(t); at the converged time (after a failed step) lambda returns to the
  // converged pressure.
  void set_time(double t) override;
  void begin_step(Assembler& assembler, Vec u0, double t0, double t1) override;
  bool update_after_solve(Assembler& assembler, Vec u1) override;
  void end_step(Assembler& assembler, Vec u1, double t1) override;
  // lambda, k, the converged pressure and the last two converged (V, p).
  void save_state(Assembler& assembler, const std::string& prefix, StateRecord& state) override;
  void load_state(Assembler& assembler, const std::string& prefix, const StateRecord& state) override;

  double energy_of_volume(double V) const override;
  double energy_derivative(double V) const override;
  double energy_second_derivative(double V) const override { return penalty_; }

  double pressure() const override { return converged_pressure_; }  // gauge [Pa], last converged state
  double target_volume() const { return target_; }                  // V*(t) [m^3]
  std::string state_column() const override { return "target_volume_m3"; }
  double state_value() const override { return target_; }
  double multiplier() const { return multiplier_; }
  double penalty() const { return penalty_; }
  int outer_updates() const { return outer_updates_; }  // total multiplier updates so far
  // For tests: sets lambda [Pa] and k [Pa/m^3].
  void set_multiplier(double lambda, double k) {
    multiplier_ = lambda;
    penalty_ = k;
  }
  const VolumeControlSpec& spec() const { return spec_; }

 private:
  VolumeControlSpec spec_;
  double target_ = 0.0, multiplier_ = 0.0, penalty_ = 0.0, base_penalty_ = 0.0, converged_pressure_ = 0.0;
  int outer_updates_ = 0;
  bool has_previous_solve_ = false;  // within the step: the last solve's (lambda, V)
  double previous_multiplier_ = 0.0, previous_volume_ = 0.0;
  std::vector<std::pair<double, double>> history_;  // converged (V, p), last two
};

}  // namespace morphfem
