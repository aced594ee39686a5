// The replay frames' compression (outputs/recording.hpp, DeflateRle, dualgrid's own run-length
// deflate encoder): one zlib stream that a plain inflater (zlib's uncompress, as the browser and
// Python read it) turns back into the same raw bytes, checksum included, for every shape of
// input (runs at the edges, runs longer than a match, many blocks, skewed byte counts that need
// length-limited codes), and no larger than zlib's own Z_RLE stream of the same bytes.
#include <zlib.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <random>
#include <vector>

#include "dualgrid/outputs/recording.hpp"

using dualgrid::outputs::replay::DeflateRle;

namespace {

// A frame-like buffer: runs of zeros (empty cells), plateaus of one value (free space at 255),
// and scrambled bytes (masses that vary cell by cell), `n` bytes long.
std::vector<std::uint8_t> FrameLike(std::size_t n) {
  std::vector<std::uint8_t> raw(n);
  std::uint32_t state = 12345u;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t block = (i / 997) % 3;
    state = state * 1664525u + 1013904223u;
    raw[i] = block == 0 ? 0 : block == 1 ? 255 : static_cast<std::uint8_t>(state >> 24);
  }
  return raw;
}

std::vector<std::uint8_t> Inflate(const std::vector<std::uint8_t>& packed, std::size_t size) {
  std::vector<std::uint8_t> raw(size + 1);  // one spare byte: a longer stream shows as size + 1
  uLongf out = raw.size();
  REQUIRE(uncompress(raw.data(), &out, packed.data(), packed.size()) == Z_OK);
  raw.resize(out);
  return raw;
}

// zlib's own stream with the run-length strategy at level 1 (what DeflateRle replaced).
std::vector<std::uint8_t> ZlibRle(const std::vector<std::uint8_t>& raw) {
  z_stream z{};
  REQUIRE(deflateInit2(&z, 1, Z_DEFLATED, 15, 8, Z_RLE) == Z_OK);
  std::vector<std::uint8_t> packed(deflateBound(&z, static_cast<uLong>(raw.size())));
  z.next_in = const_cast<Bytef*>(raw.data());
  z.avail_in = static_cast<uInt>(raw.size());
  z.next_out = packed.data();
  z.avail_out = static_cast<uInt>(packed.size());
  REQUIRE(deflate(&z, Z_FINISH) == Z_STREAM_END);
  packed.resize(z.total_out);
  deflateEnd(&z);
  return packed;
}

void CheckRoundTrip(const std::vector<std::uint8_t>& raw) {
  std::vector<std::uint8_t> packed;
  REQUIRE(DeflateRle(raw, packed));
  CHECK(Inflate(packed, raw.size()) == raw);
}

}  // namespace

TEST_CASE("a replay frame deflated with Z_RLE inflates to the same raw bytes", "[replay]") {
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{426000}}) {
    const std::vector<std::uint8_t> raw = FrameLike(n);
    std::vector<std::uint8_t> packed = {1, 2, 3};  // replaced, not appended to
    REQUIRE(DeflateRle(raw, packed));
    // A zlib header (RFC 1950): deflate with a 32 KiB window, header check bits valid.
    REQUIRE(packed.size() >= 2);
    CHECK(packed[0] == 0x78);
    CHECK((packed[0] * 256 + packed[1]) % 31 == 0);
    CHECK(Inflate(packed, n) == raw);
  }
}

TEST_CASE("the run-length strategy shrinks a frame's long runs", "[replay]") {
  // 426,000 bytes (the highway's frame) in runs of 997 equal bytes, every third run scrambled.
  const std::vector<std::uint8_t> raw = FrameLike(426000);
  std::vector<std::uint8_t> packed;
  REQUIRE(DeflateRle(raw, packed));
  // The scrambled third cannot shrink below ~1 byte a byte (142,000 bytes); each run of equal
  // bytes is one literal and matches of at most 258 bytes (a few bytes each). Without matching
  // (Huffman coding alone) the runs would cost at least 1 bit a byte: 284,000 / 8 = 35,500 bytes
  // more than the scrambled third.
  const std::size_t scrambled = 426000 / 3;
  CHECK(packed.size() < scrambled + scrambled / 10 + 284000 / 258 * 4);
  CHECK(packed.size() > scrambled * 9 / 10);  // random bytes do not compress
}

TEST_CASE("runs of every length, at the start, the middle and the end, inflate exactly",
          "[replay]") {
  // Runs of 1-600 equal bytes (matches of 3-258 bytes and their remainders), the run's byte
  // equal to or different from the one before, ending anywhere in the buffer.
  std::mt19937 rng(2026);
  for (int trial = 0; trial < 300; ++trial) {
    std::vector<std::uint8_t> raw;
    const std::size_t size = rng() % 3000;
    const int alphabet = 1 + static_cast<int>(rng() % 4);
    while (raw.size() < size) {
      const std::size_t run = 1 + rng() % (rng() % 2 ? 8 : 600);
      raw.insert(raw.end(), std::min(run, size - raw.size()),
                 static_cast<std::uint8_t>(rng() % alphabet * 85));
    }
    CheckRoundTrip(raw);
  }
}

TEST_CASE("incompressible bytes and long runs across many blocks inflate exactly", "[replay]") {
  std::mt19937 rng(7);
  std::vector<std::uint8_t> random(300000);  // ~18 blocks of literals
  for (std::uint8_t& b : random) b = static_cast<std::uint8_t>(rng());
  CheckRoundTrip(random);
  CheckRoundTrip(std::vector<std::uint8_t>(3000000, 0));   // runs of 258, checksum reductions
  CheckRoundTrip(std::vector<std::uint8_t>(100001, 255));  // a remainder of 2 bytes
  std::vector<std::uint8_t> mixed = random;                // literals, then a run, then more
  mixed.insert(mixed.end(), 70000, 7);
  mixed.insert(mixed.end(), random.begin(), random.begin() + 5000);
  CheckRoundTrip(mixed);
}

TEST_CASE("byte counts whose Huffman tree is deeper than 15 levels get limited codes", "[replay]") {
  // Byte k appears Fibonacci(k + 1) times (k = 1..18, 10,944 bytes: one block): with the end
  // of block (once) the symbols' counts are Fibonacci numbers 1, 1, 2, 3, 5, ..., which make an
  // unlimited Huffman code a chain 18 levels deep, beyond deflate's 15. Each next byte is the one
  // with the most left that differs from the one before, so no byte repeats (every byte a literal:
  // no match symbols change the counts).
  std::vector<std::size_t> left(19, 0);
  left[1] = 1;
  left[2] = 2;
  for (int k = 3; k <= 18; ++k) left[k] = left[k - 1] + left[k - 2];
  std::vector<std::uint8_t> raw;
  for (int previous = 0;;) {
    int pick = 0;
    for (int k = 1; k <= 18; ++k)
      if (k != previous && left[k] > 0 && (pick == 0 || left[k] >= left[pick])) pick = k;
    if (pick == 0) break;
    raw.push_back(static_cast<std::uint8_t>(pick));
    --left[pick];
    previous = pick;
  }
  REQUIRE(raw.size() == 10944);
  for (std::size_t i = 1; i < raw.size(); ++i) REQUIRE(raw[i] != raw[i - 1]);
  CheckRoundTrip(raw);
}

TEST_CASE("a frame packs as small as zlib's own run-length stream", "[replay]") {
  // The same tokens as zlib's Z_RLE with Huffman codes built the same way: the sizes may differ
  // by a few bytes (tie-breaks between equal counts), not by more than 0.5 %.
  const std::vector<std::uint8_t> raw = FrameLike(426000);
  std::vector<std::uint8_t> packed;
  REQUIRE(DeflateRle(raw, packed));
  const std::size_t zlib_size = ZlibRle(raw).size();
  CHECK(packed.size() <= zlib_size + zlib_size / 200);
}
