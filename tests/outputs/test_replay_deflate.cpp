// The replay frames' compression (outputs/recording.hpp, DeflateRle): one zlib stream that a
// plain inflater (zlib's uncompress, as the browser and Python read it) turns back into the same
// raw bytes, and whose run-length matching shrinks the long runs a frame is made of.
#include <zlib.h>

#include <catch2/catch.hpp>
#include <cstdint>
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
