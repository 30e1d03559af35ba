#pragma once
// Light nodes: a node just beyond a body's face whose cell holds only a sliver of the face's
// particles (the face just past a grid line) takes, instead of a velocity of its own, the
// linear extension of the velocity of the heavy nodes behind it (docs/physics.md section 8.7).
// Its mass, momentum and forces go to those nodes with the extension's weights (the
// transpose), so the step is MPM on the extended basis: the functions still sum to one, the
// momentum is the same, each mass is its extended function's lumped mass. The solver calls
// these at the points of its step named in solver.hpp.
#include <cstddef>
#include <vector>

namespace smpm {

struct Grid;

class LightNodes {
 public:
  // A node is light when it is at most `ratio` times as heavy as every node its extension
  // reads (and the body ends beyond it); 0 turns the extension off.
  double ratio = 0;
  static constexpr double kDefaultRatio = 0.15;  // the case key's default
  bool active() const { return ratio > 0; }
  std::size_t count() const { return links_.size(); }  // light nodes this step

  // After the momentum p2g: the nodes that may be light (heavier than the void's `floor`, at
  // most `ratio` times the heaviest, unconstrained); false, and no light node, when none is.
  bool candidates(const Grid& g, double floor);
  // Then the light nodes among them (none where `layer` is set: the nodes the boundary layers
  // weigh); their masses and momenta to the heavy nodes.
  void classify_and_fold(Grid& g, const std::vector<char>& layer);
  // The loads are in: their forces, less gravity's share (gx, gy: the gravity that acted on
  // every node's own mass, the heavy nodes' already including the light nodes').
  void fold_forces(Grid& g, double gx, double gy) const;
  void fold(double* a) const;          // a_j += w a_i (the transpose of the extension)
  void extend(double* a) const;        // a_i = sum w a_j
  // The mass correction's product a = M_c t at the light nodes' masters (folded), and at each
  // light node the value that makes its next term t - a / m the extension of its masters'
  // (m: the masses; fix: the constraints; floor: the void nodes' mass).
  void fold_product(const double* m, const unsigned char* fix, double floor, const double* tx,
                    const double* ty, double* ax, double* ay) const;

 private:
  struct Link {
    long node = 0;
    int n = 0;  // masters
    long master[4] = {0, 0, 0, 0};
    double w[4] = {0, 0, 0, 0};
  };
  std::vector<Link> links_;
  std::vector<long> cand_;
  std::vector<char> light_, keep_;
};

}  // namespace smpm
