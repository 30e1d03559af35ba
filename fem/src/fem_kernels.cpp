// Time stepping of the FEM far-field: plain arrays, OpenMP, no deal.II (compiled with -O3).
#include <omp.h>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <type_traits>

#include "fem_impl.hpp"
#include "silentmpm/dashpot.hpp"

namespace smpm::fem {

namespace {
// Loops over fewer items than this run on one thread: below it the fork/join of a parallel region
// costs more than it saves (and far more on an oversubscribed machine).
constexpr std::int64_t kParallelMinimum = 40000;
// The least bytes a step's pass over the rows moves for its stores to be timed both ways (see
// Solver::step): a pass that the cache may hold keeps plain stores.
constexpr double kStreamTrialBytes = 32e6;

std::string fmt(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.6g", v);
  return b;
}
}  // namespace

double symmetric_max_eigenvalue(std::vector<double>& a, int n) {
  for (int sweep = 0; sweep < 100; ++sweep) {
    double off = 0, diag = 0;
    for (int p = 0; p < n; ++p) {
      diag += a[p * n + p] * a[p * n + p];
      for (int q = p + 1; q < n; ++q) off += a[p * n + q] * a[p * n + q];
    }
    if (off <= 1e-30 * diag) break;
    for (int p = 0; p < n; ++p)
      for (int q = p + 1; q < n; ++q) {
        const double apq = a[p * n + q];
        if (std::fabs(apq) <= 1e-300) continue;
        const double theta = (a[q * n + q] - a[p * n + p]) / (2 * apq);
        const double tt = (theta >= 0 ? 1.0 : -1.0) / (std::fabs(theta) + std::sqrt(theta * theta + 1));
        const double c = 1 / std::sqrt(tt * tt + 1), s = tt * c;
        for (int k = 0; k < n; ++k) {  // columns p, q
          const double akp = a[k * n + p], akq = a[k * n + q];
          a[k * n + p] = c * akp - s * akq;
          a[k * n + q] = s * akp + c * akq;
        }
        for (int k = 0; k < n; ++k) {  // rows p, q
          const double apk = a[p * n + k], aqk = a[q * n + k];
          a[p * n + k] = c * apk - s * aqk;
          a[q * n + k] = s * apk + c * aqk;
        }
      }
  }
  double m = a[0];
  for (int p = 1; p < n; ++p) m = std::max(m, a[p * n + p]);
  return m;
}

std::size_t Solver::nodes() const {
  return impl_->glob.empty() ? impl_->x.size() : impl_->mesh_nodes;
}
std::size_t Solver::matrix_blocks() const { return impl_->col.size(); }
std::size_t Solver::stored_blocks() const { return impl_->val.size() / 4; }
bool Solver::rows_shared() const { return !impl_->row_val.empty(); }
int Solver::store_mode() const { return impl_->stream_mode; }
std::size_t Solver::row_groups() const {
  return static_cast<std::size_t>(std::count(impl_->row4.begin(), impl_->row4.end(), 1));
}
std::size_t Solver::pml_cells() const {
  return impl_->part ? impl_->part->pml_cells.size() : impl_->pml.cell.size();
}
std::size_t Solver::pml_tensor_cells() const {
  const Impl::Pml& P = impl_->pml;
  if (!P.tensor_found) return 0;
  const Impl::Part* part = impl_->part.get();
  std::size_t k = 0;
  for (std::size_t cc = 0; cc < pml_cells(); ++cc)
    k += P.tensor_ok[P.shape[part ? part->pml_cells[cc] : cc]];
  return k;
}
std::size_t Solver::cells() const { return impl_->n_cells; }
int Solver::degree() const { return impl_->degree; }
int Solver::thread_count() const { return impl_->threads; }
std::array<double, 4> Solver::bounds() const { return impl_->box; }
std::vector<std::uint32_t> Solver::explicit_force_nodes() const {
  const Impl& m = *impl_;
  std::vector<std::uint32_t> out(m.pml.touched.begin(), m.pml.touched.end());
  out.insert(out.end(), m.visc.node.begin(), m.visc.node.end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::array<double, 2> Solver::gravity() const {
  return {{impl_->spec.gravity_x, impl_->spec.gravity_y}};
}
double Solver::critical_dt() const { return impl_->crit_dt; }
int Solver::snapshot_count() const { return impl_->snapshots; }
std::vector<double> Solver::snapshot_times() const { return impl_->snapshot_times; }
const std::vector<double>& Solver::node_x() const { return impl_->x; }
const std::vector<double>& Solver::node_y() const { return impl_->y; }
const std::vector<double>& Solver::mass() const { return impl_->mass; }
std::vector<double>& Solver::displacement() {
  impl_->ku_valid = false;
  return impl_->u;
}
std::vector<double>& Solver::velocity() { return impl_->v; }
const std::vector<Solver::DashpotBlock>& Solver::dashpots() const { return impl_->dash; }
const std::vector<std::uint8_t>& Solver::constraint_mask() const { return impl_->mask; }
const std::vector<std::uint32_t>& Solver::cell_nodes() const { return impl_->cell_nodes; }

std::vector<std::uint32_t> Solver::boundary_nodes(const std::vector<int>& curves) const {
  std::vector<std::uint32_t> out;
  for (int c : curves) {
    auto it = impl_->curve_nodes.find(c);
    if (it != impl_->curve_nodes.end()) out.insert(out.end(), it->second.begin(), it->second.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

namespace {
using V2 = double __attribute__((vector_size(16)));  // two doubles, one SIMD register
using V4 = double __attribute__((vector_size(32)));  // four nodes' x (or y)
using V8 = double __attribute__((vector_size(64)));  // four nodes' (x, y)

#ifdef __AVX512DQ__
// (p[0], p[1]) in each of four lanes' pairs, by one load (the masked form: GCC's unmasked
// intrinsic reads an undefined register and warns).
inline V8 bcast2(const double* p) {
  return reinterpret_cast<V8>(_mm512_mask_broadcast_f64x2(_mm512_setzero_pd(), 0xff, _mm_loadu_pd(p)));
}
#endif

// (p[0], p[0], p[1], p[1], p[2], p[2], p[3], p[3]): four nodes' value for their (x, y) lanes.
inline V8 dup4(const double* p) {
  V4 x;
  std::memcpy(&x, p, sizeof x);
  return __builtin_shufflevector(x, x, 0, 0, 1, 1, 2, 2, 3, 3);
}

// The stiffness's rows (Impl's node-block CSR), read one at a time.
struct Rows {
  const std::uint64_t* __restrict rp;
  const std::uint32_t* __restrict cl;
  const double* __restrict kv;
  const std::uint32_t* __restrict rv;
  explicit Rows(const Solver::Impl& m)
      : rp(m.rowptr.data()), cl(m.col.data()), kv(m.val.data()), rv(m.row_val.data()) {}
  // (K u)_i as the pair (x, y); SHARED: rows share values (Impl::row_val).
  template <bool SHARED>
  inline V2 times(std::int64_t i, const double* __restrict u) const {
    const double* __restrict row = kv + 4 * (SHARED ? std::uint64_t{rv[i]} : rp[i]);
    // (fx, fy) += (Kxx, Kyx) u_x + (Kxy, Kyy) u_y: each lane the scalar sum
    // f += K_0 u_x + K_1 u_y, with the same multiply-adds, two at a time.
    V2 acc = {0.0, 0.0};
    for (std::uint64_t k = rp[i]; k < rp[i + 1]; ++k) {
      const double ux = u[2 * cl[k]], uy = u[2 * cl[k] + 1];
      const double* b = row + 4 * (k - rp[i]);
      V2 c0, c1;
      std::memcpy(&c0, b, sizeof c0);
      std::memcpy(&c1, b + 2, sizeof c1);
      acc += c0 * ux + c1 * uy;
    }
    return acc;
  }
  // Rows i .. i+3 of a group Impl::row4 marks (shared values): the four rows' (x, y) in one
  // register, each lane the sums of times() (a block's u of the four rows is one run of u).
  inline V8 times4(std::int64_t i, const double* __restrict u) const {
    const double* __restrict row = kv + 4 * std::uint64_t{rv[i]};
    const std::uint32_t* __restrict c = cl + rp[i];
    const std::uint64_t n = rp[i + 1] - rp[i];
    V8 acc = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (std::uint64_t k = 0; k < n; ++k) {
      V8 w;
      std::memcpy(&w, u + 2 * std::uint64_t{c[k]}, sizeof w);
      const V8 ux = __builtin_shufflevector(w, w, 0, 0, 2, 2, 4, 4, 6, 6);
      const V8 uy = __builtin_shufflevector(w, w, 1, 1, 3, 3, 5, 5, 7, 7);
      // The block's two columns, each repeated in the four rows' lanes (one load each).
#ifdef __AVX512DQ__
      const V8 c0 = bcast2(row + 4 * k);
      const V8 c1 = bcast2(row + 4 * k + 2);
#else
      const double* b = row + 4 * k;
      const V8 c0 = {b[0], b[1], b[0], b[1], b[0], b[1], b[0], b[1]};
      const V8 c1 = {b[2], b[3], b[2], b[3], b[2], b[3], b[2], b[3]};
#endif
      acc += c0 * ux + c1 * uy;
    }
    return acc;
  }
};

// f = -K u on the rows list[0 .. n) (LIST), or on rows 0 .. n; SHARED: rows share values.
template <bool LIST, bool SHARED>
void minus_ku(const Solver::Impl& m, const std::uint32_t* list, std::int64_t n,
              const double* __restrict u, double* __restrict f) {
  const Rows K(m);
#pragma omp parallel for schedule(static) num_threads(m.threads) if (n >= kParallelMinimum)
  for (std::int64_t r = 0; r < n; ++r) {
    const std::int64_t i = LIST ? list[r] : r;
    const V2 acc = K.times<SHARED>(i, u);
    f[2 * i] = -acc[0];
    f[2 * i + 1] = -acc[1];
  }
}
}  // namespace

void Solver::internal_force(const double* __restrict u, double* __restrict f) const {
  const Impl& m = *impl_;
  const bool shared = !m.row_val.empty();
  if (m.part) {  // several ranks: this rank's own rows
    const auto n = static_cast<std::int64_t>(m.part->own.size());
    if (shared) minus_ku<true, true>(m, m.part->own.data(), n, u, f);
    else minus_ku<true, false>(m, m.part->own.data(), n, u, f);
  } else {
    const auto n = static_cast<std::int64_t>(m.x.size());
    if (shared) minus_ku<false, true>(m, nullptr, n, u, f);
    else minus_ku<false, false>(m, nullptr, n, u, f);
  }
}

namespace {
// f += f_ext(time) over the loaded nodes only.
void add_loads(const Solver::Impl& m, double time, double* f) {
  for (const auto& l : m.loads) {
    const double s = l.fn(time);
    if (s == 0) continue;
    for (std::size_t k = 0; k < l.nodes.size(); ++k) {
      f[2 * l.nodes[k]] += s * l.f[2 * k];
      f[2 * l.nodes[k] + 1] += s * l.f[2 * k + 1];
    }
  }
}
}  // namespace

void Solver::refresh_external_force(double time, double* f) const {
  for (const auto& l : impl_->loads)
    for (const auto nd : l.nodes) f[2 * nd] = f[2 * nd + 1] = 0.0;
  add_loads(*impl_, time, f);
}

void Solver::set_dt(double h) {
  Impl& m = *impl_;
  if (!(h > 0) || !std::isfinite(h)) throw FemError("FEM: time step must be > 0, got " + fmt(h));
  if (h > m.crit_dt * (1 + 1e-12))
    throw FemError("FEM: time step " + fmt(h) + " s is above the stability limit " +
                   fmt(m.crit_dt) + " s (element bound, CFL " + fmt(h / m.crit_dt) + " > 1)");
  dt = h;
}

namespace {
// The explicit forces of the perfectly matched layers at u^n into m.dash_force (docs/physics.md
// section 9.3), advancing their memory variables to t_n. Per quadrature point of a layer cell:
// the x-derivative part of the stiffness carries s_y / s_x = 1 + (d_y - d_x) / (i omega +
// alpha + d_x), the y-derivative part s_x / s_y; the convolutions of du/dx with exp(-(alpha +
// d_x) t) and of du/dy with exp(-(alpha + d_y) t) are the memories. Per layer node the mass
// term m (s_x s_y)(i omega)^2 u less its damping part m (d_x + d_y) v (in the dashpot block):
// -m [(d_x + d_y)(-alpha u + alpha^2 I1) + d_x d_y (u - 2 alpha I1 + alpha^2 I2)], with I1 the
// convolution of u and I2 that of I1 with exp(-alpha t).
// One layer cell's forces at u into f (through the dashpot blocks), advancing its points'
// memories; NB, NQ its nodes and quadrature points (0: P.nb and P.nq at run time).
template <int NB, int NQ>
inline void pml_cell(Solver::Impl::Pml& P, std::int64_t c, const double* __restrict u,
                     const std::int32_t* __restrict dn, double* __restrict f) {
  const int nb = NB ? NB : P.nb, nq = NQ ? NQ : P.nq;
  const std::uint32_t* cn = P.cell_nodes.data() + c * nb;
  const double* gs = P.grad.data() + static_cast<std::size_t>(P.shape[c]) * nq * nb * 2;
  // The x and y components as pairs (one SIMD register), each lane the scalar multiply-adds.
  V2 U[9], F[9];
  for (int a = 0; a < nb; ++a) {
    std::memcpy(&U[a], u + 2 * cn[a], sizeof(V2));
    F[a] = V2{0.0, 0.0};
  }
  for (int q = 0; q < nq; ++q) {
    const std::size_t k = c * nq + q;
    const double* g = gs + 2 * q * nb;
    V2 Gx = {0.0, 0.0}, Gy = {0.0, 0.0};  // (du_x/dx, du_y/dx), (du_x/dy, du_y/dy)
    for (int a = 0; a < nb; ++a) {
      Gx += g[2 * a] * U[a];
      Gy += g[2 * a + 1] * U[a];
    }
    double* xi = P.xi.data() + 4 * k;
    const double* t = P.packed.data() + 8 * P.kind[k];  // kl, km, cx, cy
    const double kl = t[0], km = t[1], *cx = t + 2, *cy = t + 5;
    V2 Xx, Xy;  // the memories of the x and of the y derivatives
    std::memcpy(&Xx, xi, sizeof(V2));
    std::memcpy(&Xy, xi + 2, sizeof(V2));
    const V2 Px = Xx + cx[2] * Gx, Py = Xy + cy[2] * Gy;
    Xx = cx[0] * Px + cx[1] * Gx;
    Xy = cy[0] * Py + cy[1] * Gy;
    std::memcpy(xi, &Xx, sizeof(V2));
    std::memcpy(xi + 2, &Xy, sizeof(V2));
    // The x part carries d_y - d_x, the y part d_x - d_y.
    const V2 Sx = V2{kl, km} * Px, Sy = V2{-km, -kl} * Py;
    for (int a = 0; a < nb; ++a) F[a] -= Sx * g[2 * a] + Sy * g[2 * a + 1];
  }
  for (int a = 0; a < nb; ++a) {
    f[2 * dn[cn[a]]] += F[a][0];
    f[2 * dn[cn[a]] + 1] += F[a][1];
  }
}

// Whether a Q1 shape table (4 points x 4 nodes x (d/dx, d/dy); the nodes and the points in
// lexicographic order, x first) is that of an axis-aligned rectangle. Then, at point (i, j),
//   du/dx = bx_j (u_1 - u_0) + tx_j (u_3 - u_2),   du/dy = ly_i (u_2 - u_0) + ry_i (u_3 - u_1)
// (bx_j = (1 - eta_j) / a, tx_j = eta_j / a, ly_i = (1 - xi_i) / b, ry_i = xi_i / b), and w gets
// bx_0, tx_0, bx_1, tx_1, ly_0, ry_0, ly_1, ry_1. Every entry is checked against that form, to
// 1e-12 of the table's largest.
bool pml_tensor_weights(const double* g, double* w) {
  auto G = [g](int q, int a, int d) { return g[2 * (4 * q + a) + d]; };
  for (int j = 0; j < 2; ++j) {
    w[2 * j] = -G(2 * j, 0, 0);
    w[2 * j + 1] = G(2 * j, 3, 0);
  }
  for (int i = 0; i < 2; ++i) {
    w[4 + 2 * i] = -G(i, 0, 1);
    w[5 + 2 * i] = G(i, 3, 1);
  }
  double big = 0;
  for (int k = 0; k < 32; ++k) big = std::max(big, std::abs(g[k]));
  if (!(big > 0)) return false;
  for (int q = 0; q < 4; ++q)
    for (int a = 0; a < 4; ++a) {
      const int i = q & 1, j = q >> 1, ia = a & 1, ja = a >> 1;
      const double ex = (ia ? 1 : -1) * (ja ? w[2 * j + 1] : w[2 * j]);
      const double ey = (ja ? 1 : -1) * (ia ? w[5 + 2 * i] : w[4 + 2 * i]);
      if (!(std::abs(G(q, a, 0) - ex) <= 1e-12 * big && std::abs(G(q, a, 1) - ey) <= 1e-12 * big))
        return false;
    }
  return true;
}

// pml_cell<4, 4> for an axis-aligned Q1 cell (pml_tensor_weights): the same terms, the points'
// derivatives blended from the four edge differences, and the forces gathered the same way
// (each point's x part, summed over the points of a row, goes to the row's edge difference;
// each y part, summed over a column, to the column's).
// (Inlined into the cells' loop: GCC kept it a call per cell, 6.6-7.0 free cells per layer cell
// against 6.2-6.5 inlined, the same bits.)
__attribute__((always_inline)) inline void pml_cell_tensor(Solver::Impl::Pml& P, std::int64_t c,
                                                           const double* __restrict u,
                                                           const std::int32_t* __restrict dn,
                                                           double* __restrict f) {
  const std::uint32_t* cn = P.cell_nodes.data() + c * 4;
  const double* w = P.tensor_w.data() + 8 * static_cast<std::size_t>(P.shape[c]);
  V2 U[4];
  for (int a = 0; a < 4; ++a) std::memcpy(&U[a], u + 2 * cn[a], sizeof(V2));
  const V2 Db = U[1] - U[0], Dt = U[3] - U[2], Dl = U[2] - U[0], Dr = U[3] - U[1];
  const V2 Gx[2] = {w[0] * Db + w[1] * Dt, w[2] * Db + w[3] * Dt};  // per row j
  const V2 Gy[2] = {w[4] * Dl + w[5] * Dr, w[6] * Dl + w[7] * Dr};  // per column i
  V2 Tx[2] = {{0.0, 0.0}, {0.0, 0.0}}, Ty[2] = {{0.0, 0.0}, {0.0, 0.0}};
  double* __restrict xis = P.xi.data() + 16 * c;
  const std::uint32_t* __restrict kind = P.kind.data() + 4 * c;
  const double* __restrict packed = P.packed.data();
  for (int q = 0; q < 4; ++q) {
    const int i = q & 1, j = q >> 1;
    double* xi = xis + 4 * q;
    const double* t = packed + 8 * kind[q];  // kl, km, cx, cy
    const double kl = t[0], km = t[1], *cx = t + 2, *cy = t + 5;
    V2 Xx, Xy;
    std::memcpy(&Xx, xi, sizeof(V2));
    std::memcpy(&Xy, xi + 2, sizeof(V2));
    const V2 Px = Xx + cx[2] * Gx[j], Py = Xy + cy[2] * Gy[i];
    Xx = cx[0] * Px + cx[1] * Gx[j];
    Xy = cy[0] * Py + cy[1] * Gy[i];
    std::memcpy(xi, &Xx, sizeof(V2));
    std::memcpy(xi + 2, &Xy, sizeof(V2));
    Tx[j] += V2{kl, km} * Px;
    Ty[i] += V2{-km, -kl} * Py;
  }
  const V2 Eb = w[0] * Tx[0] + w[2] * Tx[1], Et = w[1] * Tx[0] + w[3] * Tx[1];
  const V2 El = w[4] * Ty[0] + w[6] * Ty[1], Er = w[5] * Ty[0] + w[7] * Ty[1];
  const V2 F[4] = {Eb + El, Er - Eb, Et - El, -(Et + Er)};
  for (int a = 0; a < 4; ++a) {
    f[2 * dn[cn[a]]] += F[a][0];
    f[2 * dn[cn[a]] + 1] += F[a][1];
  }
}

template <int NB, int NQ>
void pml_cells(Solver::Impl& m) {
  Solver::Impl::Pml& P = m.pml;
  double* __restrict f = m.dash_force.data();
  const std::int32_t* __restrict dn = m.dash_of_node.data();
  const double* __restrict u = m.u.data();
  // Several ranks: the layer cells around this rank's nodes (Part::pml_cells), by colour.
  const Solver::Impl::Part* part = m.part.get();
  const std::vector<std::uint32_t>& starts = part ? part->pml_colour_start : P.colour_start;
  for (std::size_t colour = 0; colour + 1 < starts.size(); ++colour) {
    const std::int64_t c0 = starts[colour], c1 = starts[colour + 1];
#pragma omp parallel for schedule(static) num_threads(m.threads) if (c1 - c0 >= 256)
    for (std::int64_t cc = c0; cc < c1; ++cc) {
      const std::int64_t c = part ? part->pml_cells[cc] : cc;
      if (NB == 4 && NQ == 4 && P.tensor_ok[P.shape[c]]) pml_cell_tensor(P, c, u, dn, f);
      else pml_cell<NB, NQ>(P, c, u, dn, f);
    }
  }
}

void pml_forces(Solver::Impl& m, double dt) {
  Solver::Impl::Pml& P = m.pml;
  if (P.dt_coef != dt) {
    std::vector<double> cx, cy;  // (e, ca, cb) per kind of point for alpha + d_x, alpha + d_y
    convolution_tables(P.alpha, P.dx, P.dy, dt, cx, cy, P.e_a, P.ca_a, P.cb_a);
    P.packed.resize(8 * P.kl.size());
    for (std::size_t j = 0; j < P.kl.size(); ++j) {
      double* t = P.packed.data() + 8 * j;
      t[0] = P.kl[j];
      t[1] = P.km[j];
      for (int i = 0; i < 3; ++i) {
        t[2 + i] = cx[3 * j + i];
        t[5 + i] = cy[3 * j + i];
      }
    }
    P.dt_coef = dt;
  }
  if (!P.tensor_found) {  // which shapes take the tensor-product form
    const std::size_t shapes = P.nb > 0 && P.nq > 0 ? P.grad.size() / (2 * P.nb * P.nq) : 0;
    P.tensor_ok.assign(shapes, 0);
    P.tensor_w.assign(8 * shapes, 0.0);
    if (m.spec.pml_tensor && P.nb == 4 && P.nq == 4)
      for (std::size_t k = 0; k < shapes; ++k)
        P.tensor_ok[k] = pml_tensor_weights(P.grad.data() + 32 * k, P.tensor_w.data() + 8 * k);
    P.tensor_found = true;
  }
  double* __restrict f = m.dash_force.data();
  const std::int32_t* __restrict dn = m.dash_of_node.data();
  const double* __restrict u = m.u.data();
  for (const std::uint32_t nd : P.touched) f[2 * dn[nd]] = f[2 * dn[nd] + 1] = 0.0;
  if (P.nb == 4 && P.nq == 4) pml_cells<4, 4>(m);
  else if (P.nb == 9 && P.nq == 9) pml_cells<9, 9>(m);
  else pml_cells<0, 0>(m);
  const Solver::Impl::Part* part = m.part.get();
  // Each node its own block: in parallel, the same values (the layer's constants and arrays
  // taken out of P first, which the stores could otherwise alias).
  const auto nodes = static_cast<std::int64_t>(part ? part->pml_nodes.size() : P.node.size());
  const std::uint32_t* __restrict list = part ? part->pml_nodes.data() : nullptr;
  const std::uint32_t* __restrict node = P.node.data();
  const double* __restrict m_sum = P.m_sum.data();
  const double* __restrict m_prod = P.m_prod.data();
  double* __restrict zeta = P.zeta.data();
  const double alpha = P.alpha, e_a = P.e_a, ca_a = P.ca_a, cb_a = P.cb_a;
#pragma omp parallel for schedule(static) num_threads(m.threads) if (nodes >= 256)
  for (std::int64_t jj = 0; jj < nodes; ++jj) {
    const std::size_t j = list ? list[jj] : static_cast<std::size_t>(jj);
    const std::uint32_t i = node[j];
    for (int c = 0; c < 2; ++c)  // zeta: 2 memories per component
      f[2 * dn[i] + c] += pml_mass_term(m_sum[j], m_prod[j], alpha, u[2 * i + c],
                                        zeta + 4 * j + 2 * c, e_a, ca_a, cb_a);
  }
}

// Stores a node group's 64 bytes; with `streaming`, without reading their cache lines first (the
// stores of the next group complete a line the group's last store began).
inline void stream(double* a, V8 x, bool streaming) {
#ifdef __SSE2__
  if (streaming && (reinterpret_cast<std::uintptr_t>(a) & 15) == 0) {
    for (int k = 0; k < 4; ++k) _mm_stream_pd(a + 2 * k, __m128d{x[2 * k], x[2 * k + 1]});
    return;
  }
#endif
  std::memcpy(a, &x, sizeof x);
}

// One node's explicit update: v+ = v + dt f / m, the trapezoidal solve at a node with a dashpot
// block (dashpot.hpp), constraints; then u_out = u_in + dt v+ (u_out may be u_in). Adds the
// work of f_ext (with the mid-step velocity) and the energy the dashpots absorb.
struct NodeUpdate {
  const std::uint8_t* __restrict mask;
  const std::int32_t* __restrict dn;
  const double* __restrict im;
  const double* __restrict ms;
  const Solver::DashpotBlock* __restrict D;
  const double* __restrict pf;  // a PML's or a damping layer's explicit forces per block (else 0)
  double* __restrict v;
  double dt, gx, gy;
  bool gravity;
  NodeUpdate(Solver::Impl& m, double dt)
      : mask(m.mask.data()), dn(m.dash_of_node.data()), im(m.inv_mass.data()),
        ms(m.mass.data()), D(m.dash.data()), pf(m.dash_force.data()), v(m.v.data()), dt(dt),
        gx(m.spec.gravity_x), gy(m.spec.gravity_y), gravity(gx != 0 || gy != 0) {}
  // f_int_x, f_int_y: node i's internal force; f_ext: 2 per node.
  inline void operator()(std::int64_t i, double f_int_x, double f_int_y,
                         const double* __restrict f_ext, const double* u_in, double* u_out,
                         double& work, double& absorbed) const {
    double fx = f_int_x + f_ext[2 * i], fy = f_int_y + f_ext[2 * i + 1];
    if (gravity) {  // the lumped body force m_i g
      fx += ms[i] * gx;
      fy += ms[i] * gy;
    }
    const double vx0 = v[2 * i], vy0 = v[2 * i + 1];
    double vx, vy;
    if (dn[i] < 0) {
      vx = (mask[i] & 1) ? 0.0 : vx0 + dt * fx * im[i];
      vy = (mask[i] & 2) ? 0.0 : vy0 + dt * fy * im[i];
    } else {
      const Solver::DashpotBlock& c = D[dn[i]];
      const double px = pf[2 * dn[i]], py = pf[2 * dn[i] + 1];
      dashpot_velocity(ms[i], c.cxx, c.cxy, c.cyy, vx0, vy0, fx + px, fy + py, dt, mask[i], vx, vy);
      const double bx = 0.5 * (vx0 + vx), by = 0.5 * (vy0 + vy);
      absorbed += dt * (bx * (c.cxx * bx + c.cxy * by) + by * (c.cxy * bx + c.cyy * by) -
                        px * bx - py * by);
    }
    book(i, f_ext, vx0, vy0, vx, vy, work);
    v[2 * i] = vx;
    v[2 * i + 1] = vy;
    u_out[2 * i] = u_in[2 * i] + dt * vx;
    u_out[2 * i + 1] = u_in[2 * i + 1] + dt * vy;
  }
  // The work of node i's loads and gravity over the step, the velocity going from v0 to v.
  inline void book(std::int64_t i, const double* __restrict f_ext, double vx0, double vy0,
                   double vx, double vy, double& work) const {
    work += dt * (f_ext[2 * i] * 0.5 * (vx0 + vx) + f_ext[2 * i + 1] * 0.5 * (vy0 + vy));
    if (gravity) work += dt * ms[i] * (gx * 0.5 * (vx0 + vx) + gy * 0.5 * (vy0 + vy));
  }
  // Whether nodes i .. i+3 are free, without a dashpot block and unloaded (fe their f_ext):
  // then their lanes of four() are their whole update and their work terms are zeros, whose
  // sum changes no total (for finite velocities; a non-finite velocity stops the run anyway).
  inline bool plain(std::int64_t i, V8 fe) const {
    std::uint32_t m4;
    std::memcpy(&m4, mask + i, sizeof m4);
#ifdef __AVX512F__
    const bool any = _mm512_cmpneq_pd_mask(reinterpret_cast<__m512d>(fe), _mm512_setzero_pd()) != 0;
#else
    using L8 = long long __attribute__((vector_size(64)));
    const L8 nz = fe != V8{};
    const bool any = ((nz[0] | nz[1]) | (nz[2] | nz[3]) | (nz[4] | nz[5]) | (nz[6] | nz[7])) != 0;
#endif
    return m4 == 0 && (dn[i] & dn[i + 1] & dn[i + 2] & dn[i + 3]) < 0 && !any;
  }
  // Whether nodes i .. i+3 are free and unloaded (plain, dashpot blocks or not).
  inline bool quiet(std::int64_t i, V8 fe) const {
    std::uint32_t m4;
    std::memcpy(&m4, mask + i, sizeof m4);
    for (int k = 0; k < 8; ++k)
      if (fe[k] != 0) return false;
    return m4 == 0;
  }
  // Gravity's work over the step on four nodes, each lane book()'s term, booked in the nodes'
  // order (v0: their start velocities, vn: their new ones).
  inline void gravity_work(std::int64_t i, const V8& v0, const V8& vn, double& work) const {
    V4 mi;
    std::memcpy(&mi, ms + i, sizeof mi);
    const V4 vx0 = __builtin_shufflevector(v0, v0, 0, 2, 4, 6);
    const V4 vy0 = __builtin_shufflevector(v0, v0, 1, 3, 5, 7);
    const V4 vx = __builtin_shufflevector(vn, vn, 0, 2, 4, 6);
    const V4 vy = __builtin_shufflevector(vn, vn, 1, 3, 5, 7);
    const V4 dm = dt * mi;
    const V4 G = gx * 0.5 * (vx0 + vx) + gy * 0.5 * (vy0 + vy);
    double w = work;
    w += dm[0] * G[0];
    w += dm[1] * G[1];
    w += dm[2] * G[2];
    w += dm[3] * G[3];
    work = w;
  }
  // Quiet nodes i .. i+3 of which some hold a dashpot block (a damping band's or a PML's
  // nodes, an edge's): those take operator()'s trapezoidal update four at a time, each lane
  // dashpot_velocity's arithmetic for a free node (the same bits), and their absorbed energy
  // is booked in the nodes' order; the others keep their lanes (f: four()'s, f_int + fe and
  // gravity; v0 and ui the group's, vn and un four()'s).
  inline void dashpots(std::int64_t i, const V8& f, const V8& v0, const V8& ui, V8& vn, V8& un,
                       double& absorbed) const {
    V4 cxx = {0, 0, 0, 0}, cxy = cxx, cyy = cxx, px = cxx, py = cxx;
    bool block[4];
    const std::int32_t d0 = dn[i];
    const bool all = d0 >= 0 && dn[i + 3] == d0 + 3;  // (blocks in the nodes' order)
    if (all) {  // four blocks in a row: their values by columns
      static_assert(sizeof(Solver::DashpotBlock) == 32, "a block: node, cxx, cxy, cyy");
      V8 b01, b23, p;
      std::memcpy(&b01, D + d0, sizeof b01);
      std::memcpy(&b23, D + d0 + 2, sizeof b23);
      std::memcpy(&p, pf + 2 * d0, sizeof p);
      cxx = __builtin_shufflevector(b01, b23, 1, 5, 9, 13);
      cxy = __builtin_shufflevector(b01, b23, 2, 6, 10, 14);
      cyy = __builtin_shufflevector(b01, b23, 3, 7, 11, 15);
      px = __builtin_shufflevector(p, p, 0, 2, 4, 6);
      py = __builtin_shufflevector(p, p, 1, 3, 5, 7);
      block[0] = block[1] = block[2] = block[3] = true;
    } else {
      for (int j = 0; j < 4; ++j) {
        const std::int32_t d = dn[i + j];
        block[j] = d >= 0;
        if (!block[j]) continue;
        cxx[j] = D[d].cxx;
        cxy[j] = D[d].cxy;
        cyy[j] = D[d].cyy;
        px[j] = pf[2 * d];
        py[j] = pf[2 * d + 1];
      }
    }
    V4 mi;
    std::memcpy(&mi, ms + i, sizeof mi);
    const V4 vx0 = __builtin_shufflevector(v0, v0, 0, 2, 4, 6);
    const V4 vy0 = __builtin_shufflevector(v0, v0, 1, 3, 5, 7);
    const V4 fx = __builtin_shufflevector(f, f, 0, 2, 4, 6) + px;
    const V4 fy = __builtin_shufflevector(f, f, 1, 3, 5, 7) + py;
    V4 vx, vy;
    dashpot_velocity_free(mi, cxx, cxy, cyy, vx0, vy0, fx, fy, dt, vx, vy);
    const V4 bx = 0.5 * (vx0 + vx), by = 0.5 * (vy0 + vy);
    const V4 e = bx * (cxx * bx + cxy * by) + by * (cxy * bx + cyy * by) - px * bx - py * by;
    double a = absorbed;  // (in a register)
    if (all) {
      vn = __builtin_shufflevector(vx, vy, 0, 4, 1, 5, 2, 6, 3, 7);
      a += dt * e[0];
      a += dt * e[1];
      a += dt * e[2];
      a += dt * e[3];
    } else {
      for (int j = 0; j < 4; ++j) {
        if (!block[j]) continue;
        vn[2 * j] = vx[j];
        vn[2 * j + 1] = vy[j];
        a += dt * e[j];
      }
    }
    absorbed = a;
    un = ui + dt * vn;
  }
  // four()'s nodes where they are not all plain (or gravity acts): quiet ones four at a time
  // (dashpots() where blocks are among them, then gravity's work), else one by one: the work of
  // each free node without a dashpot, operator() for the others (vn and un then take what it
  // wrote). Apart, so that the plain groups keep their registers (and their code: the step's
  // loop is the same with it).
  [[gnu::noinline]] void mixed(std::int64_t i, const V8& f_int, const double* __restrict f_ext,
                               const double* u_in, double* u_out, double& work, double& absorbed,
                               const V8& v0, V8& vn, V8& un) const {
    V8 fe;
    std::memcpy(&fe, f_ext + 2 * i, sizeof fe);
    if (quiet(i, fe)) {  // (their f_ext's work terms are zeros)
      if (std::max(std::max(dn[i], dn[i + 1]), std::max(dn[i + 2], dn[i + 3])) >= 0) {
        V8 f = f_int + fe;  // four()'s
        if (gravity) {
          const V8 g = {gx, gy, gx, gy, gx, gy, gx, gy};
          f += dup4(ms + i) * g;
        }
        V8 ui;
        std::memcpy(&ui, u_in + 2 * i, sizeof ui);
        dashpots(i, f, v0, ui, vn, un, absorbed);
      }
      if (gravity) gravity_work(i, v0, vn, work);
      return;
    }
    for (int j = 0; j < 4; ++j) {
      const std::int64_t k = i + j;
      if (mask[k] == 0 && dn[k] < 0) {
        book(k, f_ext, v0[2 * j], v0[2 * j + 1], vn[2 * j], vn[2 * j + 1], work);
        continue;
      }
      (*this)(k, f_int[2 * j], f_int[2 * j + 1], f_ext, u_in, u_out, work, absorbed);
      vn[2 * j] = v[2 * k];
      vn[2 * j + 1] = v[2 * k + 1];
      un[2 * j] = u_out[2 * k];
      un[2 * j + 1] = u_out[2 * k + 1];
    }
  }
  // operator() on nodes i .. i+3 (f_int their internal forces, u_out not u_in): their (x, y)
  // in one register, each lane the single node's arithmetic for a free node without a dashpot;
  // a node with either takes operator() itself, in its place among the four (the work and the
  // absorbed energy booked in the nodes' order), and its lanes then hold what it wrote.
  // G: gravity acts (the step's loop made for each; a plain group then books its work here).
  template <bool G>
  inline void four(std::int64_t i, V8 f_int, const double* __restrict f_ext, const double* u_in,
                   double* u_out, double& work, double& absorbed, bool streaming) const {
    V8 fe, v0, ui;
    std::memcpy(&fe, f_ext + 2 * i, sizeof fe);
    std::memcpy(&v0, v + 2 * i, sizeof v0);
    std::memcpy(&ui, u_in + 2 * i, sizeof ui);
    V8 f = f_int + fe;
    if (G) {
      const V8 g = {gx, gy, gx, gy, gx, gy, gx, gy};
      f += dup4(ms + i) * g;
    }
    const V8 w = dup4(im + i);
    V8 vn = v0 + dt * f * w;
    V8 un = ui + dt * vn;
    if (!plain(i, fe)) {  // copies: the plain path's values stay in registers
      V8 fi = f_int, v_old = v0, v_new = vn, u_new = un;
      mixed(i, fi, f_ext, u_in, u_out, work, absorbed, v_old, v_new, u_new);
      vn = v_new;
      un = u_new;
    } else if (G) {
      gravity_work(i, v0, vn, work);
    }
    std::memcpy(v + 2 * i, &vn, sizeof vn);
    stream(u_out + 2 * i, un, streaming);
  }
};

// The explicit update (NodeUpdate) of every node with skip == nullptr or skip[i] < 0, from the
// forces f_int and f_ext. Several ranks: this rank's own nodes only (Part::own).
template <bool LIST>
void advance_nodes_on(Solver::Impl& m, const std::uint32_t* list, std::int64_t n,
                      const std::int64_t* skip, const double* __restrict f_int,
                      const double* __restrict f_ext, double dt, bool parallel, double& work_out,
                      double& absorbed_out) {
  const NodeUpdate node(m, dt);
  double* u = m.u.data();
  double work = 0, absorbed = 0;
#pragma omp parallel for schedule(static) reduction(+ : work, absorbed) num_threads(m.threads) \
    if (parallel)
  for (std::int64_t r = 0; r < n; ++r) {
    const std::int64_t i = LIST ? list[r] : r;
    if (skip && skip[i] >= 0) continue;
    node(i, f_int[2 * i], f_int[2 * i + 1], f_ext, u, u, work, absorbed);
  }
  work_out += work;
  absorbed_out += absorbed;
  m.ku_valid = false;
}

// The whole step's nodal pass in one: per row -K u^n (kept in m.ku for the energies) and the
// node's update (NodeUpdate) into the other displacement buffer, which then becomes m.u; u^n is
// read from the buffer that no row writes, so the rows' order does not matter. The same sums
// and products as minus_ku and then advance_nodes_on, so the same bits; the nodal pass then
// moves neither -K u nor u a second time. Several ranks: this rank's own rows.
template <bool LIST, bool SHARED, bool GRAVITY>
void fused_step_on(Solver::Impl& m, const std::uint32_t* list, std::int64_t n,
                   const double* __restrict f_ext, double dt, bool parallel, double& work_out,
                   double& absorbed_out, bool streaming) {
  const Rows K(m);
  const NodeUpdate node(m, dt);
  if (m.u_next.size() != m.u.size()) m.u_next.assign(m.u.size(), 0.0);
  const double* __restrict u = m.u.data();
  double* __restrict un = m.u_next.data();
  double* __restrict f = m.ku.data();
  double work = 0, absorbed = 0;
  const std::uint8_t* row4 = !LIST && SHARED && !m.row4.empty() ? m.row4.data() : nullptr;
  if (!row4) {  // row by row
#pragma omp parallel for schedule(static) reduction(+ : work, absorbed) num_threads(m.threads) \
    if (parallel)
    for (std::int64_t r = 0; r < n; ++r) {
      const std::int64_t i = LIST ? list[r] : r;
      const V2 acc = K.times<SHARED>(i, u);
      f[2 * i] = -acc[0];
      f[2 * i + 1] = -acc[1];
      node(i, -acc[0], -acc[1], f_ext, u, un, work, absorbed);
    }
  } else {
    // Each thread the rows a static schedule would give it, in order (the same sums of work and
    // absorbed energy per thread).
#pragma omp parallel reduction(+ : work, absorbed) num_threads(m.threads) if (parallel)
    {
      const std::int64_t nt = omp_get_num_threads(), t = omp_get_thread_num();
      const std::int64_t q = n / nt, rest = n % nt;
      const std::int64_t r0 = t * q + std::min(t, rest), r1 = r0 + q + (t < rest ? 1 : 0);
      auto one = [&](std::int64_t i, V2 acc) {
        f[2 * i] = -acc[0];
        f[2 * i + 1] = -acc[1];
        node(i, -acc[0], -acc[1], f_ext, u, un, work, absorbed);
      };
      // Rows one at a time; where Impl::row4 marks a group of four (4g .. 4g+3), the group at
      // once, its arrays fetched kAhead rows ahead (the many streams of the pass leave the
      // hardware's prefetchers behind).
      constexpr std::int64_t kAhead = 32;
      for (std::int64_t r = r0; r < r1;) {
        if (r % 4 == 0 && r + 4 <= r1 && row4[r / 4]) {
          if (r + kAhead < r1) {
            const std::int64_t a = r + kAhead;
            // u^n where the group's furthest column (the mesh row above) will be: the pass reaches
            // new lines of u there first (its own row's and the row below's it read before).
            const std::uint64_t far = std::uint64_t{K.cl[K.rp[r + 1] - 1]} + kAhead;
            __builtin_prefetch(u + 2 * std::min(far, static_cast<std::uint64_t>(n - 1)));
            __builtin_prefetch(un + 2 * a, 1);
            __builtin_prefetch(f + 2 * a, 1);
            __builtin_prefetch(node.v + 2 * a, 1);
            __builtin_prefetch(f_ext + 2 * a);
            __builtin_prefetch(K.cl + K.rp[a]);
            __builtin_prefetch(K.cl + std::min(K.rp[a] + 16, K.rp[n]));
            if (a % 8 == 0) {
              __builtin_prefetch(node.im + a);
              __builtin_prefetch(node.ms + a);
              __builtin_prefetch(node.dn + a);
            }
          }
          const V8 fi = -K.times4(r, u);
          stream(f + 2 * r, fi, streaming);
          node.template four<GRAVITY>(r, fi, f_ext, u, un, work, absorbed, streaming);
          r += 4;
          continue;
        }
        one(r, K.times<SHARED>(r, u));
        ++r;
      }
#ifdef __SSE2__
      if (streaming) _mm_sfence();  // this thread's streamed stores before anything reads them
#endif
    }
  }
  m.u.swap(m.u_next);
  work_out += work;
  absorbed_out += absorbed;
  m.ku_valid = false;
}

// The damping layers' stiffness-proportional forces, -sqrt(beta_i) (K w)_i with w = sqrt(beta) v
// (the velocity of the last step), added to the listed nodes' explicit forces; several ranks:
// the rows of this rank's listed nodes (w reads its ghosts, which hold current v).
void viscous_forces(Solver::Impl& m) {
  Solver::Impl::Viscous& V = m.visc;
  const double* __restrict v = m.v.data();
  double* __restrict w = V.w.data();
  for (std::size_t r = 0; r < V.node.size(); ++r) {
    const std::uint32_t i = V.node[r];
    w[2 * i] = V.root_beta[r] * v[2 * i];
    w[2 * i + 1] = V.root_beta[r] * v[2 * i + 1];
  }
  const auto n = static_cast<std::int64_t>(V.row_node.size());
  if (m.row_val.empty()) minus_ku<true, false>(m, V.row_node.data(), n, w, V.kw.data());
  else minus_ku<true, true>(m, V.row_node.data(), n, w, V.kw.data());
  double* __restrict f = m.dash_force.data();
  const std::int32_t* __restrict dn = m.dash_of_node.data();
  for (std::size_t q = 0; q < V.rows.size(); ++q) {
    const std::uint32_t r = V.rows[q], i = V.node[r];
    f[2 * dn[i]] += V.root_beta[r] * V.kw[2 * i];
    f[2 * dn[i] + 1] += V.root_beta[r] * V.kw[2 * i + 1];
  }
}

// The explicit forces of the layers (into m.dash_force) from u^n and v^{n-1/2}, before the nodes
// move.
void explicit_forces(Solver::Impl& m, double dt) {
  if (m.visc.active())  // these nodes' explicit forces start from zero (the PML's zeroes its own)
    for (const std::uint32_t i : m.visc.node)
      m.dash_force[2 * m.dash_of_node[i]] = m.dash_force[2 * m.dash_of_node[i] + 1] = 0.0;
  if (m.pml.active()) pml_forces(m, dt);
  if (m.visc.active()) viscous_forces(m);
}

void advance_nodes(Solver::Impl& m, const std::int64_t* skip, const double* f_int,
                   const double* f_ext, double dt, bool parallel, double& work_out,
                   double& absorbed_out) {
  explicit_forces(m, dt);
  if (m.part)
    advance_nodes_on<true>(m, m.part->own.data(), static_cast<std::int64_t>(m.part->own.size()),
                           skip, f_int, f_ext, dt, parallel, work_out, absorbed_out);
  else
    advance_nodes_on<false>(m, nullptr, static_cast<std::int64_t>(m.mass.size()), skip, f_int,
                            f_ext, dt, parallel, work_out, absorbed_out);
}
}  // namespace

void Solver::step() {
  Impl& m = *impl_;
  if (!(dt > 0) || dt > m.crit_dt * (1 + 1e-12)) set_dt(dt);  // throws with the reason
  // f_ext is zero away from the loaded nodes (fext is zero-initialised and only these entries
  // are ever written): refresh just those, not the whole vector (a serial pass over every dof
  // would cap the two-thread speed-up).
  refresh_external_force(t, m.fext.data());
  explicit_forces(m, dt);
  // One pass over the rows: -K u^n into m.ku (update_energies reads it) and the nodes' update.
  // Several ranks: each steps and books its own nodes (update_energies adds them up), and then
  // receives the nodes it reads from their owners.
  const bool shared = !m.row_val.empty();
  const std::uint32_t* own = m.part ? m.part->own.data() : nullptr;
  const auto rows = static_cast<std::int64_t>(m.part ? m.part->own.size() : m.x.size());
  const bool parallel = rows >= kParallelMinimum;
  double& work = m.part ? m.part->work : energy.external_work;
  double& absorbed = m.part ? m.part->absorbed : energy.absorbed;
  // Streaming stores or plain ones: the first twelve steps of a large pass (by the bench's count
  // of its bytes, about 156 a node) take each way three steps at a time, twice, and keep
  // streaming where its fastest step is 2 % faster than the plain stores' (the first of each
  // three, which follows the other way's, not counted).
  if (m.stream_mode < 0 && (m.row4.empty() || 156.0 * rows < kStreamTrialBytes)) m.stream_mode = 0;
  const bool streaming = m.stream_mode == 1 || (m.stream_mode < 0 && (m.stream_trial / 3) % 2 == 1);
  const double start = m.stream_mode < 0 ? omp_get_wtime() : 0.0;
  const double* fe = m.fext.data();
  // (Gravity: the groups' loop made for it, the other one left as it is without.)
  const auto fused = [&](auto gravity) {
    constexpr bool G = decltype(gravity)::value;
    if (own && shared) fused_step_on<true, true, G>(m, own, rows, fe, dt, parallel, work, absorbed, streaming);
    else if (own) fused_step_on<true, false, G>(m, own, rows, fe, dt, parallel, work, absorbed, streaming);
    else if (shared) fused_step_on<false, true, G>(m, nullptr, rows, fe, dt, parallel, work, absorbed, streaming);
    else fused_step_on<false, false, G>(m, nullptr, rows, fe, dt, parallel, work, absorbed, streaming);
  };
  if (m.spec.gravity_x != 0 || m.spec.gravity_y != 0) fused(std::true_type{});
  else fused(std::false_type{});
  if (m.stream_mode < 0) {
    const int k = m.stream_trial;
    if (k % 3 != 0) m.stream_time[(k / 3) % 2][2 * (k / 6) + k % 3 - 1] = omp_get_wtime() - start;
    if (++m.stream_trial == 12) {
      const double plain = *std::min_element(m.stream_time[0], m.stream_time[0] + 4);
      const double streamed = *std::min_element(m.stream_time[1], m.stream_time[1] + 4);
      m.stream_mode = streamed < 0.98 * plain ? 1 : 0;
    }
  }
  if (m.part) exchange_ghosts(m);
  t += dt;
  ++steps;
  // ku now holds -K u^n (u^n = the displacement before this step), used by update_energies().
}

void Solver::advance_free_nodes(const std::int64_t* skip, const double* f_int, const double* f_ext,
                                double dt, double& work_out, double& absorbed_out) {
  advance_nodes(*impl_, skip, f_int, f_ext, dt, true, work_out, absorbed_out);
  if (impl_->part) exchange_ghosts(*impl_);
}

void Solver::update_energies() {
  Impl& m = *impl_;
  const std::int64_t n = static_cast<std::int64_t>(m.part ? m.part->own.size() : m.x.size());
  double kin = 0, el = 0;
  // Elastic: 1/2 u^n K u^{n+1}; ku holds -K u^n from the last step (or -K u if never stepped).
  if (steps == 0 && !m.ku_valid) {
    internal_force(m.u.data(), m.ku.data());
    m.ku_valid = true;
  }
  const std::uint32_t* own = m.part ? m.part->own.data() : nullptr;
#pragma omp parallel for schedule(static) reduction(+ : kin, el) num_threads(m.threads) if (n >= kParallelMinimum)
  for (std::int64_t r = 0; r < n; ++r) {
    const std::int64_t i = own ? own[r] : r;
    kin += 0.5 * m.mass[i] * (m.v[2 * i] * m.v[2 * i] + m.v[2 * i + 1] * m.v[2 * i + 1]);
    el -= 0.5 * (m.ku[2 * i] * m.u[2 * i] + m.ku[2 * i + 1] * m.u[2 * i + 1]);
  }
  energy.kinetic = kin;
  energy.elastic = el;
  if (m.part) {  // several ranks: the sums of their own nodes' shares
    double e[4] = {kin, el, m.part->work, m.part->absorbed};
    sum_over_ranks(m, e, 4);
    energy.kinetic = e[0];
    energy.elastic = e[1];
    energy.external_work = e[2];
    energy.absorbed = e[3];
  }
}

std::vector<Sample> Solver::sample() const {
  const Impl& m = *impl_;
  std::vector<Sample> out(m.probes.size());
  for (std::size_t p = 0; p < m.probes.size(); ++p) {
    Sample s;
    const double w = m.probes[p].w;
    for (const auto& pr : m.probes[p].parts) {
      // Several ranks: each part is read by the rank of its cell (which holds its nodes; a
      // local model keeps only those).
      if (m.part && m.glob.empty() &&
          m.part->cell_rank[pr.cell] != static_cast<std::uint32_t>(m.part->rank))
        continue;
      double g[2][2] = {{0, 0}, {0, 0}}, vel[2] = {0, 0};
      for (std::size_t k = 0; k < pr.dofs.size(); ++k) {
        const int c = pr.comp[k];
        const double uu = m.u[pr.dofs[k]];
        g[c][0] += uu * pr.dx[k];
        g[c][1] += uu * pr.dy[k];
        vel[c] += m.v[pr.dofs[k]] * pr.N[k];
      }
      const double exx = g[0][0], eyy = g[1][1], gxy = g[0][1] + g[1][0];
      const double tr = exx + eyy;
      s.sxx += w * (pr.lambda * tr + 2 * pr.mu * exx);
      s.syy += w * (pr.lambda * tr + 2 * pr.mu * eyy);
      s.szz += w * pr.lambda * tr;
      s.sxy += w * pr.mu * gxy;
      s.vx += w * vel[0];
      s.vy += w * vel[1];
      s.div += w * tr;
      s.curl += w * (g[1][0] - g[0][1]);
    }
    s.j2 = j2_of(s.sxx, s.syy, s.szz, s.sxy);
    out[p] = s;
  }
  if (m.part && !out.empty()) {  // several ranks: each probe's parts added up over them
    std::vector<double> b;
    for (const Sample& s : out) b.insert(b.end(), {s.sxx, s.syy, s.szz, s.sxy, s.vx, s.vy, s.div, s.curl});
    sum_over_ranks(m, b.data(), static_cast<int>(b.size()));
    for (std::size_t p = 0; p < out.size(); ++p) {
      const double* v = b.data() + 8 * p;
      out[p] = Sample{v[0], v[1], v[2], v[3], 0.0, v[4], v[5], v[6], v[7]};
      out[p].j2 = j2_of(v[0], v[1], v[2], v[3]);
    }
  }
  return out;
}



// Checkpoints: displacement, velocity, -K u^n (the step and the elastic energy reuse it), the
// clock, the energies and the snapshot times (fem.xdmf is rebuilt from them on restart).
// Several ranks (every rank calls it; the ranks write the file at once): the booked energies
// summed, and each rank's own nodes and its part's layer cells as its parts of the blocks,
// with their numbers (blocks `nodes`, `pml_cells`, `pml_nodes`), which load_state reads into a
// model built whole.
namespace {
// The items (nodes, layer cells ...) whose owner is `me`, ascending.
std::vector<std::uint32_t> owned(const std::vector<std::uint32_t>& owner, std::uint32_t me) {
  std::vector<std::uint32_t> out;
  for (std::size_t i = 0; i < owner.size(); ++i)
    if (owner[i] == me) out.push_back(static_cast<std::uint32_t>(i));
  return out;
}
// `width` values per item of `v` for the items `which`, in that order.
std::vector<double> values_of(const std::vector<double>& v, const std::vector<std::uint32_t>& which,
                              std::size_t width) {
  std::vector<double> out;
  out.reserve(width * which.size());
  for (const auto i : which) out.insert(out.end(), v.begin() + width * i, v.begin() + width * (i + 1));
  return out;
}
}  // namespace

void get_items(const StateReader& r, const std::string& name, const std::string& numbers,
               std::size_t items, std::size_t width, std::vector<double>& v) {
  if (!r.has(numbers)) {
    r.get(name, v, width * items);
    return;
  }
  std::vector<std::uint32_t> at;
  r.get(numbers, at, items);
  std::vector<double> parts;
  r.get(name, parts, width * items);
  std::vector<std::uint8_t> seen(items, 0);
  v.assign(width * items, 0.0);
  for (std::size_t q = 0; q < items; ++q) {
    if (at[q] >= items || seen[at[q]]++)
      r.fail("block '" + numbers + "' does not name every item once (corrupt checkpoint)");
    std::copy_n(parts.begin() + width * q, width, v.begin() + width * at[q]);
  }
}

void Solver::put_nodes(StateWriter& w, const std::string& name,
                       const std::vector<double>& per_node) const {
  const Impl& m = *impl_;
  if (!m.part) w.put(name, per_node);
  else w.put_part(name, values_of(per_node, m.part->own, 2));
}

void Solver::get_nodes(const StateReader& r, const std::string& prefix, const std::string& name,
                       std::vector<double>& per_node) const {
  const Impl& m = *impl_;
  if (m.glob.empty()) {
    get_items(r, name, prefix + "nodes", m.x.size(), 2, per_node);
    return;
  }
  std::vector<double> whole;  // a local model: its nodes' values
  get_items(r, name, prefix + "nodes", m.mesh_nodes, 2, whole);
  per_node.resize(2 * m.glob.size());
  for (std::size_t i = 0; i < m.glob.size(); ++i) {
    per_node[2 * i] = whole[2 * m.glob[i]];
    per_node[2 * i + 1] = whole[2 * m.glob[i] + 1];
  }
}

void Solver::save_state(StateWriter& w, const std::string& pre) const {
  const Impl& m = *impl_;
  Energies e = energy;
  if (m.part) {
    const Impl::Part& P = *m.part;
    double b[2] = {P.work, P.absorbed};
    sum_over_ranks(m, b, 2);
    e.external_work = b[0];
    e.absorbed = b[1];
  }
  w.put(pre + "dt", dt);
  w.put(pre + "t", t);
  w.put(pre + "steps", static_cast<std::int64_t>(steps));
  w.put(pre + "energy", e);
  if (m.part && m.glob.empty()) {
    w.put_part(pre + "nodes", m.part->own);
  } else if (m.part) {  // a local model: its own nodes' mesh numbers
    std::vector<std::uint32_t> numbers;
    numbers.reserve(m.part->own.size());
    for (const auto i : m.part->own) numbers.push_back(m.glob[i]);
    w.put_part(pre + "nodes", numbers);
  }
  put_nodes(w, pre + "u", m.u);
  put_nodes(w, pre + "v", m.v);
  put_nodes(w, pre + "ku", m.ku);
  w.put(pre + "ku_valid", static_cast<std::uint8_t>(m.ku_valid));
  w.put(pre + "snapshot_times", snapshot_times());
  // A local model has layers when the whole model has, even if none is in this rank's part:
  // every rank puts the same part blocks.
  if (!(m.glob.empty() ? m.pml.active() : m.pml.whole_cells > 0)) return;
  if (!m.part) {
    w.put(pre + "pml_xi", m.pml.xi);
    w.put(pre + "pml_zeta", m.pml.zeta);
    return;
  }
  if (!m.glob.empty()) {  // a local model: its part's cells and its own nodes, by their numbers
    std::vector<std::uint32_t> cells, numbers;
    for (std::size_t k = 0; k < m.pml.cell.size(); ++k)
      if (m.pml.own_cell[k]) {
        cells.push_back(static_cast<std::uint32_t>(k));
        numbers.push_back(m.pml.glob_cell[k]);
      }
    w.put_part(pre + "pml_cells", numbers);
    w.put_part(pre + "pml_xi", values_of(m.pml.xi, cells, 4 * m.pml.nq));
    w.put_part(pre + "pml_nodes", m.pml.glob_node);
    w.put_part(pre + "pml_zeta", m.pml.zeta);
    return;
  }
  const Impl::Part& P = *m.part;
  const auto me = static_cast<std::uint32_t>(P.rank);
  std::vector<std::uint32_t> cell_owner(m.pml.cell.size()), node_owner(m.pml.node.size());
  for (std::size_t c = 0; c < cell_owner.size(); ++c) cell_owner[c] = P.cell_rank[m.pml.cell[c]];
  for (std::size_t j = 0; j < node_owner.size(); ++j) node_owner[j] = P.node_rank[m.pml.node[j]];
  const std::vector<std::uint32_t> cells = owned(cell_owner, me), nodes = owned(node_owner, me);
  w.put_part(pre + "pml_cells", cells);
  w.put_part(pre + "pml_xi", values_of(m.pml.xi, cells, 4 * m.pml.nq));
  w.put_part(pre + "pml_nodes", nodes);
  w.put_part(pre + "pml_zeta", values_of(m.pml.zeta, nodes, 4));
}

void Solver::load_state(const StateReader& r, const std::string& pre) {
  Impl& m = *impl_;
  const double dt_saved = r.get<double>(pre + "dt");
  if (dt_saved != dt)
    r.fail("FE time step " + fmt(dt_saved) + " s in the checkpoint, " + fmt(dt) +
           " s in this case (a checkpoint of another case)");
  // A local model on several ranks: rank 0 alone reads the nodal blocks and the layers'
  // memories and sends each rank its own (a restart sends the others the checkpoint without
  // them: Solver::blocks_from_root).
  const bool from_root = local_on_ranks(m);
  if (from_root) {
    load_from_root(m, r, pre);
  } else {
    get_nodes(r, pre, pre + "u", m.u);
    get_nodes(r, pre, pre + "v", m.v);
    get_nodes(r, pre, pre + "ku", m.ku);
    m.ku_valid = r.get<std::uint8_t>(pre + "ku_valid") != 0;
  }
  t = r.get<double>(pre + "t");
  steps = static_cast<long>(r.get<std::int64_t>(pre + "steps"));
  energy = r.get<Energies>(pre + "energy");
  r.get(pre + "snapshot_times", m.snapshot_times);
  m.snapshots = static_cast<int>(m.snapshot_times.size());
  if (m.pml.active() && m.glob.empty()) {
    get_items(r, pre + "pml_xi", pre + "pml_cells", m.pml.cell.size(), 4 * m.pml.nq, m.pml.xi);
    get_items(r, pre + "pml_zeta", pre + "pml_nodes", m.pml.node.size(), 4, m.pml.zeta);
  } else if (m.pml.whole_cells > 0 && !from_root) {  // a local model: its cells' and nodes' memories
    Impl::Pml& P = m.pml;
    const auto w = static_cast<std::size_t>(4 * P.nq);
    std::vector<double> xi, zeta;
    get_items(r, pre + "pml_xi", pre + "pml_cells", P.whole_cells, w, xi);
    get_items(r, pre + "pml_zeta", pre + "pml_nodes", P.whole_nodes, 4, zeta);
    for (std::size_t k = 0; k < P.cell.size(); ++k)
      std::copy_n(xi.begin() + static_cast<std::ptrdiff_t>(w * P.glob_cell[k]), w, P.xi.begin() + static_cast<std::ptrdiff_t>(w * k));
    for (std::size_t j = 0; j < P.node.size(); ++j)
      std::copy_n(zeta.begin() + 4 * static_cast<std::ptrdiff_t>(P.glob_node[j]), 4, P.zeta.begin() + 4 * static_cast<std::ptrdiff_t>(j));
  }
  if (m.part) {  // several ranks: the booked energies stay with rank 0
    m.part->work = m.part->rank == 0 ? energy.external_work : 0.0;
    m.part->absorbed = m.part->rank == 0 ? energy.absorbed : 0.0;
  }
}



std::vector<std::string> Solver::blocks_from_root(const std::string& pre) {
  // ("ku" covers the flag "ku_valid" too, which load_from_root sends with the nodes.)
  return {pre + "u", pre + "v", pre + "ku", pre + "nodes", pre + "pml_"};
}

}  // namespace smpm::fem
