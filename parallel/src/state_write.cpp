// One checkpoint file written by every rank at once (state_write.hpp).
#include "silentmpm/state_write.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <unistd.h>

#include <filesystem>
#include <stdexcept>
#include <vector>

#include "silentmpm/mpi_bytes.hpp"
#include "silentmpm/state_io.hpp"

namespace smpm {

namespace {

std::size_t g_piece = std::size_t{1} << 30;
int g_open_fault = -1;  // a rank whose open fails (tests)

// A run of the file's bytes this rank writes: where, how long, its hash, and its source.
struct Piece {
  std::uint64_t at = 0, length = 0, hash = 0;
  const char* data = nullptr;
};

// Rank 0's block table as bytes: per block the name, element size, count and part flag.
struct Entry {
  std::string name;
  std::uint32_t elem = 0;
  std::uint64_t count = 0;
  bool part = false;
};

template <class T>
void append(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
T take(const std::string& s, std::size_t& at) {
  T v;
  std::memcpy(&v, s.data() + at, sizeof v);
  at += sizeof v;
  return v;
}

std::vector<Entry> root_table(const StateWriter& w, int rank, MPI_Comm comm) {
  std::string t;
  if (rank == 0)
    for (const auto& b : w.blocks()) {
      append(t, static_cast<std::uint32_t>(b.name.size()));
      t += b.name;
      append(t, b.elem);
      append(t, b.count);
      append(t, static_cast<std::uint8_t>(b.part));
    }
  broadcast_bytes(t, comm);
  std::vector<Entry> table;
  for (std::size_t at = 0; at < t.size();) {
    Entry e;
    const auto len = take<std::uint32_t>(t, at);
    e.name = t.substr(at, len);
    at += len;
    e.elem = take<std::uint32_t>(t, at);
    e.count = take<std::uint64_t>(t, at);
    e.part = take<std::uint8_t>(t, at) != 0;
    table.push_back(std::move(e));
  }
  return table;
}

std::string mpi_error(int rc) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(rc, text, &len);
  return std::string(text, static_cast<std::size_t>(len));
}

}  // namespace

std::size_t state_write_piece() { return g_piece; }
void set_state_write_piece(std::size_t bytes) {
  g_piece = std::clamp<std::size_t>(bytes, 1, std::size_t{1} << 30);
}
void set_state_write_open_fault(int rank) { g_open_fault = rank; }

void write_state_collectively(const StateWriter& w, const std::string& path, MPI_Comm comm) {
  int rank = 0, size = 1;
  MPI_Comm_rank(comm, &rank);
  MPI_Comm_size(comm, &size);
  const std::vector<Entry> table = root_table(w, rank, comm);

  // This rank's part blocks must be rank 0's, in the same order.
  std::vector<const StateWriter::Block*> mine;
  for (const auto& b : w.blocks())
    if (b.part) mine.push_back(&b);
  std::vector<std::size_t> parts;  // the table's part blocks
  for (std::size_t k = 0; k < table.size(); ++k)
    if (table[k].part) parts.push_back(k);
  int same = mine.size() == parts.size();
  for (std::size_t q = 0; same && q < parts.size(); ++q)
    same = mine[q]->name == table[parts[q]].name && mine[q]->elem == table[parts[q]].elem;
  MPI_Allreduce(MPI_IN_PLACE, &same, 1, MPI_INT, MPI_LAND, comm);
  if (!same)
    throw std::logic_error(path + ": the ranks' checkpoints hold different part blocks");

  // Every rank's count of every part block.
  const std::size_t np = parts.size();
  std::vector<unsigned long long> my(np), all(np * static_cast<std::size_t>(size));
  for (std::size_t q = 0; q < np; ++q) my[q] = mine[q]->count;
  MPI_Allgather(my.data(), static_cast<int>(np), MPI_UNSIGNED_LONG_LONG, all.data(),
                static_cast<int>(np), MPI_UNSIGNED_LONG_LONG, comm);

  // The layout, and the pieces this rank writes.
  const std::string& buf = w.buffer();
  std::vector<std::string> heads;  // rank 0's block heads (reserved: the pieces point into them)
  heads.reserve(table.size() + 1);
  std::vector<Piece> pieces;
  auto add = [&](std::uint64_t at, const char* data, std::uint64_t length) {
    if (length) pieces.push_back({at, length, 0, data});
  };
  std::uint64_t pos = StateWriter::head_size();
  if (rank == 0) add(0, buf.data(), pos);
  for (std::size_t k = 0, q = 0; k < table.size(); ++k) {
    const Entry& e = table[k];
    std::uint64_t total = e.count, before = 0;
    if (e.part) {
      total = 0;
      for (int r = 0; r < size; ++r) {
        const unsigned long long c = all[static_cast<std::size_t>(r) * np + q];
        total += c;
        if (r < rank) before += c;
      }
    }
    std::string head = StateWriter::block_head(e.name, e.elem, total);
    const std::uint64_t head_length = head.size();
    if (rank == 0) {
      heads.push_back(std::move(head));
      add(pos, heads.back().data(), head_length);
    }
    pos += head_length;
    if (e.part) {
      add(pos + e.elem * before, buf.data() + mine[q]->offset, e.elem * mine[q]->count);
      ++q;
    } else if (rank == 0) {
      add(pos, buf.data() + w.blocks()[k].offset, e.elem * e.count);
    }
    pos += e.elem * total;
  }
  if (rank == 0) {
    heads.push_back(StateWriter::end_mark());
    add(pos, heads.back().data(), heads.back().size());
  }
  pos += StateWriter::end_mark().size();
  const std::uint64_t sum_at = pos;
  for (Piece& p : pieces) p.hash = state_hash(p.data, p.length);

  // Every rank writes its pieces; rank 0 then joins the hashes and writes the checksum.
  const std::string tmp = path + ".tmp";
  const std::string tmp_name = std::filesystem::path(tmp).filename().string();
  std::string err;
  auto check = [&](int rc, const std::string& what) {
    if (rc != MPI_SUCCESS && err.empty()) err = what + ": " + mpi_error(rc);
    return rc == MPI_SUCCESS;
  };
  // A stale temporary file (an earlier write that was killed) goes first, so the file holds
  // only what this write puts; a link is followed, as one process's write follows it, and a
  // regular file behind it is cut to this write's length once written.
  if (rank == 0) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(std::filesystem::symlink_status(tmp, ec)))
      std::filesystem::remove(tmp, ec);
  }
  MPI_Barrier(comm);
  // Each rank opens the file on its own (MPI_COMM_SELF; the writes are independent anyway), so
  // an open that fails on some ranks leaves no handle on the others that a collective close
  // would have to wait for: each rank closes what it opened.
  MPI_File fh = MPI_FILE_NULL;
  bool opened = false;
  if (rank == g_open_fault)
    err = "cannot create " + tmp_name + ": a fault set by a test";
  else
    opened = check(MPI_File_open(MPI_COMM_SELF, tmp.c_str(), MPI_MODE_CREATE | MPI_MODE_WRONLY,
                                 MPI_INFO_NULL, &fh),
                   "cannot create " + tmp_name);
  // A descriptor of the same file for fsync, which MPI_File_sync cannot do with one process's
  // leniency (below), taken now so that the sync sees every write of this rank.
  int fd = -1;
  if (opened) {
    fd = ::open(tmp.c_str(), O_WRONLY);
    if (fd < 0) {
      const int e = errno;
      err = "cannot open " + tmp_name + " to sync it: " + std::strerror(e);
    }
  }
  int ok = opened;
  MPI_Allreduce(MPI_IN_PLACE, &ok, 1, MPI_INT, MPI_LAND, comm);
  if (ok) {
    for (const Piece& p : pieces)
      for (std::uint64_t done = 0; done < p.length && err.empty();) {
        const int n = static_cast<int>(std::min<std::uint64_t>(p.length - done, g_piece));
        MPI_Status st;
        if (!check(MPI_File_write_at(fh, static_cast<MPI_Offset>(p.at + done), p.data + done, n,
                                     MPI_BYTE, &st),
                   "cannot write"))
          break;
        int wrote = 0;
        MPI_Get_count(&st, MPI_BYTE, &wrote);
        if (wrote != n) {
          err = "cannot write: " + std::to_string(wrote) + " of " + std::to_string(n) +
                " bytes written (disk full or an I/O error)";
          break;
        }
        done += static_cast<std::uint64_t>(n);
      }
  }
  // The pieces' (offset, length, hash) to rank 0, which joins them in file order.
  std::vector<unsigned long long> triples;
  for (const Piece& p : pieces) triples.insert(triples.end(), {p.at, p.length, p.hash});
  int n3 = static_cast<int>(triples.size());
  std::vector<int> counts(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
  MPI_Gather(&n3, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  std::vector<unsigned long long> every;
  if (rank == 0) {
    int at = 0;
    for (int r = 0; r < size; ++r) displs[r] = at, at += counts[r];
    every.resize(static_cast<std::size_t>(at));
  }
  MPI_Gatherv(triples.data(), n3, MPI_UNSIGNED_LONG_LONG, every.data(), counts.data(),
              displs.data(), MPI_UNSIGNED_LONG_LONG, 0, comm);
  if (ok && rank == 0) {
    std::vector<std::array<unsigned long long, 3>> runs;
    for (std::size_t k = 0; k < every.size(); k += 3) runs.push_back({every[k], every[k + 1], every[k + 2]});
    std::sort(runs.begin(), runs.end());
    std::uint64_t h = 0, next = 0;
    for (const auto& r : runs) {
      if (r[0] != next) break;
      h = state_hash_join(h, r[2], r[1]);
      next += r[1];
    }
    if (next != sum_at && err.empty()) err = "the ranks' pieces do not tile the file (a program error)";
    MPI_Status st;
    if (err.empty()) check(MPI_File_write_at(fh, static_cast<MPI_Offset>(sum_at), &h, 8, MPI_BYTE, &st),
                           "cannot write");
  }
  // Each rank's pieces to the disk before the handles close: fsync on its own descriptor
  // (flushing the file's dirty pages of this node), with one process's leniency: a file system
  // or device with no fsync (EINVAL, EROFS) is not an error.
  if (ok && err.empty() && fd >= 0 && ::fsync(fd) != 0) {
    const int e = errno;
    if (e != EINVAL && e != EROFS) err = std::string("cannot sync: ") + std::strerror(e);
  }
  if (fd >= 0) ::close(fd);
  if (opened) check(MPI_File_close(&fh), "cannot close");
  if (ok && rank == 0 && err.empty()) {
    std::error_code ec;
    if (std::filesystem::is_regular_file(tmp, ec) &&
        std::filesystem::file_size(tmp, ec) != sum_at + 8) {
      std::filesystem::resize_file(tmp, sum_at + 8, ec);
      if (ec) err = "cannot cut " + tmp_name + " to its length: " + ec.message();
    }
  }

  // The first failing rank's reason, to every rank.
  int first = err.empty() ? size : rank;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == size && rank == 0 && std::rename(tmp.c_str(), path.c_str()) != 0)
    err = "cannot rename " + tmp_name + " to it: " + std::strerror(errno), first = 0;
  MPI_Bcast(&first, 1, MPI_INT, 0, comm);
  if (first == size) return;
  std::string why = err;
  if (first != 0) {  // from the failing rank to rank 0, then to every rank
    if (rank == first) MPI_Send(why.data(), static_cast<int>(why.size()), MPI_CHAR, 0, 7303, comm);
    if (rank == 0) {
      MPI_Status st;
      MPI_Probe(first, 7303, comm, &st);
      int n = 0;
      MPI_Get_count(&st, MPI_CHAR, &n);
      why.resize(static_cast<std::size_t>(n));
      MPI_Recv(why.data(), n, MPI_CHAR, first, 7303, comm, MPI_STATUS_IGNORE);
    }
  }
  broadcast_bytes(why, comm);
  if (rank == 0) std::remove(tmp.c_str());
  throw std::runtime_error(path + ": " + why + " (rank " + std::to_string(first) + " of " +
                           std::to_string(size) + ")");
}

}  // namespace smpm
