#pragma once
// Case files: JSON, SI units. load_case() reads, applies command-line overrides, validates every
// key and builds a ready-to-run Solver. Any problem throws CaseError whose message names the
// file and the key path (e.g. "pulse.json: materials.tungsten.poisson: must be < 0.5, got 0.5").
// The full key reference with defaults is docs/case-reference.md.
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "silentmpm/fem.hpp"
#include "silentmpm/hybrid.hpp"
#include "silentmpm/solver.hpp"

namespace smpm {

// The message is made one readable line: control characters (a newline in a key) are escaped,
// a word of more than 200 characters is cut to its first 80, and a message of more than 2 000
// characters to its first 1 500 and last 300, each cut saying how much it left out.
struct CaseError : std::runtime_error {
  explicit CaseError(const std::string& what);
};

// Probe quantities: "sxx", "syy", "szz", "sxy", "J2", "vx", "vy".
struct ProbeSpec {
  std::string name;
  double x = 0, y = 0;
  std::vector<std::string> fields;
  int body = -1;  // sample only this body's particles (-1: all bodies)
  int fem_index = -1;  // hybrid case: index of the FEM probe (the point is in the FEM region), -1: particles
  // A point of a probe along a curve ("curve" key; name = "<along>_<k>"): the curve probe's
  // name, its physical curve (e.g. `14 "top"`) and the point's arc length from the first point.
  std::string along;   // empty for a point probe
  std::string curve;
  double s = 0;
  // A region probe ("region": [x0, y0, x1, y1]): the mean over the particles in the box
  // (Solver::region_mean); x, y are then its centre.
  bool region = false;
  double rx0 = 0, ry0 = 0, rx1 = 0, ry1 = 0;
};

// One body as built (summary.json "bodies"): name, material, extent [x0, y0, x1, y1] (its box,
// or its gmsh surface's bounding box) and the surface (e.g. `1 "plate"`; empty for a box).
struct BodyInfo {
  std::string name, material, surface;
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

struct OutputSpec {
  long history_every = 1;   // steps between history rows
  int snapshots = 10;       // number of particle snapshots over the run (0: none)
  bool progress = true;     // print a progress line on long runs
  // Checkpoints (DIR/checkpoint.smpm, overwritten each time): every checkpoint_every steps, or
  // each time the clock passes a multiple of checkpoint_time seconds (0: none).
  long checkpoint_every = 0;
  double checkpoint_time = 0;
  unsigned fields = ~0u;    // particle snapshot fields (SnapshotField bits of output.hpp)
  int compression = 0;      // deflate level of the snapshot datasets, 0 (none) to 9
  bool grid = false;        // also the MPM grid's nodal snapshots (grid.h5 + grid.xdmf)
};

struct Case {
  std::string source;       // file name (for messages)
  std::string title;
  double t_end = 0;
  std::vector<ProbeSpec> probes;
  std::vector<BodyInfo> bodies;  // MPM bodies, in the order of "bodies"
  OutputSpec output;
  std::unique_ptr<Solver> solver;  // seeded, boundary conditions added, finalize() called
  // FEM region (a case with "fem"): mesh read, boundaries added, dt set; probes added in the
  // order of `probes`. Null for an MPM-only case; solver is null for an FEM-only case.
  // Shared pointers: the far field lives in a module the process loads only for such a case
  // (cases/src/modules.hpp), and a shared pointer destroys it with the deleter of the code that
  // made it, so that the rest of the program never names the module's destructors.
  std::shared_ptr<fem::Solver> fem;
  // Both an MPM and an FEM region (cases/fe/case_hybrid.cpp): the coupled step over solver and fem.
  std::shared_ptr<Hybrid> hybrid;
  std::vector<std::string> notes;  // human-readable description of the loads (time functions...)
  // Several MPI ranks (load_case_on_ranks): rank 0 built the whole case and every other rank its
  // skeleton; the split sends each rank its block's particles from rank 0.
  bool scattered = false;
  // Hash of the validated document without the keys a restart may change (checkpoints carry it).
  std::uint64_t fingerprint = 0;
};

// Read a case file. overrides are "key.path=value" strings (value parsed as JSON, or taken as a
// string if it is not valid JSON) applied before validation; array elements by index
// ("bodies.0.particles_per_cell=4").
Case load_case(const std::string& path, const std::vector<std::string>& overrides = {});
// Under an MPI launcher with several ranks (collective): rank 0 builds the whole case, the others
// build it without particles (an MPM case without multi-field contact; any other case is built
// whole on every rank), and the split sends each rank its block (docs/parallel.md "Set-up"), so
// that only rank 0 holds every particle at start-up. Rank 0's verdict on the case is every
// rank's: its error, when it has one, is thrown on every rank. On one process: load_case.
Case load_case_on_ranks(const std::string& path, const std::vector<std::string>& overrides = {});
// Same from the text of a case file; `source` names it in messages, and relative paths in it
// are taken from source's folder (the working directory when source has none).
Case load_case_text(const std::string& text, const std::string& source,
                    const std::vector<std::string>& overrides = {});

// Pre-flight limits of the loader, process-wide. memory_bytes: the most an MPM grid with its
// particles may need (0: 80 % of the machine's physical memory); mesh_cells: the most cells a
// gmsh geometry or FE mesh may be meshed into. The fuzz harness lowers both.
struct LoadLimits {
  double memory_bytes = 0;
  double mesh_cells = 1e7;
};
void set_load_limits(const LoadLimits& limits);
const LoadLimits& load_limits();

// " (did you mean \"check\"?)" when one of the candidates is close to word, else "" (the
// suggestion every case error gives, for the command line's use too).
std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates);
// Same from an already parsed document; `source` names it in messages.
Case build_case(const nlohmann::json& doc, const std::string& source);

// The FE region's line of `silentmpm check` ("FEM: <cells> cells, Q<k>, ..."): a case with an
// FEM region and no MPM bodies.
std::string fem_check_line(const Case& c);

}  // namespace smpm
