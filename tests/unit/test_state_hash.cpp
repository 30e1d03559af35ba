// The checkpoint's checksum (state_io.hpp): pieces hashed apart join into the whole's hash, at
// every split of a buffer and from any starting hash; a change of any one byte changes it; the
// word-at-a-time loop equals the plain byte-by-byte definition. A reader over the file on disk
// (StateReader::open, which hashes the file in pieces) reads what the reader over its bytes
// reads, and refuses what it refuses with the same message.
#include <gtest/gtest.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <functional>
#include <fstream>
#include <random>
#include <string>

#include "silentmpm/state_io.hpp"

namespace smpm::testing {
namespace {

// sum over bytes of (b_k + 1) x^(n-k) mod 2^61 - 1, one byte at a time (the definition), with
// x recovered as the hash of one byte 0 followed by another: (1) x + 1.
std::uint64_t by_definition(const std::string& s) {
  const std::uint64_t p = (std::uint64_t{1} << 61) - 1;
  const std::uint64_t x = state_hash("\0\0", 2) - 1;
  std::uint64_t h = 0;
  for (unsigned char c : s)
    h = static_cast<std::uint64_t>((static_cast<unsigned __int128>(h) * x + c + 1u) % p);
  return h;
}

std::string random_bytes(std::size_t n, std::mt19937_64& g) {
  std::string s(n, '\0');
  for (char& c : s) c = static_cast<char>(g() & 0xff);
  return s;
}

TEST(StateHash, MatchesItsDefinition) {
  std::mt19937_64 g(7);
  for (std::size_t n : {0, 1, 7, 8, 9, 15, 16, 17, 1000}) {
    const std::string s = random_bytes(n, g);
    EXPECT_EQ(state_hash(s.data(), s.size()), by_definition(s)) << n << " bytes";
  }
}

TEST(StateHash, PiecesJoinIntoTheWhole) {
  std::mt19937_64 g(11);
  const std::string s = random_bytes(301, g);
  const std::uint64_t whole = state_hash(s.data(), s.size());
  for (std::size_t cut = 0; cut <= s.size(); ++cut) {
    const std::uint64_t a = state_hash(s.data(), cut), b = state_hash(s.data() + cut, s.size() - cut);
    ASSERT_EQ(state_hash_join(a, b, s.size() - cut), whole) << "cut at " << cut;
    ASSERT_EQ(state_hash(s.data() + cut, s.size() - cut, a), whole) << "continued at " << cut;
  }
}

TEST(StateHash, EveryOneByteChangeIsSeen) {
  std::mt19937_64 g(13);
  const std::string s = random_bytes(64, g);
  const std::uint64_t h = state_hash(s.data(), s.size());
  for (std::size_t k = 0; k < s.size(); ++k)
    for (int v = 0; v < 256; ++v) {
      if (static_cast<unsigned char>(s[k]) == v) continue;
      std::string t = s;
      t[k] = static_cast<char>(v);
      ASSERT_NE(state_hash(t.data(), t.size()), h) << "byte " << k << " set to " << v;
    }
  // Leading zero bytes count too.
  EXPECT_NE(state_hash("\0a", 2), state_hash("a", 1));
}

// A file's last 8 bytes are the hash of every byte before them.
TEST(StateHash, IsTheFilesChecksum) {
  StateWriter w;
  w.put("x", std::vector<double>{1, 2, 3});
  w.put_part("y", std::vector<std::int32_t>{4, 5});
  const std::string b = w.bytes();
  std::uint64_t sum = 0;
  std::memcpy(&sum, b.data() + b.size() - 8, 8);
  EXPECT_EQ(sum, state_hash(b.data(), b.size() - 8));
  std::string c = b;
  c[20] ^= 1;
  EXPECT_THROW(StateReader(c, "c"), StateError);
  EXPECT_NO_THROW(StateReader(b, "b"));
}

std::string reader_error(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(StateHash, ReaderOnTheDiskReadsAsOnTheBytes) {
  std::mt19937_64 g(17);
  std::vector<double> big(300000);
  for (double& v : big) v = static_cast<double>(g() % 1000003) * 0.25;
  StateWriter w;
  w.put_string("run.note", "a checkpoint");
  w.put("mpm.x", big);
  w.put("mpm.count", std::int64_t{42});
  w.put("empty", std::vector<float>{});
  const std::string bytes = w.bytes();
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "smpm_state_open";
  std::filesystem::create_directories(dir);
  auto save = [&](const std::string& name, const std::string& b) {
    std::ofstream(dir / name, std::ios::binary) << b;
    return (dir / name).string();
  };
  const std::string file = save("state.smpm", bytes);
  const StateReader disk = StateReader::open(file), mem(bytes, file);
  std::vector<double> a, b;
  disk.get("mpm.x", a);
  mem.get("mpm.x", b);
  EXPECT_TRUE(a == b && a == big);
  EXPECT_EQ(disk.get<std::int64_t>("mpm.count"), 42);
  EXPECT_EQ(disk.get_string("run.note"), "a checkpoint");
  std::vector<float> e{1.0f};
  disk.get("empty", e);
  EXPECT_TRUE(e.empty());
  EXPECT_EQ(disk.without({"mpm."}), mem.without({"mpm."}));
  // Refused alike: a flipped byte in the middle, a cut, trailing bytes; a missing file.
  std::string flipped = bytes;
  flipped[bytes.size() / 2] ^= 4;
  for (const std::string& bad :
       {flipped, bytes.substr(0, bytes.size() / 3), bytes + "x", bytes.substr(0, 10)}) {
    const std::string f = save("bad.smpm", bad);
    const std::string want = reader_error([&] { StateReader(bad, f); });
    EXPECT_FALSE(want.empty());
    EXPECT_EQ(reader_error([&] { StateReader::open(f); }), want);
  }
  EXPECT_EQ(reader_error([&] { StateReader::open((dir / "none.smpm").string()); }),
            (dir / "none.smpm").string() + ": cannot read it");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace smpm::testing
