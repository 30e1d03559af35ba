#pragma once
// gmsh geometries for MPM bodies and boundary sets.
//
//  * load_geometry() opens a gmsh `.geo` (meshed in 2D through the gmsh C++ API, with the mesh
//    size variable `h` set to the size asked for) or a `.msh` file, and returns the first-order
//    triangles/quadrangles of every physical surface and the line segments of every physical
//    curve. gmsh itself stays inside geometry.cpp: this header does not include gmsh.h.
//  * seed_surface() fills a physical surface with particles on the grid lattice (n x n per
//    cell, at the sub-cell positions Solver::seed_rectangle uses for a grid-aligned box), keeping
//    the lattice points inside the surface's elements.
//  * select_curve_layer() picks the particles of a body within a depth of a physical curve, each
//    with the outward normal of the curve at its closest point and the boundary-length weight of
//    BoundaryLayer (sum of weights = curve length exactly).
//  * nodes_near_curve() picks the grid nodes within a distance of a physical curve (fixed and
//    roller conditions).
//
// Errors throw GeometryError with a message that names the file and the physical group.
#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "silentmpm/boundary.hpp"
#include "silentmpm/particles.hpp"

namespace smpm {

class Solver;

struct GeometryError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct Geometry {
  struct Surface {
    int tag = 0;
    std::string name;
    // Node indices of each element; [3] = -1 for a triangle.
    std::vector<std::array<int, 4>> elems;
  };
  struct Curve {
    int tag = 0;
    std::string name;
    std::vector<std::array<int, 2>> segs;  // node indices of each 2-node line
    // Per segment: the point of the CAD curve over the segment's middle (the chord midpoint
    // projected onto the gmsh curve; the chord midpoint itself for a .msh or a straight curve).
    // Curve probes treat each segment as the circular arc through its ends and this point.
    std::vector<std::array<double, 2>> mid;
  };

  std::string file;                  // as given (for messages)
  std::vector<double> x, y;          // node coordinates (z ignored; must be 0)
  std::vector<Surface> surfaces;     // physical surfaces, ordered by tag
  std::vector<Curve> curves;         // physical curves, ordered by tag

  // Index into surfaces / curves, or -1.
  int find_surface(int tag) const;
  int find_surface(const std::string& name) const;
  int find_curve(int tag) const;
  int find_curve(const std::string& name) const;
  // `1 "aluminium", 2 "steel"` for messages.
  std::string list_surfaces() const;
  std::string list_curves() const;
  // "physical surface 2 \"steel\"" for messages.
  static std::string label(const char* kind, int tag, const std::string& name);
  // A coordinate or length for messages (6 significant digits).
  static std::string num(double v);

  double area(const Surface& s) const;
  std::array<double, 4> bounds(const Surface& s) const;  // xmin, ymin, xmax, ymax
  double length(const Curve& c) const;
  // True if (px, py) lies in an element of s or within tol of one.
  bool contains(const Surface& s, double px, double py, double tol) const;
};

// Read a .geo (meshed with mesh size `size`; size <= 0 keeps the file's own `h`) or a .msh.
// `parameters` set other numbers of a .geo before it is read (gmsh -setnumber; the .geo declares
// them with DefineConstant so that the given value wins).
// Throws GeometryError "<file>: ..." for an unreadable, empty or unparsable file, a file without
// physical surfaces, second-order or unsupported elements, or a geometry outside the z = 0 plane,
// and a size that would give more than max_cells cells (estimated before meshing).
Geometry load_geometry(const std::string& file, double size,
                       const std::vector<std::pair<std::string, double>>& parameters = {},
                       double max_cells = 1e7);

// The physical groups of the same file, without meshing a .geo: each surface and curve with its
// tag and name and no elements (a case's references to them are checked with this before the
// mesh is made). Throws as load_geometry() does for a file that cannot be read or names no group.
Geometry load_geometry_groups(const std::string& file, double size,
                              const std::vector<std::pair<std::string, double>>& parameters = {});

// Lattice seeding of surface `s` into solver `sol` (grid already initialised, materials set):
// points grid.x0 + (i + 1/2) h / n, grid.y0 + (j + 1/2) h / n inside an element, volume
// (h / n)^2, mass rho (h / n)^2. Returns the number of particles added. Throws GeometryError if
// the surface reaches outside the grid. Seeding::Gauss takes each grid cell's n x n
// Gauss-Legendre points instead (Solver::gauss_point), each with its weights' share of h^2.
std::size_t seed_surface(Solver& sol, const Geometry& g, const Geometry::Surface& s, int n_per_side,
                         int group, int body, double vx0, double vy0,
                         Seeding seeding = Seeding::Uniform);

// Which side of a curve the body lies on: the body's surface (for a body seeded from the
// geometry) or its box.
struct BodyRegion {
  const Geometry::Surface* surface = nullptr;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // box, when surface is null
};

// Particles of `body` within `depth` of curve `c` (distance to the discretised curve < depth,
// closest point not beyond an open end of the curve). Normals: each segment's outward normal
// (away from the body), blended linearly along the segment towards the mean normal at vertices
// where the curve turns by less than 30 degrees (exactly radial on a discretised circle);
// corners keep the normal of each side. Weights w = V_p L / sum V_p with L the curve length.
// Throws GeometryError if the curve does not bound the body (body on neither or both sides).
enum class LayerWeights {
  Volume,  // w = V_p L / sum V_p (as Solver::select_layer)
  Length   // w = the length of curve nearest to the particle's projection (1D Voronoi cells)
};
BoundaryLayer select_curve_layer(const Solver& sol, const Geometry& g, const Geometry::Curve& c,
                                 const BodyRegion& region, int body, double depth,
                                 const std::string& name,
                                 LayerWeights weights = LayerWeights::Volume);

// Points evenly spaced by arc length along a physical curve (probes along a curve,
// geometry_probes.cpp). The curve's segments must form one chain, open or closed (end points of
// its pieces that coincide to 1e-9 of its extent are joined); it runs in the
// direction of its first segment (the first gmsh curve of the group), or the opposite one with
// `reverse`. Each segment is the circular arc through its end points and Curve::mid (exact for
// straight lines and circles). Open chain: `count` points from end to end, s_k = k L / (count-1);
// closed: `count` points s_k = k L / count. With spacing > 0 instead of count (count = 0):
// s_k = k * spacing for as many points as fit (the last one <= L; < L on a closed chain).
// Throws GeometryError naming the file and the curve.
struct CurvePoint {
  double x, y;    // on the curve
  double cx, cy;  // the same point on the meshed segment (for inside tests)
  double s;       // arc length from the first point
};
struct CurvePoints {
  std::vector<CurvePoint> points;
  double length = 0;  // arc length of the whole curve
  bool closed = false;
};
CurvePoints curve_points(const Geometry& g, const Geometry::Curve& c, int count, double spacing,
                         bool reverse);

// Grid nodes within `tol` of curve `c` (closest point not beyond an open end, to 1e-6 h).
std::vector<uint32_t> nodes_near_curve(const Solver& sol, const Geometry& g,
                                       const Geometry::Curve& c, double tol);

}  // namespace smpm
