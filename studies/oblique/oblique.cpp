// oblique: plane P and SV pulses on the FEM LK dashpot boundary at several angles, measured by
// extended-domain differencing (see oblique.hpp), written as OUT/metrics.json and the receiver
// traces OUT/trace_<P|SV>_<angle>.csv.
//
//   oblique OUTDIR [--method fem|mpm] [--angles "0 15 30 45 60"] [--fwhm 24] [--flat 200] [--taper 60] [--degree 1] [--threads N] [--shape bilinear|gimp|bspline]
//           [--boundary lk|kv|damping|pml|delayed] [--delta CELLS] [--band CELLS] [--r0 R] [--alpha 1/S] [--power N] [--parallel P]
//           [--beta F] (damping: the band's stiffness part, F h / c_d seconds)
//           (the right side of run A)
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <sstream>

#include "oblique.hpp"
#include "oblique_mpm.hpp"

using namespace smpm;

int main(int argc, char** argv) {
  if (argc < 2 || std::string(argv[1]) == "--help") {
    std::fprintf(stderr, "usage: oblique OUTDIR [--angles \"0 15 30 45 60\"] [--fwhm 16] "
                         "[--degree 1] [--threads N] [--shape bilinear|gimp|bspline] [--ppc 1|4|9] [--scheme usl|musl|usf] "
                         "[--boundary lk|kv|damping|pml|delayed] [--delta CELLS] [--band CELLS] [--r0 R] [--alpha 1/S] [--power N] [--parallel P] [--beta F] [--receiver CELLS]\n");
    return argc < 2 ? 1 : 0;
  }
  const std::string out = argv[1];
  std::vector<double> angles = {0, 15, 30, 45, 60};
  oblique::Setup base;
  std::string method = "fem";
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--angles") {
      angles.clear();
      std::istringstream in(argv[i + 1]);
      for (double x; in >> x;) angles.push_back(x);
    } else if (a == "--method") {
      method = argv[i + 1];
      if (method != "fem" && method != "mpm") {
        std::fprintf(stderr, "oblique: --method must be fem or mpm\n");
        return 1;
      }
    } else if (a == "--fwhm") {
      base.fwhm = std::atoi(argv[i + 1]);
    } else if (a == "--degree") {
      base.degree = std::atoi(argv[i + 1]);
    } else if (a == "--flat") {
      base.flat = std::atoi(argv[i + 1]);
    } else if (a == "--taper") {
      base.taper = std::atoi(argv[i + 1]);
    } else if (a == "--threads") {
      base.threads = std::atoi(argv[i + 1]);
    } else if (a == "--boundary") {
      base.boundary = argv[i + 1];
      if (base.boundary != "lk" && base.boundary != "kv" && base.boundary != "damping" &&
          base.boundary != "pml" && base.boundary != "delayed") {
        std::fprintf(stderr, "oblique: --boundary must be lk, kv, damping, pml or delayed\n");
        return 1;
      }
    } else if (a == "--delta") {
      base.delta = std::atof(argv[i + 1]);
    } else if (a == "--band") {
      base.band = std::atof(argv[i + 1]);
    } else if (a == "--receiver") {
      base.receiver = std::atof(argv[i + 1]);
    } else if (a == "--r0") {
      base.r0 = std::atof(argv[i + 1]);
    } else if (a == "--alpha") {
      base.alpha = std::atof(argv[i + 1]);
    } else if (a == "--power") {
      base.power = std::atof(argv[i + 1]);
    } else if (a == "--parallel") {
      base.parallel = std::atof(argv[i + 1]);
    } else if (a == "--beta") {
      base.beta = std::atof(argv[i + 1]);
    } else if (a == "--ppc") {
      base.ppc = std::atoi(argv[i + 1]);
      if (base.ppc != 1 && base.ppc != 4 && base.ppc != 9) {
        std::fprintf(stderr, "oblique: --ppc must be 1, 4 or 9\n");
        return 1;
      }
    } else if (a == "--scheme") {
      base.scheme = argv[i + 1];
      if (base.scheme != "usl" && base.scheme != "musl" && base.scheme != "usf") {
        std::fprintf(stderr, "oblique: --scheme must be usl, musl or usf\n");
        return 1;
      }
    } else if (a == "--shape") {
      const std::string v = argv[i + 1];
      if (v == "bilinear") base.shape = ShapeKind::Bilinear;
      else if (v == "gimp") base.shape = ShapeKind::UGimp;
      else if (v == "bspline") base.shape = ShapeKind::BSpline2;
      else {
        std::fprintf(stderr, "oblique: --shape must be bilinear, gimp or bspline\n");
        return 1;
      }
    } else {
      std::fprintf(stderr, "oblique: unknown option %s\n", a.c_str());
      return 1;
    }
  }
  if (!(base.receiver > 0 && base.receiver < 150)) {  // run A is 160 cells wide
    std::fprintf(stderr, "oblique: --receiver must be between 0 and 150 cells from the boundary\n");
    return 1;
  }
  if (method == "mpm" && base.boundary == "pml" && (base.scheme == "musl" || base.scheme == "usf") &&
      base.ppc == 1) {
    const double cd = oblique::Plane(base).mat.cd;
    const double need = pml_one_ppc_alpha(cd, base.r0, base.power, base.band * base.h, base.h);
    if (base.band < kPmlOnePpcCells || !(base.alpha >= need)) {
      std::fprintf(stderr, "oblique: --boundary pml under --scheme %s at --ppc 1 needs --band >= %d "
                           "and --alpha >= %.6g (slow backward waves of the scheme grow in the "
                           "layer), or --ppc 4 or 9\n", base.scheme.c_str(), kPmlOnePpcCells, need);
      return 1;
    }
  }
  if (method == "fem" && (base.ppc != 1 || !base.scheme.empty())) {
    std::fprintf(stderr, "oblique: --ppc and --scheme are the particles': --method mpm only\n");
    return 1;
  }
  if (method == "fem" && base.boundary == "delayed") {
    std::fprintf(stderr, "oblique: --boundary delayed is the particles' closure: --method mpm only\n");
    return 1;
  }
  try {
    std::filesystem::create_directories(out);
    nlohmann::ordered_json j;
    j["method"] = method == "fem"
                      ? "FEM (deal.II) Q" + std::to_string(base.degree) +
                            ", lumped mass, semi-implicit LK dashpots a = b = 1; extended-domain "
                            "differencing"
                      : "MPM, " + std::to_string(base.ppc) + " particle" +
                            (base.ppc == 1 ? "" : "s") + " per cell, " +
                            (base.scheme == "usl" || (base.scheme.empty() && base.boundary == "pml")
                                 ? "USL"
                                 : base.scheme == "usf" ? "USF" : "MUSL") +
                            ", nodal semi-implicit silent layer a = b = 1, CFL 0.3; extended-domain "
                            "differencing (div u, curl u: the sampled velocity's div and curl "
                            "integrated over the steps)";
    if (method == "mpm") j["shape"] = shape_name(base.shape);
    j["boundary"] = base.boundary;
    if (base.boundary == "kv") j["kv_delta_cells"] = base.delta;
    if (base.boundary == "damping") {
      j["damping_band_cells"] = base.band;
      j["damping_r0"] = base.r0;
      j["damping_power"] = base.power;
      j["damping_beta_h_over_cd"] = base.beta;
    }
    if (base.boundary == "pml") {
      j["pml_cells"] = base.band;
      j["pml_r0"] = base.r0;
      j["pml_alpha"] = base.alpha;
      j["pml_power"] = base.power;
      j["pml_parallel"] = base.parallel;
    }
    j["nu"] = base.nu;
    j["pulse_fwhm_cells"] = base.fwhm;
    j["results"] = nlohmann::ordered_json::array();
    for (bool sv : {false, true})
      for (double ang : angles) {
        oblique::Setup s = base;
        s.sv = sv;
        s.angle_deg = ang;
        const oblique::Result r = method == "fem" ? oblique::measure(s) : oblique::measure_mpm(s);
        const char* w = sv ? "SV" : "P";
        std::printf("%-2s %4.0f deg: %s %.5f (exact %.5f)  %s %.5f (exact %.5f)%s  [%.1f s]\n", w, ang,
                    sv ? "|R_SS|" : "|R_PP|", r.r_same, r.exact_same, sv ? "|R_SP|" : "|R_PS|",
                    r.r_conv, r.exact_conv, r.evanescent ? " (evanescent P)" : "", r.seconds);
        std::fflush(stdout);
        j["results"].push_back({{"wave", w},
                                {"angle_deg", ang},
                                {sv ? "R_SS" : "R_PP", r.r_same},
                                {sv ? "R_SS_exact" : "R_PP_exact", r.exact_same},
                                {sv ? "R_SP" : "R_PS", r.r_conv},
                                {sv ? "R_SP_exact" : "R_PS_exact", r.exact_conv},
                                {"reflected_p_evanescent", r.evanescent},
                                {"dt", r.dt},
                                {"t_end", r.t_end},
                                {"dofs", {r.dofs_a, r.dofs_b}},
                                {"seconds", r.seconds}});
        std::ofstream tr(out + "/trace_" + (method == "fem" ? "" : "mpm_") + w + "_" +
                         std::to_string(static_cast<int>(ang)) + ".csv");
        tr << "time,incident,reflected_div,reflected_curl\n" << std::setprecision(9);
        for (std::size_t k = 0; k < r.t.size(); ++k)
          tr << r.t[k] << "," << r.inc[k] << "," << r.ddiv[k] << "," << r.dcurl[k] << "\n";
      }
    std::ofstream(out + "/metrics" + (method == "fem" ? "" : "_mpm") + ".json") << std::setw(2) << j << "\n";
  } catch (const std::exception& e) {
    std::fprintf(stderr, "oblique: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
