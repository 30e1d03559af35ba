#pragma once
// Discontinuous bifurcation (REFERENCE.md §5): the acoustic tensor Q_jk(n) = n_i C_ijkl n_l of a
// continuum tangent, its determinant swept over the normal angle, and the closed-form J2 criterion
// used as the sweep's test oracle.
//
// Normals n and -n describe one plane, so angles are taken in [0, 180) degrees, measured from +x.
// A symmetric state has two critical planes (+theta and -theta = 180 - theta); which one a
// particle takes is the tie-break, an input:
//   SmallestAngle  the candidate with the smaller angle in [0, 180)  (default: +44.7 deg in plate
//                  tension, n along x in simple shear)
//   LargestAngle   the candidate with the larger angle (135.3 deg = -44.7 deg; n along y)
// Two minima tie when their determinants differ by less than tie_tolerance * mu * M.

namespace smpm {

enum class TieBreak { SmallestAngle, LargestAngle };

struct BifurcationParams {
  bool enabled = true;
  double step_deg = 1.0;          // sweep step
  TieBreak tie = TieBreak::SmallestAngle;
  double tie_tolerance = 1e-9;    // relative (to mu * M) difference under which minima tie
};

struct BifurcationResult {
  bool bifurcated = false;  // min det Q <= 0
  double theta = 0;         // critical angle in degrees, [0, 180)
  double det_min = 0;       // det Q at theta
  int minima = 0;           // number of tied minima the tie-break chose among
};

// det Q(n) for the tangent C (layout of j2_tangent) and n = (cos th, sin th), th in radians.
double acoustic_det(const double C[16], double theta_rad);

// Sweep theta over [0, 180) in steps of P.step_deg, refine every local minimum (golden section
// within one step on each side), pick the global minimum with the tie-break. scale = mu * M
// (for the tie tolerance).
BifurcationResult bifurcation_sweep(const double C[16], const BifurcationParams& P, double scale);

// Closed-form J2 criterion (REFERENCE.md §5): bifurcation on the plane of normal n iff
// H <= H_cr(n) = 6G(|a|^2 - (a.n)^2) + (6G^2/M)(a.n)^2 - 3G, a = N n (in-plane block of s/|s|).
double hcr_j2(double sxx, double syy, double szz, double sxy, double mu, double M, double theta_rad);
// max over the normal angle of hcr_j2 (fine sweep and refinement); theta_deg gets the argmax.
double hcr_j2_max(double sxx, double syy, double szz, double sxy, double mu, double M,
                  double* theta_deg = nullptr);

}  // namespace smpm
