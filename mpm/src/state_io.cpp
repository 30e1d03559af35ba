// Named binary blocks of a run's state (the layout in state_io.hpp).
#include "silentmpm/state_io.hpp"

#include <algorithm>
#include <array>
#include <cerrno>
#include <filesystem>

#include <unistd.h>

namespace smpm {

namespace {
constexpr char kMagic[10] = {'S', 'M', 'P', 'M', 'S', 'T', 'A', 'T', 'E', '\0'};
constexpr std::uint32_t kLayout = 2;  // 2: the joinable checksum (1: FNV-1a)
constexpr std::uint32_t kOrderMark = 0x01020304u;

template <class T>
void append(std::string& s, T v) {
  s.append(reinterpret_cast<const char*>(&v), sizeof v);
}
}  // namespace

std::uint64_t fnv1a64(const void* data, std::size_t n, std::uint64_t h) {
  const auto* b = static_cast<const unsigned char*>(data);
  for (std::size_t i = 0; i < n; ++i) {
    h ^= b[i];
    h *= 1099511628211ull;
  }
  return h;
}

namespace {
// Arithmetic modulo p = 2^61 - 1.
constexpr std::uint64_t kP = (std::uint64_t{1} << 61) - 1;
constexpr std::uint64_t kX = 0x2F6B3C1D9E4A5871ull % kP;  // the hash's base

std::uint64_t mod_p(unsigned __int128 v) {
  std::uint64_t r = static_cast<std::uint64_t>(v & kP) + static_cast<std::uint64_t>(v >> 61);
  r = (r & kP) + (r >> 61);
  return r >= kP ? r - kP : r;
}
std::uint64_t mul_p(std::uint64_t a, std::uint64_t b) {
  return mod_p(static_cast<unsigned __int128>(a) * b);
}
std::uint64_t pow_p(std::uint64_t x, std::uint64_t n) {
  std::uint64_t r = 1;
  for (; n; n >>= 1, x = mul_p(x, x))
    if (n & 1) r = mul_p(r, x);
  return r;
}
}  // namespace

std::uint64_t state_hash(const void* data, std::size_t n, std::uint64_t h) {
  const auto* b = static_cast<const unsigned char*>(data);
  // Eight bytes at a time: h x^8 + sum (b_k + 1) x^(7-k); only the first product is in the chain.
  static const std::array<std::uint64_t, 9> X = [] {
    std::array<std::uint64_t, 9> a{};
    a[0] = 1;
    for (int k = 1; k < 9; ++k) a[k] = mul_p(a[k - 1], kX);
    return a;
  }();
  std::size_t i = 0;
  for (; i + 8 <= n; i += 8) {
    unsigned __int128 s = static_cast<unsigned __int128>(h) * X[8];
    for (int k = 0; k < 8; ++k) s += static_cast<unsigned __int128>(b[i + k] + 1u) * X[7 - k];
    h = mod_p(s);
  }
  for (; i < n; ++i) h = mod_p(static_cast<unsigned __int128>(h) * kX + (b[i] + 1u));
  return h;
}

std::uint64_t state_hash_join(std::uint64_t a, std::uint64_t b, std::uint64_t length_of_b) {
  return mod_p(static_cast<unsigned __int128>(mul_p(a, pow_p(kX, length_of_b))) + b);
}

std::size_t StateWriter::head_size() { return sizeof kMagic + 8; }

std::string StateWriter::block_head(const std::string& name, std::uint32_t elem,
                                    std::uint64_t count) {
  std::string s;
  append(s, static_cast<std::uint32_t>(name.size()));
  s += name;
  append(s, elem);
  append(s, count);
  return s;
}

StateWriter::StateWriter() {
  buf_.append(kMagic, sizeof kMagic);
  append(buf_, kLayout);
  append(buf_, kOrderMark);
}

void StateWriter::raw(const std::string& name, std::size_t elem, std::size_t count,
                      const void* data, bool part) {
  if (name == "end" || !names_.emplace(name, true).second)
    throw std::logic_error("state block '" + name + "' written twice");
  buf_ += block_head(name, static_cast<std::uint32_t>(elem), count);
  blocks_.push_back({name, static_cast<std::uint32_t>(elem), count, buf_.size(), part});
  if (count) buf_.append(static_cast<const char*>(data), elem * count);
}

std::string StateWriter::bytes() {
  std::string out = std::move(buf_);
  buf_.clear();
  names_.clear();
  blocks_.clear();
  out += end_mark();
  append(out, state_hash(out.data(), out.size()));
  return out;
}

void StateReader::fail(const std::string& what) const {
  throw StateError(file_ + ": " + what);
}

StateReader::StateReader(std::string bytes, std::string file)
    : data_(std::move(bytes)), file_(std::move(file)), size_(data_.size()) {
  parse();
}

StateReader StateReader::open(const std::string& path) {
  StateReader r;
  r.file_ = path;
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  std::FILE* f = ec ? nullptr : std::fopen(path.c_str(), "rb");
  if (!f) throw std::runtime_error(path + ": cannot read it");
  r.disk_.reset(f, std::fclose);
  r.size_ = static_cast<std::size_t>(size);
  r.parse();
  return r;
}

void StateReader::read_at(std::size_t pos, std::size_t n, void* out) const {
  if (!disk_) {
    std::memcpy(out, data_.data() + pos, n);
    return;
  }
  // pread keeps no file position: the reader's getters may run on any thread.
  auto* dst = static_cast<char*>(out);
  for (std::size_t done = 0; done < n;) {
    const ssize_t got = ::pread(::fileno(disk_.get()), dst + done, n - done,
                                static_cast<off_t>(pos + done));
    if (got > 0) {
      done += static_cast<std::size_t>(got);
      continue;
    }
    if (got < 0 && errno == EINTR) continue;
    const std::string why = got < 0 ? std::strerror(errno) : "the file got shorter";
    fail("cannot read bytes " + std::to_string(pos) + " to " + std::to_string(pos + n) + " of " +
         std::to_string(size_) + " (" + why + ")");
  }
}

void StateReader::parse() {
  const std::size_t head = sizeof kMagic + 8;
  char magic[sizeof kMagic] = {};
  if (size_ >= head) read_at(0, sizeof kMagic, magic);
  if (size_ < head || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    fail("not a silentmpm checkpoint (no SMPMSTATE header)");
  std::uint32_t layout, order;
  read_at(sizeof kMagic, 4, &layout);
  read_at(sizeof kMagic + 4, 4, &order);
  if (order != kOrderMark) fail("written on a machine of another byte order");
  if (layout != kLayout)
    fail("checkpoint layout " + std::to_string(layout) + ", this build reads layout " +
         std::to_string(kLayout) + " (written by another version: run the case from the start)");
  std::size_t pos = head;
  auto need = [&](std::size_t n) {
    if (size_ - pos < n)
      fail("truncated at byte " + std::to_string(pos) + " of " + std::to_string(size_) +
           " (the file was cut short: an interrupted copy or a full disk)");
  };
  for (;;) {
    std::uint32_t len, elem;
    std::uint64_t count;
    need(4);
    read_at(pos, 4, &len);
    pos += 4;
    if (len > 256) fail("corrupt block table at byte " + std::to_string(pos - 4));
    need(len + 12);
    std::string name(len, '\0');
    read_at(pos, len, name.data());
    pos += len;
    read_at(pos, 4, &elem);
    read_at(pos + 4, 8, &count);
    pos += 12;
    if (name == "end") break;
    if (elem == 0 || count > (size_ - pos) / elem)
      fail("truncated in block '" + name + "' (the file was cut short)");
    blocks_[name] = Block{elem, static_cast<std::size_t>(count), pos};
    pos += elem * count;
  }
  need(8);
  std::uint64_t sum;
  read_at(pos, 8, &sum);
  std::uint64_t h = 0;
  if (!disk_) {
    h = state_hash(data_.data(), pos);
  } else {  // in pieces: the hash continues across them
    std::string piece(std::min<std::size_t>(pos, std::size_t{1} << 26), '\0');
    for (std::size_t at = 0; at < pos;) {
      const std::size_t n = std::min(piece.size(), pos - at);
      read_at(at, n, piece.data());
      h = state_hash(piece.data(), n, h);
      at += n;
    }
  }
  if (sum != h) fail("checksum mismatch (the file is corrupt)");
  if (pos + 8 != size_) fail("trailing bytes after the end mark (the file is corrupt)");
}

const StateReader::Block& StateReader::find(const std::string& name, std::size_t elem) const {
  const auto it = blocks_.find(name);
  if (it == blocks_.end()) fail("block '" + name + "' missing (a checkpoint of another kind of run)");
  if (it->second.elem != elem)
    fail("block '" + name + "' holds " + std::to_string(it->second.elem) + "-byte values, " +
         std::to_string(elem) + " expected");
  return it->second;
}

void StateReader::mismatch(const std::string& name, std::size_t got, std::size_t want) const {
  fail("block '" + name + "' holds " + std::to_string(got) + " values, this case has " +
       std::to_string(want) + " (a checkpoint of another case)");
}

std::string StateReader::without(const std::vector<std::string>& prefixes) const {
  std::vector<std::pair<std::size_t, std::string>> kept;  // in the file's order
  for (const auto& [name, b] : blocks_) {
    bool drop = false;
    for (const auto& p : prefixes) drop = drop || name.rfind(p, 0) == 0;
    if (!drop) kept.push_back({b.offset, name});
  }
  std::sort(kept.begin(), kept.end());
  StateWriter w;
  std::string block;
  for (const auto& [offset, name] : kept) {
    const Block& b = blocks_.at(name);
    block.resize(b.elem * b.count);
    if (!block.empty()) read_at(b.offset, block.size(), block.data());
    w.put_block(name, b.elem, b.count, block.data());
  }
  return w.bytes();
}

std::string StateReader::get_string(const std::string& name) const {
  const Block& b = find(name, 1);
  std::string s(b.count, '\0');
  if (b.count) read_at(b.offset, b.count, s.data());
  return s;
}

}  // namespace smpm
