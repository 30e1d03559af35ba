#pragma once
// Contact between bodies that share the background grid.
//
// Two modes, chosen per case:
//
//  * Single (default, the paper's): every body maps to one velocity field. Bodies that reach a
//    common node move with one velocity there: no interpenetration, but also no slip and no
//    separation (they stick). The solver's ordinary step is this mode; nothing here runs.
//
//  * Multi (Bardenhagen, Brackbill & Sulsky 2000): one velocity field per body. Each step every
//    body has its own nodal mass, momentum, internal force and mass gradient
//    g_b,i = sum_p m_p grad N_i(x_p) (which points out of body b at its surface). The centre of
//    mass field (the sum over bodies) takes the loads, the silent-layer dashpots and the
//    constraints exactly as in the single mode. At a node where two or more bodies have mass:
//
//      v_b+   = v_cm+ + [(p_b + dt f_b) / m_b - (p + dt f) / m]    (body's own acceleration,
//               loads and dashpots shared by all bodies; sum_b m_b v_b+ = m v_cm+ exactly)
//      n      = g_h / |g_h|, h the body with the largest nodal mass   (outward normal of h;
//               n_b = n for b = h, -n for the others)
//      dv     = v_b+ - v_cm+,  dv_n = dv . n_b
//      only if dv_n > 0 (approaching; for two bodies this is (v_1 - v_2) . n_1 > 0):
//        v_b+ -= dv_n n_b                                          (no interpenetration)
//        v_b+ -= min(mu dv_n, |dv_t|) dv_t / |dv_t|                (Coulomb: stick or slide)
//
//    Normal: the heavier body's mass gradient. It is one normal shared by the pair, so the
//    corrections of the two bodies are equal and opposite impulses and the total momentum is
//    conserved to round-off. The heavier body has more particle mass in the node's support, so
//    its gradient is the better resolved one; in particular where a small body sits on a larger
//    one, the larger body's face stays flat under the small body's corners. The symmetric
//    alternative, the difference g_1 - g_2, tilts the normal at such corners and the contact then
//    "ploughs": a block sliding frictionless on a base (tests/physics/test_contact.cpp) received 7 % less
//    than its tangential impulse with it, 0.1 % with the heavier-body normal. Where the heavier
//    body's gradient is weak (shorter than 1/4 of |g_h - g_others|: a node inside body h) the
//    difference is used. Where a velocity component is held by a constraint, that component of
//    the normal is dropped (the contact acts along the free directions only).
//
//    Gap check: two bodies share a node as soon as their particles are less than about a cell
//    apart (a cell and a half with the wide shapes), so sharing a node is not touching. At each
//    shared node the nodal centroid of each body's particles, x_b = sum m_p N x_p / m_b, and
//    their mean size s_b = sum m_p N sqrt(V_p) / m_b give how far the node lies outside that
//    body's surface, d_b: a flat surface with layers of particles of size s_b behind it puts the
//    centroid offset(d) behind the node, offset the layers' distances weighted by the case's own
//    1D shape (contact.cpp), and the measured offset gives d_b back. The gap between the
//    particle domains is d_h + d_b; only a body whose gap is closed (below 1 % of a cell) is in
//    contact with h. Without the check, bodies less than a cell apart keep exchanging impulses
//    while not touching (a rebounding flyer stays within a cell of the target for tens of
//    microseconds). Earlier forms and what they did to the 1D impact (docs/physics.md §4): one
//    reach per body, s / 2, exact at 1 ppc only (4 ppc lost 39 % of the energy and rebounded at
//    half the closed form's speed, 9 ppc gained 43 %); one reach per body from the bilinear
//    weights at a node on the surface, whose offset grows only 0.63-0.75 times as fast as d
//    from 4 ppc on (the face 0.25 of a cell off the grid lines at 4 ppc: rebound 1.21 of the
//    closed form, +15 %; B-splines on the lines: duration 1.07, rebound 1.04, +1.6 %).
//    Each body's particles then take their own corrected field in g2p. The velocity gradient
//    (MUSL: from the re-mapped momenta; USF: from the start-of-step momenta) is each body's own
//    uncorrected field: correcting it too fed the light body's edge particles a spurious strain
//    rate through grad N (not small where N is) and gained energy (+30 % of the impact energy
//    in the impact study, with the flyer leaving at -7.0 m/s; 0.4 % loss without it).
//
//    Energy: the corrections are impulses m_b dv_b. Their work on the corrected velocities is
//    zero for the normal part (after it the pair moves together along n: an ideal constraint)
//    and, for friction, the tangential impulse times the slip velocity that remains, which is
//    the Coulomb dissipation mu N |v_slip| dt. It is accumulated in `dissipated` and added to
//    Solver::energy.dissipated, so the energy balance stays closed. (Counting the work on the
//    mid-step velocity instead would book the nodal "inelastic collision" of the first touch,
//    0.5 % of the impact energy in the 1D test, which the particles do not actually lose: their
//    kinetic + elastic energy stays within 0.04 % of the initial one.)
#include <array>
#include <cstdint>
#include <vector>

#include "silentmpm/step_hooks.hpp"

namespace smpm {

enum class ContactType { Single, Multi };
const char* contact_type_name(ContactType t);

// In the multi mode a hook set on the solver's step: the step maps each body to its own field
// (the arrays below) and their sum to the grid; the hooks find the contact nodes after the
// momentum p2g and split and correct the bodies' updated velocities after the grid update.
class Contact : public StepHooks {
 public:
  ContactType type = ContactType::Single;
  double friction = 0.0;  // Coulomb coefficient mu >= 0 (multi only)

  bool multi() const { return type == ContactType::Multi; }

  // Diagnostics of the last step (multi only).
  double dissipated = 0;               // accumulated energy removed by the contact corrections
  std::vector<std::array<double, 2>> force;  // contact force on each body (N per unit thickness)
  long contact_nodes = 0;              // nodes where two or more bodies have mass
  long active_nodes = 0;               // of those, nodes where bodies approached (corrected)

  // Called by Solver::finalize (multi only): splits material groups so that every group holds
  // particles of one body (a body's particles then form contiguous ranges), sizes the fields and
  // hands them to the solver (Solver::use_body_fields).
  void setup(Solver& s);
  // The split's outcome, for the ranks of a set-up from rank 0 that built the case without its
  // particles (docs/parallel.md "Set-up"): the bodies, the groups before the split, the group
  // each added group copies and the body of every group.
  std::vector<int> split_layout() const;
  // Rank 0's split (split_layout) on a rank whose solver holds no particles and has not split
  // its groups: the same copies of materials, the same bodies, the fields sized.
  void adopt_split(Solver& s, const std::vector<int>& layout);
  // Sizes the bodies' fields to the solver's grid and hands them to it: by setup, and again
  // when a decomposition replaced the grid by a window of it.
  void resize(Solver& s);

  // The hooks of the multi mode.
  void after_momentum(Solver& s) override;     // contact nodes
  void after_grid_update(Solver& s) override;  // bodies' velocities, contact correction
  // The power of the loads is taken with v+: there is no single re-mapped field.
  bool remapped_power() const override { return false; }

 private:
  int nb_ = 0;                    // bodies
  std::vector<int> body_of_group_;
  int groups_before_ = 0;          // material groups before the split
  std::vector<int> copied_from_;  // per group the split added: the group it copies
  using Field = std::vector<std::vector<double>>;  // [body][node]
  Field m_, px_, py_, fx_, fy_, gx_, gy_, vx_, vy_, vnx_, vny_, qx_, qy_;
  Field xm_, ym_, sm_;  // sum m_p N x_p, sum m_p N y_p, sum m_p N sqrt(V_p): nodal centroid, size
  std::vector<uint32_t> cnodes_;  // nodes with two or more bodies this step

  void find_contact_nodes(Solver& s);
  void split_start(Solver& s);
  void split_updated(Solver& s);
  void correct(Solver& s, Field& vx, Field& vy, bool count);
};

}  // namespace smpm
