// Meshes through the gmsh C++ API: a .geo is meshed at the size the case asks for, a .msh is
// read; both are checked (first-order quadrilaterals only, one physical group per entity, every
// surface in a physical surface) and written back as ASCII MSH 4.1 text for deal.II's stream
// reader, without Physical Points (which deal.II's readers do not handle well).
#include <gmsh.h>
#include <mpi.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <memory>
#include <set>
#include <sstream>

#include "silentmpm/mpi_bytes.hpp"
#include "silentmpm/fem.hpp"
#include "silentmpm/gmsh_session.hpp"

namespace smpm::fem {

namespace {

namespace fs = std::filesystem;

std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}

const char* kSizeParameter = "Parameters/h";

std::string element_name(int type) {
  std::string name;
  int dim = 0, order = 0, nn = 0, npv = 0;
  std::vector<double> lc;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, nn, lc, npv);
  } catch (...) {
    return "element type " + std::to_string(type);
  }
  return name;
}

}  // namespace

const PhysicalGroup* Mesh::surface(int tag) const {
  for (const auto& g : surfaces)
    if (g.tag == tag) return &g;
  return nullptr;
}
const PhysicalGroup* Mesh::curve(int tag) const {
  for (const auto& g : curves)
    if (g.tag == tag) return &g;
  return nullptr;
}

static int find_tag(const std::vector<PhysicalGroup>& gs, const std::string& s) {
  for (const auto& g : gs)
    if (g.name == s || std::to_string(g.tag) == s) return g.tag;
  return -1;
}
int Mesh::surface_tag(const std::string& s) const { return find_tag(surfaces, s); }
int Mesh::curve_tag(const std::string& s) const { return find_tag(curves, s); }

namespace {
Mesh mesh_here(const std::string& file, double size, double max_cells,
               const std::vector<std::pair<std::string, double>>& parameters) {
  std::error_code ec;
  if (!fs::exists(file, ec)) throw FemError(file + ": mesh file not found");
  if (fs::is_directory(file, ec)) throw FemError(file + ": is a directory, not a mesh file");
  if (const std::string e = gmsh_input_problem(file); !e.empty()) throw FemError(file + ": " + e);
  const std::string ext = fs::path(file).extension().string();
  if (ext != ".geo" && ext != ".msh")
    throw FemError(file + ": unsupported mesh file (expected a gmsh .geo or .msh)");
  if (ext == ".msh" && size > 0)
    throw FemError(file + ": a mesh size applies to a .geo only (a .msh is already meshed)");

  if (ext == ".msh" && !parameters.empty())
    throw FemError(file + ": parameters apply to a .geo only (a .msh is already meshed)");

  Mesh m;
  m.file = file;
  m.size = size;
  // The parameters go in through a wrapper .geo (gmsh_session.hpp); the size through ONELAB.
  std::unique_ptr<GeoParameters> wrapper;
  try {
    wrapper = std::make_unique<GeoParameters>(file, 0.0, parameters);
  } catch (const std::runtime_error& e) {
    throw FemError(e.what());
  }
  const std::string opened = wrapper->path();
  GmshSession gs;
  auto fail = [&](const std::string& what) -> void { throw FemError(file + ": " + what); };
  if (const std::string e = gs.call_error([&] { gmsh::open(opened); }); !e.empty())
    fail("gmsh cannot read it: " + e);
  if (ext == ".geo") {
    std::vector<double> hv;
    gmsh::onelab::getNumber(kSizeParameter, hv);
    if (size > 0) {
      if (hv.empty())
        fail("the .geo does not declare its mesh size as DefineConstant[ h = {..., Name \"" +
             std::string(kSizeParameter) + "\"} ], so the size " + fmt(size) +
             " cannot be applied");
      gmsh::onelab::setNumber(kSizeParameter, {size});
      // Parse again with the new size.
      if (const std::string e = gs.call_error([&] { gmsh::open(opened); }); !e.empty())
        fail("gmsh cannot read it: " + e);
    }
    // Before meshing: a size that would make more cells than the run could hold is refused
    // (meshing alone would take hours and ignore signals).
    if (!hv.empty() || size > 0) {
      std::vector<double> h_now;
      gmsh::onelab::getNumber(kSizeParameter, h_now);
      if (!h_now.empty())
        if (const std::string e = gmsh_mesh_size_problem(h_now[0], max_cells); !e.empty()) fail(e);
    }
    gmsh::option::setNumber("Mesh.RecombineAll", 1);
    if (const std::string e = gs.call_error([] { gmsh::model::mesh::generate(2); }); !e.empty())
      fail("gmsh cannot mesh it: " + e);
  }

  // Element checks.
  std::vector<int> types;
  gmsh::model::mesh::getElementTypes(types, 2);
  if (types.empty()) fail("has no 2D elements (is it meshed? a .geo needs Plane Surface)");
  for (int t : types) {
    if (t == 3) continue;  // 4-node quadrangle
    if (t == 2)
      fail("contains triangles; the FEM far-field needs an all-quad mesh (use Recombine "
           "Surface or Transfinite Surface with Recombine)");
    fail("contains " + element_name(t) +
         " elements; only first-order 4-node quadrilaterals are supported (second-order elements: "
         "set Mesh.ElementOrder = 1)");
  }
  std::vector<int> ltypes;
  gmsh::model::mesh::getElementTypes(ltypes, 1);
  for (int t : ltypes)
    if (t != 1)
      fail("contains " + element_name(t) + " boundary elements; only first-order lines are supported");
  {
    std::vector<std::size_t> tags, nodes;
    gmsh::model::mesh::getElementsByType(3, tags, nodes);
    m.quads = tags.size();
  }

  // Physical groups.
  gmsh::vectorpair groups;
  gmsh::model::getPhysicalGroups(groups);
  std::map<std::pair<int, int>, int> entity_group;
  for (const auto& [dim, tag] : groups) {
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    if (dim == 2) m.surfaces.push_back({tag, name});
    if (dim == 1) m.curves.push_back({tag, name});
    if (dim == 1 || dim == 2) {
      if (tag <= 0) fail("physical group " + std::to_string(tag) + " must have a positive tag");
      std::vector<int> ents;
      gmsh::model::getEntitiesForPhysicalGroup(dim, tag, ents);
      for (int e : ents) {
        auto [it, fresh] = entity_group.emplace(std::make_pair(dim, e), tag);
        if (!fresh)
          fail(std::string(dim == 2 ? "surface " : "curve ") + std::to_string(e) +
               " belongs to two physical groups (" + std::to_string(it->second) + " and " +
               std::to_string(tag) + "); give each entity one group");
      }
    }
  }
  if (m.surfaces.empty())
    fail("has no Physical Surface; every surface needs one (it gives the material)");
  gmsh::vectorpair surfs;
  gmsh::model::getEntities(surfs, 2);
  for (const auto& [dim, tag] : surfs)
    if (!entity_group.count({dim, tag}))
      fail("surface " + std::to_string(tag) + " is in no Physical Surface (its elements would be lost)");
  for (const auto& [dim, tag] : groups)
    if (dim == 0) gmsh::model::removePhysicalGroups({{0, tag}});

  // Write ASCII MSH 4.1 and read it back as text.
  gmsh::option::setNumber("Mesh.MshFileVersion", 4.1);
  gmsh::option::setNumber("Mesh.Binary", 0);
  gmsh::option::setNumber("Mesh.SaveAll", 0);
  const fs::path tmp = fs::temp_directory_path() /
                       ("smpm_mesh_" + std::to_string(::getpid()) + "_" +
                        std::to_string(reinterpret_cast<std::uintptr_t>(&m)) + ".msh");
  if (const std::string e = gs.call_error([&] { gmsh::write(tmp.string()); }); !e.empty())
    fail("gmsh cannot write the mesh: " + e);
  std::ifstream f(tmp);
  std::ostringstream ss;
  ss << f.rdbuf();
  m.msh = ss.str();
  fs::remove(tmp, ec);
  if (m.msh.empty()) fail("gmsh wrote an empty mesh");
  return m;
}


// Several MPI ranks (docs/parallel.md, "The FE far field"): every rank asks for the mesh at
// once; rank 0 alone reads or meshes the file and sends the result (or its error, which every
// rank then throws) to the others.
void broadcast(std::string& s) { broadcast_bytes(s, MPI_COMM_WORLD); }

void broadcast(std::vector<PhysicalGroup>& groups) {
  unsigned long long n = groups.size();
  MPI_Bcast(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  groups.resize(n);
  for (auto& g : groups) {
    MPI_Bcast(&g.tag, 1, MPI_INT, 0, MPI_COMM_WORLD);
    broadcast(g.name);
  }
}
}  // namespace

Mesh load_mesh(const std::string& file, double size, double max_cells,
               const std::vector<std::pair<std::string, double>>& parameters, bool text_to_all) {
  int running = 0, finished = 0, ranks = 1, rank = 0;
  MPI_Initialized(&running);
  if (running) MPI_Finalized(&finished);
  if (running && !finished) {
    MPI_Comm_size(MPI_COMM_WORLD, &ranks);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  }
  if (ranks == 1) return mesh_here(file, size, max_cells, parameters);
  Mesh m;
  std::string why;
  if (rank == 0) {
    try {
      m = mesh_here(file, size, max_cells, parameters);
    } catch (const std::exception& e) {  // any failure: the others must not wait for a mesh
      why = e.what();
      if (why.empty()) why = file + ": the mesh could not be read";
    }
  }
  broadcast(why);
  if (!why.empty()) throw FemError(why);
  broadcast(m.file);
  MPI_Bcast(&m.size, 1, MPI_DOUBLE, 0, MPI_COMM_WORLD);
  int text = text_to_all ? 1 : 0;  // rank 0's word: whether the text goes to every rank
  MPI_Bcast(&text, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (text) broadcast(m.msh);
  broadcast(m.surfaces);
  broadcast(m.curves);
  unsigned long long quads = m.quads;
  MPI_Bcast(&quads, 1, MPI_UNSIGNED_LONG_LONG, 0, MPI_COMM_WORLD);
  m.quads = static_cast<std::size_t>(quads);
  return m;
}

}  // namespace smpm::fem
