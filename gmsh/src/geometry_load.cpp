// Reading gmsh geometries (.geo meshed through the gmsh C++ API, or .msh) into plain arrays:
// node coordinates, the elements of each physical surface, the segments of each physical curve.
// Part of the gmsh module (with the session, gmsh_session.cpp); with fem/src/fem_mesh.cpp the
// only file of the project that calls gmsh.
#include <gmsh.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include <unistd.h>

#include "silentmpm/geometry.hpp"
#include "silentmpm/gmsh_module.hpp"
#include "silentmpm/gmsh_session.hpp"

namespace smpm {

namespace {

std::string fmt17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

std::string lower_ext(const std::string& file) {
  std::string e = std::filesystem::path(file).extension().string();
  for (char& c : e) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return e;
}

// Run a gmsh call; turn every way gmsh reports failure (a thrown std::string, an exception, an
// "Error" in the log) into a GeometryError.
void gmsh_call(const GmshSession& session, const std::string& file, const char* what,
               const std::function<void()>& fn) {
  const std::string err = session.load_error(fn);
  if (!err.empty()) throw GeometryError(file + ": gmsh could not " + what + ": " + err);
}

std::string element_name(int type) {
  std::string name;
  int dim, order, nn, npn;
  std::vector<double> lc;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, nn, lc, npn);
  } catch (...) {
    return "type " + std::to_string(type);
  }
  return "\"" + name + "\" (gmsh type " + std::to_string(type) + ")";
}

int element_order(int type) {
  std::string name;
  int dim, order = 1, nn, npn;
  std::vector<double> lc;
  try {
    gmsh::model::mesh::getElementProperties(type, name, dim, order, nn, lc, npn);
  } catch (...) {
  }
  return order;
}

// Curve::mid: the chord midpoint of every segment, projected onto the gmsh curve entity it was
// meshed from (a .geo's CAD curve; `entities` lists (entity, first segment) and is empty for a
// .msh). A projection that fails or lands far from the chord (more than a quarter of its length)
// keeps the chord midpoint. Exceptions are swallowed and the log is not consulted: a failed
// projection only costs the exactness of curve probe positions.
void curve_mids(const Geometry& g, Geometry::Curve& c,
                const std::vector<std::pair<int, std::size_t>>& entities) {
  c.mid.resize(c.segs.size());
  for (std::size_t k = 0; k < c.segs.size(); ++k) {
    const auto& sg = c.segs[k];
    c.mid[k] = {0.5 * (g.x[sg[0]] + g.x[sg[1]]), 0.5 * (g.y[sg[0]] + g.y[sg[1]])};
  }
  for (std::size_t e = 0; e < entities.size(); ++e) {
    const std::size_t k0 = entities[e].second;
    const std::size_t k1 = e + 1 < entities.size() ? entities[e + 1].second : c.segs.size();
    if (k1 <= k0) continue;
    std::vector<double> xyz, closest, param;
    for (std::size_t k = k0; k < k1; ++k) xyz.insert(xyz.end(), {c.mid[k][0], c.mid[k][1], 0.0});
    try {
      gmsh::model::getClosestPoint(1, entities[e].first, xyz, closest, param);
    } catch (...) {
      continue;
    }
    if (closest.size() != xyz.size()) continue;
    for (std::size_t k = k0; k < k1; ++k) {
      const double px = closest[3 * (k - k0)], py = closest[3 * (k - k0) + 1];
      const auto& sg = c.segs[k];
      const double len = std::hypot(g.x[sg[1]] - g.x[sg[0]], g.y[sg[1]] - g.y[sg[0]]);
      if (std::isfinite(px) && std::isfinite(py) &&
          std::hypot(px - c.mid[k][0], py - c.mid[k][1]) <= 0.25 * len)
        c.mid[k] = {px, py};
    }
  }
}

// load_geometry() and, with mesh false, load_geometry_groups().
Geometry load(const std::string& file, double size,
              const std::vector<std::pair<std::string, double>>& parameters, double max_cells,
              bool mesh) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(file, ec)) throw GeometryError(file + ": cannot open file (it does not exist)");
  if (fs::is_directory(file, ec)) throw GeometryError(file + ": cannot open file (it is a directory)");
  if (const std::string e = gmsh_input_problem(file); !e.empty()) throw GeometryError(file + ": " + e);
  {
    std::ifstream f(file, std::ios::binary);
    if (!f) throw GeometryError(file + ": cannot open file (not readable)");
    std::ostringstream ss;
    ss << f.rdbuf();
    const std::string text = ss.str();
    if (text.find_first_not_of(" \t\r\n") == std::string::npos)
      throw GeometryError(file + ": the file is empty");
  }
  const std::string ext = lower_ext(file);
  const bool geo = ext == ".geo";
  if (!geo && ext != ".msh")
    throw GeometryError(file + ": unsupported file type \"" + ext +
                        "\" (give a gmsh .geo or .msh file)");

  // The numbers (h and the parameters) go in through a wrapper .geo (gmsh_session.hpp).
  if (!geo && !parameters.empty())
    throw GeometryError(file + ": parameters are only used by a .geo file");
  std::unique_ptr<GeoParameters> wrapper;
  try {
    wrapper = std::make_unique<GeoParameters>(file, geo ? size : 0.0, parameters);
  } catch (const std::runtime_error& e) {
    throw GeometryError(e.what());
  }
  const std::string opened = wrapper->path();
  GmshSession session;

  gmsh_call(session, file, geo ? "read the geometry" : "read the mesh",
            [&] { gmsh::open(opened); });
  if (geo && mesh) {
    if (size > 0) gmsh::option::setNumber("Mesh.MeshSizeMax", size);
    if (const std::string e = gmsh_mesh_size_problem(size, max_cells); !e.empty())
      throw GeometryError(file + ": " + e);
    gmsh_call(session, file, "mesh the geometry", [&] { gmsh::model::mesh::generate(2); });
  }

  Geometry g;
  g.file = file;
  gmsh::vectorpair groups;
  gmsh_call(session, file, "list the physical groups",
            [&] { gmsh::model::getPhysicalGroups(groups); });
  bool any = false;
  for (const auto& dt : groups) any = any || dt.first == 1 || dt.first == 2;
  if (!any)
    throw GeometryError(file + ": defines no physical surface or physical curve (name the bodies "
                               "and boundaries with Physical Surface / Physical Curve)");
  if (!mesh) {  // the groups' tags and names only
    for (const auto& [dim, tag] : groups) {
      std::string name;
      gmsh::model::getPhysicalName(dim, tag, name);
      if (dim == 2) g.surfaces.push_back({tag, name, {}});
      if (dim == 1) g.curves.push_back({tag, name, {}, {}});
    }
    auto by_tag = [](const auto& a, const auto& b) { return a.tag < b.tag; };
    std::sort(g.surfaces.begin(), g.surfaces.end(), by_tag);
    std::sort(g.curves.begin(), g.curves.end(), by_tag);
    return g;
  }

  // Nodes.
  std::vector<std::size_t> node_tags;
  std::vector<double> coord, pcoord;
  gmsh_call(session, file, "read the nodes",
            [&] { gmsh::model::mesh::getNodes(node_tags, coord, pcoord); });
  std::unordered_map<std::size_t, int> index;
  index.reserve(node_tags.size());
  double scale = 0;
  for (std::size_t k = 0; k < node_tags.size(); ++k)
    scale = std::max({scale, std::fabs(coord[3 * k]), std::fabs(coord[3 * k + 1])});
  for (std::size_t k = 0; k < node_tags.size(); ++k) {
    if (std::fabs(coord[3 * k + 2]) > 1e-9 * std::max(scale, 1e-300))
      throw GeometryError(file + ": node " + std::to_string(node_tags[k]) + " has z = " +
                          fmt17(coord[3 * k + 2]) + "; a 2D geometry must lie in the plane z = 0");
    index[node_tags[k]] = static_cast<int>(g.x.size());
    g.x.push_back(coord[3 * k]);
    g.y.push_back(coord[3 * k + 1]);
  }
  auto node = [&](std::size_t tag, const std::string& where) {
    auto it = index.find(tag);
    if (it == index.end())
      throw GeometryError(file + ": " + where + ": element refers to unknown node " +
                          std::to_string(tag));
    return it->second;
  };

  // Surfaces first, so an error names the body's surface before its curves.
  std::stable_sort(groups.begin(), groups.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  for (const auto& group : groups) {
    const int dim = group.first, tag = group.second;  // named copies: lambdas below capture dim
    if (dim != 1 && dim != 2) continue;
    std::string name;
    gmsh::model::getPhysicalName(dim, tag, name);
    const std::string where = Geometry::label(dim == 2 ? "physical surface" : "physical curve", tag, name);
    std::vector<int> entities;
    gmsh::model::getEntitiesForPhysicalGroup(dim, tag, entities);
    Geometry::Surface surf;
    Geometry::Curve curve;
    std::vector<std::pair<int, std::size_t>> curve_entities;  // (entity, first segment)
    for (int ent : entities) {
      if (dim == 1) curve_entities.push_back({ent, curve.segs.size()});
      std::vector<int> types;
      std::vector<std::vector<std::size_t>> etags, ntags;
      gmsh_call(session, file, "read the elements", [&] {
        gmsh::model::mesh::getElements(types, etags, ntags, dim, ent);
      });
      for (std::size_t t = 0; t < types.size(); ++t) {
        const int type = types[t];
        const bool ok = dim == 2 ? (type == 2 || type == 3) : type == 1;
        if (!ok) {
          const int order = element_order(type);
          throw GeometryError(
              file + ": " + where + ": " +
              (order >= 2 ? "second-order element " : "unsupported element ") + element_name(type) +
              "; only first-order " +
              (dim == 2 ? "triangles and quadrangles" : "2-node lines") +
              " are supported (remove Mesh.ElementOrder / high-order settings)");
        }
        const std::vector<std::size_t>& nt = ntags[t];
        if (dim == 2) {
          const int nn = type == 2 ? 3 : 4;
          for (std::size_t e = 0; e + nn <= nt.size(); e += nn) {
            std::array<int, 4> el = {-1, -1, -1, -1};
            for (int k = 0; k < nn; ++k) el[k] = node(nt[e + k], where);
            surf.elems.push_back(el);
          }
        } else {
          for (std::size_t e = 0; e + 2 <= nt.size(); e += 2)
            curve.segs.push_back({node(nt[e], where), node(nt[e + 1], where)});
        }
      }
    }
    if (dim == 2) {
      if (surf.elems.empty())
        throw GeometryError(file + ": " + where + " has no elements" +
                            (geo ? " (is the surface meshed?)" : ""));
      surf.tag = tag;
      surf.name = name;
      g.surfaces.push_back(std::move(surf));
    } else {
      if (curve.segs.empty())
        throw GeometryError(file + ": " + where + " has no line elements" +
                            (geo ? " (is the curve part of a meshed surface?)" : ""));
      curve.tag = tag;
      curve.name = name;
      curve_mids(g, curve, geo ? curve_entities : std::vector<std::pair<int, std::size_t>>{});
      g.curves.push_back(std::move(curve));
    }
  }
  auto by_tag = [](const auto& a, const auto& b) { return a.tag < b.tag; };
  std::sort(g.surfaces.begin(), g.surfaces.end(), by_tag);
  std::sort(g.curves.begin(), g.curves.end(), by_tag);
  return g;
}

}  // namespace

Geometry load_geometry(const std::string& file, double size,
                       const std::vector<std::pair<std::string, double>>& parameters,
                       double max_cells) {
  return load(file, size, parameters, max_cells, true);
}

Geometry load_geometry_groups(const std::string& file, double size,
                              const std::vector<std::pair<std::string, double>>& parameters) {
  return load(file, size, parameters, 0, false);
}

}  // namespace smpm

extern "C" const smpm::GmshModule* silentmpm_gmsh_module() {
  static const smpm::GmshModule table{smpm::kGmshModuleApi, &smpm::load_geometry,
                                      &smpm::load_geometry_groups};
  return &table;
}
