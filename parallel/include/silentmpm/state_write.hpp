#pragma once
// One checkpoint file written by every rank at once (MPI-IO; docs/parallel.md "Checkpoints").
// The file is the one StateWriter::bytes gives on one process, with each block put with
// put_part holding every rank's part joined in rank order, and each block put with put taken
// from rank 0 (the others may put it too, or leave it out). Every rank writes its parts at their
// offsets and hashes them; rank 0 writes the header, the block table and its whole blocks,
// joins the pieces' hashes into the file's checksum (state_hash_join) and renames the file into
// place once every rank's part is in.
#include <mpi.h>

#include <cstddef>
#include <string>

namespace smpm {

class StateWriter;

// Collective over comm. Writes `path` whole or not at all: into `path`.tmp, renamed when every
// rank has written and synced its pieces (fsync on each rank; a file system without fsync,
// EINVAL or EROFS, is not an error, as on one process). A failure on any rank (a full disk, an
// I/O error, an open that fails on some ranks only) is a std::runtime_error on every rank naming
// the file, the first failing rank and the cause; the temporary file is removed and no rank
// keeps it open. Ranks whose part blocks differ in name, order or element size (a program
// error) get a std::logic_error.
void write_state_collectively(const StateWriter& w, const std::string& path, MPI_Comm comm);

// The most bytes one MPI write carries (2^30: an MPI count is an int); a test sets it smaller.
std::size_t state_write_piece();
void set_state_write_piece(std::size_t bytes);
// A test's fault: the open of the temporary file fails on this rank (-1: on none).
void set_state_write_open_fault(int rank);

}  // namespace smpm
