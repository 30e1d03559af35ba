#pragma once
// The state of a run as named binary blocks: what a checkpoint holds (the run loop writes it to
// DIR/checkpoint.smpm; docs/case-reference.md "Checkpoints and restart").
//
// A StateWriter collects blocks, each a name, an element size and the raw bytes of an array
// (or one scalar); a StateReader finds them again by name and checks their element size and
// count, so that a block of the wrong kind or length is one error naming the block and the file.
// Values are stored bit for bit (a restored double is the same double), in the byte order of
// the machine that wrote them (the file's header records it; another order is refused).
//
// File layout (StateWriter::bytes):
//   "SMPMSTATE\0" (10 bytes), uint32 layout version, uint32 byte-order mark 0x01020304,
//   then per block: uint32 name length, name, uint32 element size, uint64 count, the data;
//   then the block "end" (no data) and a uint64 checksum of every byte before it (state_hash).
//
// Several MPI ranks write one file at once (the MPI module's write_state): a block put with
// put_part holds every rank's part joined in rank order, a block put with put comes from
// rank 0 alone. The checksum is a hash that pieces hashed apart can join, so each rank hashes
// what it writes.
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace smpm {

// A checkpoint that cannot be used: truncated, corrupt, of another case or version. The message
// names the file and what is wrong.
struct StateError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// 64-bit FNV-1a of a byte string (case fingerprints).
std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t h = 1469598103934665603ull);

// A checkpoint's checksum: the polynomial sum over its bytes b_1..b_n of (b_k + 1) x^(n-k)
// modulo the prime 2^61 - 1 (x fixed). `h` is the hash of the bytes before `data`, so
// state_hash(B, state_hash(A)) is the hash of A followed by B; state_hash_join does the same from
// the two pieces' hashes and the second's length, so that pieces hashed apart (by the ranks that
// wrote them) give the whole file's. A one-byte change always changes it.
std::uint64_t state_hash(const void* data, std::size_t n, std::uint64_t h = 0);
std::uint64_t state_hash_join(std::uint64_t a, std::uint64_t b, std::uint64_t length_of_b);

class StateWriter {
 public:
  StateWriter();
  template <class T>
  void put(const std::string& name, const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>, "blocks hold plain values");
    raw(name, sizeof(T), v.size(), v.data());
  }
  template <class T>
  void put(const std::string& name, const T& value) {
    static_assert(std::is_trivially_copyable_v<T>, "blocks hold plain values");
    raw(name, sizeof(T), 1, &value);
  }
  void put_string(const std::string& name, const std::string& s) { raw(name, 1, s.size(), s.data()); }
  // This process's part of a block whose whole is every rank's part in rank order (on one
  // process, the block itself). Every rank puts the same part blocks in the same order.
  template <class T>
  void put_part(const std::string& name, const std::vector<T>& v) {
    static_assert(std::is_trivially_copyable_v<T>, "blocks hold plain values");
    raw(name, sizeof(T), v.size(), v.data(), true);
  }
  // The file's bytes: header, blocks, end mark and checksum. Moves the buffer out (no copy of a
  // state that may be most of the memory): the writer is empty afterwards.
  std::string bytes();

  // What a writer over several ranks needs: the blocks in the order put, each with where its
  // data lies in buffer() (which holds the header and the blocks as one process's file would).
  struct Block {
    std::string name;
    std::uint32_t elem = 0;
    std::uint64_t count = 0;
    std::size_t offset = 0;
    bool part = false;
  };
  const std::vector<Block>& blocks() const { return blocks_; }
  const std::string& buffer() const { return buf_; }
  static std::size_t head_size();  // the header's bytes (magic, layout, byte-order mark)
  // A block's table entry (name length, name, element size, count) and the end block's.
  static std::string block_head(const std::string& name, std::uint32_t elem, std::uint64_t count);
  static std::string end_mark() { return block_head("end", 0, 0); }
  // A block of `count` values of `elem` bytes each, copied from `data` (a whole block).
  void put_block(const std::string& name, std::size_t elem, std::size_t count, const void* data) {
    raw(name, elem, count, data);
  }

 private:
  std::string buf_;
  std::map<std::string, bool> names_;
  std::vector<Block> blocks_;
  void raw(const std::string& name, std::size_t elem, std::size_t count, const void* data,
           bool part = false);
};

class StateReader {
 public:
  // Parses and checks the whole file (header, block table, checksum); `file` names it in errors.
  StateReader(std::string bytes, std::string file);
  // The file at `path`, read from the disk block by block as the getters ask, after the same
  // checks (the checksum streamed over the file in pieces): no buffer the size of the file, so a
  // restart holds one copy of the state, the solver's. The getters read the bytes again (the
  // checksum vouches for the file as it was when opened; a file changed on the disk meanwhile
  // is not caught). An unreadable file is a std::runtime_error "PATH: cannot read it"; a read
  // that fails later a StateError naming the bytes and the cause.
  static StateReader open(const std::string& path);
  bool has(const std::string& name) const { return blocks_.count(name) != 0; }
  // An array block; `count` (when not npos) is the length the caller expects.
  template <class T>
  void get(const std::string& name, std::vector<T>& v, std::size_t count = npos) const {
    const Block& b = find(name, sizeof(T));
    if (count != npos && b.count != count) mismatch(name, b.count, count);
    v.resize(b.count);
    if (b.count) read_at(b.offset, b.count * sizeof(T), v.data());
  }
  template <class T>
  T get(const std::string& name) const {
    const Block& b = find(name, sizeof(T));
    if (b.count != 1) mismatch(name, b.count, 1);
    T v;
    read_at(b.offset, sizeof(T), &v);
    return v;
  }
  std::string get_string(const std::string& name) const;
  // The file without the blocks whose names start with one of `prefixes` (a new file, with its
  // own checksum): what a rank that receives its particles from rank 0 reads of a checkpoint.
  std::string without(const std::vector<std::string>& prefixes) const;
  const std::string& file() const { return file_; }
  [[noreturn]] void fail(const std::string& what) const;

  static constexpr std::size_t npos = static_cast<std::size_t>(-1);

 private:
  struct Block {
    std::size_t elem = 0, count = 0, offset = 0;
  };
  StateReader() = default;
  std::string data_, file_;
  std::shared_ptr<std::FILE> disk_;  // the open file (open()); else the bytes are data_
  std::size_t size_ = 0;             // the file's bytes
  std::map<std::string, Block> blocks_;
  void parse();
  void read_at(std::size_t pos, std::size_t n, void* out) const;
  const Block& find(const std::string& name, std::size_t elem) const;
  [[noreturn]] void mismatch(const std::string& name, std::size_t got, std::size_t want) const;
};

}  // namespace smpm
