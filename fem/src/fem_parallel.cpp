// The FE far field over MPI ranks (docs/parallel.md, "The FE far field"): the split of the work
// by METIS's cut of the cells, the ghost update after each step, sums and gathers over ranks.
// Plain MPI point-to-point and collectives; no deal.II here (the cut is made in fem_setup.cpp).
#include <mpi.h>

#include <algorithm>
#include <cstdio>
#include <limits>
#include <string>

#include "fem_impl.hpp"
#include "silentmpm/mpi_bytes.hpp"

namespace smpm::fem {

namespace {
constexpr int kGhostTag = 7301;
}  // namespace

void check_can_split(const Solver::Impl& m) {
  if (m.part) throw FemError("FEM: the model is already split over the MPI ranks");
  int running = 0;
  MPI_Initialized(&running);
  if (!running) throw FemError("FEM: splitting the model over ranks needs MPI, which is not running");
}

void check_enough_cells(std::size_t nc, int size) {
  if (nc < static_cast<std::size_t>(size))
    throw FemError("FEM: fewer cells (" + std::to_string(nc) + ") than MPI ranks (" +
                   std::to_string(size) + "): run it on fewer ranks or on a finer mesh");
}

void check_parts(const std::vector<std::uint32_t>& cell_rank, int size, std::size_t nc) {
  const auto ranks = static_cast<std::size_t>(size);
  std::vector<std::size_t> cells_of(ranks, 0);
  for (const auto r : cell_rank) ++cells_of[r];
  for (std::size_t r = 0; r < ranks; ++r)
    if (cells_of[r] == 0)
      throw FemError("FEM: METIS left rank " + std::to_string(r) + " of " + std::to_string(size) +
                     " without cells (" + std::to_string(nc) + " cells): run it on fewer ranks");
}

void make_part(const Solver::Impl& m, Solver::Impl::Part& P, std::uint32_t me) {
  const std::size_t nc = m.n_cells, nn = m.x.size();
  const auto ranks = static_cast<std::size_t>(P.size);
  P.own.clear();
  P.links.clear();
  P.ghosts = 0;
  const std::size_t nb = static_cast<std::size_t>((m.degree + 1) * (m.degree + 1));
  P.node_rank.assign(nn, std::numeric_limits<std::uint32_t>::max());
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t a = 0; a < nb; ++a) {
      auto& r = P.node_rank[m.cell_nodes[c * nb + a]];
      r = std::min(r, P.cell_rank[c]);
    }
  for (std::size_t i = 0; i < nn; ++i)
    if (P.node_rank[i] == me) P.own.push_back(static_cast<std::uint32_t>(i));

  // A cell is stepped by its part's rank and by the rank of each of its nodes (so that a rank
  // holds every cell around its own nodes); each such rank reads all the cell's nodes, and
  // receives those it does not own from their owners.
  std::vector<std::vector<std::uint32_t>> send(ranks), recv(ranks);
  std::vector<char> local(nc, 0);
  std::vector<std::uint32_t> rs;
  for (std::size_t c = 0; c < nc; ++c) {
    rs.assign(1, P.cell_rank[c]);
    for (std::size_t a = 0; a < nb; ++a) rs.push_back(P.node_rank[m.cell_nodes[c * nb + a]]);
    std::sort(rs.begin(), rs.end());
    rs.erase(std::unique(rs.begin(), rs.end()), rs.end());
    local[c] = std::binary_search(rs.begin(), rs.end(), me);
    for (std::size_t a = 0; a < nb; ++a) {
      const std::uint32_t n = m.cell_nodes[c * nb + a], o = P.node_rank[n];
      for (const std::uint32_t q : rs) {
        if (q == o) continue;
        if (o == me) send[q].push_back(n);
        if (q == me) recv[o].push_back(n);
      }
    }
  }
  for (std::size_t q = 0; q < ranks; ++q) {
    for (auto* l : {&send[q], &recv[q]}) {
      std::sort(l->begin(), l->end());
      l->erase(std::unique(l->begin(), l->end()), l->end());
    }
    if (send[q].empty() && recv[q].empty()) continue;
    P.ghosts += recv[q].size();
    P.links.push_back({static_cast<int>(q), std::move(send[q]), std::move(recv[q])});
  }

  // The perfectly matched layers: the layer cells this rank steps, colour by colour, and its
  // own nodes' memories.
  if (m.pml.active()) {
    const Solver::Impl::Pml& L = m.pml;
    P.pml_cells.clear();
    P.pml_nodes.clear();
    P.pml_colour_start.assign(1, 0);
    for (std::size_t k = 0; k + 1 < L.colour_start.size(); ++k) {
      for (std::uint32_t c = L.colour_start[k]; c < L.colour_start[k + 1]; ++c)
        if (local[L.cell[c]]) P.pml_cells.push_back(c);
      P.pml_colour_start.push_back(static_cast<std::uint32_t>(P.pml_cells.size()));
    }
    for (std::size_t j = 0; j < L.node.size(); ++j)
      if (P.node_rank[L.node[j]] == me) P.pml_nodes.push_back(static_cast<std::uint32_t>(j));
  }
}

void Solver::distribute() {
  Impl& m = *impl_;
  check_can_split(m);
  auto part = std::make_unique<Impl::Part>();
  Impl::Part& P = *part;
  MPI_Comm_rank(MPI_COMM_WORLD, &P.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &P.size);
  const std::size_t nc = m.n_cells;
  check_enough_cells(nc, P.size);
  // Rank 0 cuts the mesh and sends the cut to the others, so that every rank holds the same one.
  // It says first whether the cut worked, so that a failure stops every rank (with rank 0's
  // reason printed by rank 0), not rank 0 alone while the others wait for the cut.
  P.cell_rank.assign(nc, 0);
  std::string why;
  if (P.rank == 0) {
    try {
      P.cell_rank = partition_cells(m, static_cast<unsigned>(P.size));
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  int cut = why.empty() ? 1 : 0;
  MPI_Bcast(&cut, 1, MPI_INT, 0, MPI_COMM_WORLD);
  if (!cut) throw FemError(P.rank == 0 ? why : "FEM: rank 0 could not cut the mesh");
  MPI_Bcast(P.cell_rank.data(), static_cast<int>(nc), MPI_UINT32_T, 0, MPI_COMM_WORLD);
  check_parts(P.cell_rank, P.size, nc);
  make_part(m, P, static_cast<std::uint32_t>(P.rank));
  // The booked energies stay with rank 0; every rank adds its own nodes' share from now on.
  // The damping layers' stiffness-proportional rows this rank steps: its own listed nodes.
  if (m.visc.active()) {
    m.visc.rows.clear();
    m.visc.row_node.clear();
    for (std::size_t r = 0; r < m.visc.node.size(); ++r)
      if (P.node_rank[m.visc.node[r]] == static_cast<std::uint32_t>(P.rank)) {
        m.visc.rows.push_back(static_cast<std::uint32_t>(r));
        m.visc.row_node.push_back(m.visc.node[r]);
      }
  }
  P.work = P.rank == 0 ? energy.external_work : 0.0;
  P.absorbed = P.rank == 0 ? energy.absorbed : 0.0;
  m.part = std::move(part);
}

int Solver::ranks() const { return impl_->part ? impl_->part->size : 1; }

std::vector<std::uint32_t> Solver::own_nodes() const {
  if (impl_->part) return impl_->part->own;
  std::vector<std::uint32_t> all(impl_->x.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = static_cast<std::uint32_t>(i);
  return all;
}

int Solver::node_owner(std::uint32_t node) const {
  return impl_->part ? static_cast<int>(impl_->part->node_rank[node]) : 0;
}

std::vector<double> Solver::gathered(const std::vector<double>& per_node) const {
  const Impl& m = *impl_;
  if (!m.part) return per_node;
  std::vector<std::vector<double>> out;
  if (!m.glob.empty()) gather_local(m, {&per_node}, 2, out);
  else gather_on_root(m, m.part->node_rank, {&per_node}, 2, out);
  return out.empty() ? std::vector<double>() : std::move(out[0]);
}

Solver::Traffic Solver::traffic() const {
  Traffic t;
  const Impl& m = *impl_;
  if (!m.part) {
    t.own_nodes = t.held_nodes = m.x.size();
    return t;
  }
  const Impl::Part& P = *m.part;
  double most[5] = {P.seconds, static_cast<double>(P.own.size()), static_cast<double>(P.ghosts),
                    static_cast<double>(P.links.size()), static_cast<double>(m.x.size())};
  double bytes = P.bytes;
  MPI_Allreduce(MPI_IN_PLACE, most, 5, MPI_DOUBLE, MPI_MAX, MPI_COMM_WORLD);
  MPI_Allreduce(MPI_IN_PLACE, &bytes, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
  t.seconds = most[0];
  t.bytes = bytes;
  t.updates = P.updates;
  t.own_nodes = static_cast<std::size_t>(most[1]);
  t.ghost_nodes = static_cast<std::size_t>(most[2]);
  t.neighbours = static_cast<std::size_t>(most[3]);
  t.held_nodes = static_cast<std::size_t>(most[4]);
  return t;
}

void exchange_ghosts(Solver::Impl& m) {
  Solver::Impl::Part& P = *m.part;
  const double t0 = MPI_Wtime();
  std::size_t ns = 0, nr = 0;
  for (const auto& l : P.links) {
    ns += l.send.size();
    nr += l.recv.size();
  }
  P.sendbuf.resize(4 * ns);
  P.recvbuf.resize(4 * nr);
  std::vector<MPI_Request> req;  // a few per step: not worth keeping
  req.reserve(2 * P.links.size());
  std::size_t off = 0;
  for (const auto& l : P.links) {
    if (!l.recv.empty()) {
      req.emplace_back();
      MPI_Irecv(P.recvbuf.data() + off, static_cast<int>(4 * l.recv.size()), MPI_DOUBLE, l.rank,
                kGhostTag, MPI_COMM_WORLD, &req.back());
    }
    off += 4 * l.recv.size();
  }
  const double* u = m.u.data();
  const double* v = m.v.data();
  off = 0;
  for (const auto& l : P.links) {
    double* b = P.sendbuf.data() + off;
    for (const std::uint32_t n : l.send) {
      *b++ = u[2 * n];
      *b++ = u[2 * n + 1];
      *b++ = v[2 * n];
      *b++ = v[2 * n + 1];
    }
    if (!l.send.empty()) {
      req.emplace_back();
      MPI_Isend(P.sendbuf.data() + off, static_cast<int>(4 * l.send.size()), MPI_DOUBLE, l.rank,
                kGhostTag, MPI_COMM_WORLD, &req.back());
    }
    off += 4 * l.send.size();
  }
  MPI_Waitall(static_cast<int>(req.size()), req.data(), MPI_STATUSES_IGNORE);
  const double* b = P.recvbuf.data();
  for (const auto& l : P.links)
    for (const std::uint32_t n : l.recv) {
      m.u[2 * n] = *b++;
      m.u[2 * n + 1] = *b++;
      m.v[2 * n] = *b++;
      m.v[2 * n + 1] = *b++;
    }
  P.seconds += MPI_Wtime() - t0;
  P.bytes += 8.0 * 4.0 * static_cast<double>(ns);
  ++P.updates;
}

void sum_over_ranks(const Solver::Impl& m, double* v, int n) {
  if (m.part) MPI_Allreduce(MPI_IN_PLACE, v, n, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
}

namespace {
std::size_t gather_piece_ = std::size_t{1} << 30;
}  // namespace

void Solver::set_gather_piece(std::size_t n) { gather_piece_ = n > 0 ? n : 1; }
long long gather_piece() { return static_cast<long long>(gather_piece_); }

void gather_on_root(const Solver::Impl& m, const std::vector<std::uint32_t>& owner,
                    const std::vector<const std::vector<double>*>& fields, int width,
                    std::vector<std::vector<double>>& out) {
  const Solver::Impl::Part& P = *m.part;
  const auto me = static_cast<std::uint32_t>(P.rank);
  const std::size_t w = static_cast<std::size_t>(width), items = owner.size();
  std::vector<double> mine;
  for (std::size_t i = 0; i < items; ++i) {
    if (owner[i] != me) continue;
    for (const auto* f : fields) mine.insert(mine.end(), f->begin() + w * i, f->begin() + w * (i + 1));
  }
  out.clear();
  std::vector<long long> counts;
  std::vector<double> all;
  gather_doubles(mine, all, counts, MPI_COMM_WORLD, static_cast<long long>(gather_piece_));
  std::vector<std::size_t> displs(counts.size(), 0);
  for (std::size_t q = 1; q < counts.size(); ++q)
    displs[q] = displs[q - 1] + static_cast<std::size_t>(counts[q - 1]);
  if (P.rank != 0) return;
  out.assign(fields.size(), std::vector<double>(w * items, 0.0));
  std::vector<std::size_t> pos(displs.begin(), displs.end());
  for (std::size_t i = 0; i < items; ++i) {
    std::size_t& p = pos[owner[i]];
    for (std::size_t f = 0; f < fields.size(); ++f) {
      std::copy(all.begin() + static_cast<std::ptrdiff_t>(p),
                all.begin() + static_cast<std::ptrdiff_t>(p + w), out[f].begin() + w * i);
      p += w;
    }
  }
}



namespace {
constexpr int kSliceTag = 7306;
// n values from `from` (or to `to`), in messages of at most gather_piece() values.
template <class T>
void send_pieces(const T* v, std::size_t n, MPI_Datatype type, int to) {
  const auto piece = static_cast<std::size_t>(gather_piece());
  for (std::size_t at = 0; at < n; at += piece)
    MPI_Send(v + at, static_cast<int>(std::min(piece, n - at)), type, to, kSliceTag, MPI_COMM_WORLD);
}
template <class T>
void recv_pieces(T* v, std::size_t n, MPI_Datatype type, int from) {
  const auto piece = static_cast<std::size_t>(gather_piece());
  for (std::size_t at = 0; at < n; at += piece)
    MPI_Recv(v + at, static_cast<int>(std::min(piece, n - at)), type, from, kSliceTag,
             MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}
}  // namespace

void slices_from_root(const std::vector<std::uint32_t>& mine,
                      const std::vector<const std::vector<double>*>& whole,
                      const std::vector<std::size_t>& widths,
                      const std::vector<std::vector<double>*>& out) {
  int rank = 0, size = 1;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank);
  MPI_Comm_size(MPI_COMM_WORLD, &size);
  std::size_t per = 0;  // values per item, over the fields
  for (const auto w : widths) per += w;
  // Item k of the list `at`: its values of every field, one after another.
  const auto fill = [&](const std::vector<std::uint32_t>& at, std::vector<double>& values) {
    values.resize(per * at.size());
    double* o = values.data();
    for (const auto i : at)
      for (std::size_t f = 0; f < whole.size(); ++f) {
        std::copy_n(whole[f]->begin() + static_cast<std::ptrdiff_t>(widths[f] * i), widths[f], o);
        o += widths[f];
      }
  };
  std::vector<double> values;
  const unsigned long long n = mine.size();
  if (rank == 0) {
    for (int r = 1; r < size; ++r) {
      unsigned long long m = 0;
      MPI_Recv(&m, 1, MPI_UNSIGNED_LONG_LONG, r, kSliceTag, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
      std::vector<std::uint32_t> at(m);
      recv_pieces(at.data(), at.size(), MPI_UINT32_T, r);
      fill(at, values);
      send_pieces(values.data(), values.size(), MPI_DOUBLE, r);
    }
    fill(mine, values);
  } else {
    MPI_Send(&n, 1, MPI_UNSIGNED_LONG_LONG, 0, kSliceTag, MPI_COMM_WORLD);
    send_pieces(mine.data(), mine.size(), MPI_UINT32_T, 0);
    values.resize(per * mine.size());
    recv_pieces(values.data(), values.size(), MPI_DOUBLE, 0);
  }
  const double* v = values.data();
  for (std::size_t f = 0; f < out.size(); ++f) out[f]->resize(widths[f] * mine.size());
  for (std::size_t k = 0; k < mine.size(); ++k)
    for (std::size_t f = 0; f < out.size(); ++f) {
      std::copy_n(v, widths[f], out[f]->begin() + static_cast<std::ptrdiff_t>(widths[f] * k));
      v += widths[f];
    }
}



void load_from_root(Solver::Impl& m, const StateReader& r, const std::string& pre) {
  const bool root = m.part->rank == 0;
  const bool layers = m.pml.whole_cells > 0;
  const std::size_t w = 4 * static_cast<std::size_t>(m.pml.nq);
  std::vector<double> u, v, ku, xi, zeta;
  std::string why;
  std::uint8_t valid = 0;
  if (root) {
    try {
      get_items(r, pre + "u", pre + "nodes", m.mesh_nodes, 2, u);
      get_items(r, pre + "v", pre + "nodes", m.mesh_nodes, 2, v);
      get_items(r, pre + "ku", pre + "nodes", m.mesh_nodes, 2, ku);
      valid = r.get<std::uint8_t>(pre + "ku_valid");
      if (layers) {
        get_items(r, pre + "pml_xi", pre + "pml_cells", m.pml.whole_cells, w, xi);
        get_items(r, pre + "pml_zeta", pre + "pml_nodes", m.pml.whole_nodes, 4, zeta);
      }
    } catch (const std::exception& e) {
      why = e.what();
    }
  }
  broadcast_bytes(why, MPI_COMM_WORLD);
  if (!why.empty()) throw StateError(why);
  MPI_Bcast(&valid, 1, MPI_UINT8_T, 0, MPI_COMM_WORLD);
  m.ku_valid = valid != 0;
  slices_from_root(m.glob, {&u, &v, &ku}, {2, 2, 2}, {&m.u, &m.v, &m.ku});
  if (layers) {
    slices_from_root(m.pml.glob_cell, {&xi}, {w}, {&m.pml.xi});
    slices_from_root(m.pml.glob_node, {&zeta}, {4}, {&m.pml.zeta});
  }
}

}  // namespace smpm::fem
