// DeflateRle (recording.hpp): a deflate encoder (RFC 1950/1951) for the replay frames' one kind of
// match, runs of one byte (distance 1), with dynamic Huffman codes per block. It chooses the same
// tokens as zlib's Z_RLE strategy (a byte, then matches of 3-258 bytes that repeat it) and skips
// zlib's byte-by-byte scan, match bookkeeping and general window: runs are found eight bytes at
// a time. Any inflater reads its output.
#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cstdint>
#include <cstring>
#include <vector>

#include "dualgrid/outputs/recording.hpp"

namespace dualgrid::outputs::replay {

namespace {

static_assert(std::endian::native == std::endian::little, "RunLength and BitWriter read words");

constexpr int kLitLenSymbols = 286, kDistSymbols = 30, kCodeLengthSymbols = 19;
constexpr int kMaxBits = 15, kMaxCodeLengthBits = 7;
constexpr int kMinMatch = 3, kMaxMatch = 258;
/// Tokens per block, as zlib's default (memLevel 8): each block's codes follow its part of the
/// frame (velocities, particles, masses).
constexpr std::size_t kBlockTokens = 16383;
/// A token below 256 is a literal byte; from kMatch on, a run of (token - kMatch) bytes.
constexpr std::uint32_t kMatch = 256;

struct LengthCode {
  std::uint16_t symbol = 0;  ///< 257-285
  std::uint8_t extra_bits = 0;
  std::uint16_t extra = 0;
};

// RFC 1951 3.2.5: the length symbols' base lengths and extra bits.
std::array<LengthCode, kMaxMatch + 1> MakeLengthCodes() {
  constexpr std::array<int, 29> base = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                        15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                        67, 83, 99, 115, 131, 163, 195, 227, 258};
  constexpr std::array<int, 29> extra = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                         2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
  std::array<LengthCode, kMaxMatch + 1> table{};
  for (int code = 0; code < 29; ++code) {
    const int last = code + 1 < 29 ? base[code + 1] - 1 : base[code];
    for (int len = base[code]; len <= last && len <= kMaxMatch; ++len)
      table[len] = {static_cast<std::uint16_t>(257 + code), static_cast<std::uint8_t>(extra[code]),
                    static_cast<std::uint16_t>(len - base[code])};
  }
  // 258 has its own symbol (285, no extra bits), not 284 with extra 31.
  table[kMaxMatch] = {285, 0, 0};
  return table;
}

const std::array<LengthCode, kMaxMatch + 1>& LengthCodes() {
  static const std::array<LengthCode, kMaxMatch + 1> table = MakeLengthCodes();
  return table;
}

/// Huffman code lengths for `freq`, none longer than `limit` bits: a complete code over at
/// least two symbols (unused symbols get length 0; with fewer than two used, the lowest unused
/// ones join with length 1, so that every inflater accepts the code).
std::vector<std::uint8_t> CodeLengths(const std::vector<std::uint32_t>& freq, int limit) {
  const int n = static_cast<int>(freq.size());
  std::vector<std::pair<std::uint64_t, int>> leaves;  // (frequency, symbol), ascending
  for (int s = 0; s < n; ++s)
    if (freq[s] > 0) leaves.emplace_back(freq[s], s);
  for (int s = 0; s < n && leaves.size() < 2; ++s)
    if (freq[s] == 0) leaves.emplace_back(0, s);
  std::sort(leaves.begin(), leaves.end());
  const int m = static_cast<int>(leaves.size());
  // Two-queue Huffman: nodes 0..m-1 are the leaves, m.. the merged nodes in order of creation.
  std::vector<std::uint64_t> weight(2 * m - 1);
  std::vector<int> parent(2 * m - 1, -1);
  for (int i = 0; i < m; ++i) weight[i] = leaves[i].first;
  int next_leaf = 0, next_node = m;
  const auto take = [&](int created) {
    if (next_leaf < m && (next_node >= created || weight[next_leaf] <= weight[next_node]))
      return next_leaf++;
    return next_node++;
  };
  for (int created = m; created < 2 * m - 1; ++created) {
    const int a = take(created), b = take(created);
    weight[created] = weight[a] + weight[b];
    parent[a] = parent[b] = created;
  }
  std::vector<int> depth(2 * m - 1, 0);
  for (int node = 2 * m - 3; node >= 0; --node) depth[node] = depth[parent[node]] + 1;
  std::vector<int> count(m + 1, 0);  // leaves per depth
  int deepest = 0;
  for (int i = 0; i < m; ++i) {
    ++count[depth[i]];
    deepest = std::max(deepest, depth[i]);
  }
  // Length-limit the tree (JPEG, Annex K.3, Adjust_BITS): two leaves at the deepest level move
  // up, one to its parent's level and the other beside a shallower leaf that becomes their
  // parent. The code stays complete (Kraft sum 1).
  for (int i = deepest; i > limit; --i) {
    while (count[i] > 0) {
      int j = i - 2;
      while (count[j] == 0) --j;
      assert(j > 0);  // 2^limit leaves fit every alphabet used here
      count[i] -= 2;
      ++count[i - 1];
      count[j + 1] += 2;
      --count[j];
    }
  }
  // The most frequent symbols take the shortest lengths.
  std::vector<std::uint8_t> lengths(n, 0);
  int leaf = m - 1;
  for (int len = 1; len <= std::min(deepest, limit); ++len)
    for (int k = 0; k < count[len]; ++k)
      lengths[leaves[leaf--].second] = static_cast<std::uint8_t>(len);
  assert(leaf == -1);
  return lengths;
}

/// Canonical codes (RFC 1951 3.2.2) for `lengths`, bit-reversed for an LSB-first writer.
std::vector<std::uint16_t> Codes(const std::vector<std::uint8_t>& lengths) {
  std::array<int, kMaxBits + 2> count{}, next{};
  for (const std::uint8_t l : lengths) ++count[l];
  count[0] = 0;
  for (int bits = 1, code = 0; bits <= kMaxBits + 1; ++bits) {
    code = (code + count[bits - 1]) << 1;
    next[bits] = code;
  }
  std::vector<std::uint16_t> codes(lengths.size(), 0);
  for (std::size_t s = 0; s < lengths.size(); ++s) {
    const int len = lengths[s];
    if (len == 0) continue;
    int code = next[len]++, reversed = 0;
    for (int b = 0; b < len; ++b, code >>= 1) reversed = (reversed << 1) | (code & 1);
    codes[s] = static_cast<std::uint16_t>(reversed);
  }
  return codes;
}

/// Appends bits least significant first, as deflate packs them, to `out` from its current end.
/// Put writes a whole word each time without a test: Reserve room first.
class BitWriter {
 public:
  explicit BitWriter(std::vector<std::uint8_t>& out) : out_(out), at_(out.size()) {}
  /// Room for `bytes` more bytes of Put.
  void Reserve(std::size_t bytes) {
    if (at_ + bytes + 8 > out_.size()) out_.resize(std::max(2 * out_.size(), at_ + bytes + 8));
  }
  /// `count` <= 32 bits.
  void Put(std::uint32_t bits, int count) {
    acc_ |= static_cast<std::uint64_t>(bits) << filled_;
    filled_ += count;
    assert(at_ + 8 <= out_.size());
    std::memcpy(out_.data() + at_, &acc_, 8);  // little endian: the low bits first
    at_ += static_cast<std::size_t>(filled_ >> 3);
    acc_ >>= filled_ & ~7;
    filled_ &= 7;
  }
  /// Pads the last byte with zero bits and trims `out` to what was written.
  void Finish() {
    out_.resize(at_);
    if (filled_ > 0) out_.push_back(static_cast<std::uint8_t>(acc_));
    filled_ = 0;
    acc_ = 0;
  }

 private:
  std::vector<std::uint8_t>& out_;
  std::size_t at_;
  std::uint64_t acc_ = 0;
  int filled_ = 0;
};

/// Length of the run of `byte` at `p`, at most `limit` bytes, eight bytes at a time.
std::size_t RunLength(const std::uint8_t* p, std::size_t limit, std::uint8_t byte) {
  const std::uint64_t pattern = 0x0101010101010101ull * byte;
  std::size_t len = 0;
  while (len + 8 <= limit) {
    std::uint64_t word;
    std::memcpy(&word, p + len, 8);
    const std::uint64_t diff = word ^ pattern;
    if (diff != 0)
      return len + static_cast<std::size_t>(__builtin_ctzll(diff) >> 3);  // little endian
    len += 8;
  }
  while (len < limit && p[len] == byte) ++len;
  return len;
}

/// Adler-32 (RFC 1950) of the bytes the tokens stand for, summed token by token: a run of L bytes
/// `v` adds L * v to A and L * A + v * L (L + 1) / 2 to B.
class Adler32 {
 public:
  void Literals(const std::uint8_t* p, std::size_t count) {
    for (std::size_t k = 0; k < count; ++k) {
      a_ += p[k];
      b_ += a_;
    }
    Count(count);
  }
  void Run(std::uint8_t v, std::uint64_t len) {
    b_ += len * a_ + v * len * (len + 1) / 2;
    a_ += len * v;
    Count(1);
  }
  std::uint32_t Value() {
    Reduce();
    return static_cast<std::uint32_t>(b_ << 16 | a_);
  }

 private:
  static constexpr std::uint64_t kBase = 65521;
  /// Tokens between reductions (at most kWord more): A gains at most 258 * 255 a token, so it
  /// stays below 2^29, and B at most 258 * A + 255 * 258 * 259 / 2 < 2^37 a token: below 2^50.
  static constexpr std::size_t kTokensPerReduction = 4096;
  void Count(std::size_t tokens) {
    unreduced_ += tokens;
    if (unreduced_ >= kTokensPerReduction) Reduce();
  }
  void Reduce() {
    a_ %= kBase;
    b_ %= kBase;
    unreduced_ = 0;
  }
  std::uint64_t a_ = 1, b_ = 0;
  std::size_t unreduced_ = 0;
};

constexpr std::size_t kWord = 8;

std::uint64_t Word(const std::uint8_t* p) {
  std::uint64_t w;
  std::memcpy(&w, p, kWord);
  return w;
}

/// 0x80 in each byte where the words `a` and `b` hold equal bytes, 0 elsewhere (exact: no carry
/// crosses a byte).
std::uint64_t EqualBytes(std::uint64_t a, std::uint64_t b) {
  constexpr std::uint64_t kLow7 = 0x7f7f7f7f7f7f7f7full;
  const std::uint64_t x = a ^ b;
  return ~(((x & kLow7) + kLow7) | x) & ~kLow7;
}

/// Z_RLE's tokens of raw[at..], at most `capacity` (a block's; it stops up to kWord + 1 short),
/// advancing `at`: a byte that repeats the one before it at least kMinMatch times starts a match of
/// distance 1 (up to kMaxMatch bytes); every other byte is a literal. Eight positions are tested at
/// once for a match's start. Returns how many tokens were written to `tokens`.
std::size_t Tokenize(const std::vector<std::uint8_t>& raw, std::size_t& at, std::uint32_t* tokens,
                     std::size_t capacity, Adler32& adler) {
  const std::size_t n = raw.size();
  const std::uint8_t* p = raw.data();
  std::size_t i = at, count = 0;
  const auto literals = [&](std::size_t k) {
    for (std::size_t j = 0; j < k; ++j) tokens[count + j] = p[i + j];
    adler.Literals(p + i, k);
    count += k;
    i += k;
  };
  if (i == 0 && n > 0) literals(1);
  while (i < n && count + kWord + 1 <= capacity) {  // at most kWord literals and a run below
    if (i + kWord + 2 <= n) {                       // p[i - 1 .. i + 9] in bounds
      const std::uint64_t starts = EqualBytes(Word(p + i), Word(p + i - 1)) &
                                   EqualBytes(Word(p + i + 1), Word(p + i)) &
                                   EqualBytes(Word(p + i + 2), Word(p + i + 1));
      if (starts == 0) {
        literals(kWord);
        continue;
      }
      literals(static_cast<std::size_t>(__builtin_ctzll(starts)) / kWord);  // little endian
    } else if (i + kMinMatch > n || p[i] != p[i - 1] || p[i + 1] != p[i] || p[i + 2] != p[i]) {
      literals(1);
      continue;
    }
    const std::size_t run = RunLength(p + i, std::min<std::size_t>(kMaxMatch, n - i), p[i - 1]);
    assert(run >= kMinMatch);
    tokens[count++] = kMatch + static_cast<std::uint32_t>(run);
    adler.Run(p[i], run);
    i += run;
  }
  at = i;
  return count;
}

/// The code-length sequence of one block's two codes, run-length coded (RFC 1951 3.2.7): each
/// entry is a symbol 0-18 and, for 16-18, its repeat count's extra bits in the upper byte.
std::vector<std::uint16_t> CodeLengthSymbols(const std::vector<std::uint8_t>& lengths) {
  std::vector<std::uint16_t> out;
  for (std::size_t i = 0; i < lengths.size();) {
    const std::uint8_t value = lengths[i];
    std::size_t run = 1;
    while (i + run < lengths.size() && lengths[i + run] == value) ++run;
    i += run;
    if (value == 0) {
      for (; run >= 11; run -= std::min<std::size_t>(run, 138))
        out.push_back(static_cast<std::uint16_t>(18 | (std::min<std::size_t>(run, 138) - 11) << 8));
      if (run >= 3) {
        out.push_back(static_cast<std::uint16_t>(17 | (run - 3) << 8));
        run = 0;
      }
    } else {
      out.push_back(value);
      --run;
      for (; run >= 3; run -= std::min<std::size_t>(run, 6))
        out.push_back(static_cast<std::uint16_t>(16 | (std::min<std::size_t>(run, 6) - 3) << 8));
    }
    for (; run > 0; --run) out.push_back(value);
  }
  return out;
}

/// Writes one block of dynamic codes: header, code tables, tokens, end of block.
/// Writes one block's header: the two codes' lengths, themselves Huffman coded.
void WriteCodes(const std::vector<std::uint8_t>& lit_len, const std::vector<std::uint8_t>& dist_len,
                bool last, BitWriter& bits) {
  int hlit = kLitLenSymbols, hdist = kDistSymbols;
  while (hlit > 257 && lit_len[hlit - 1] == 0) --hlit;
  while (hdist > 1 && dist_len[hdist - 1] == 0) --hdist;
  std::vector<std::uint8_t> all(lit_len.begin(), lit_len.begin() + hlit);
  all.insert(all.end(), dist_len.begin(), dist_len.begin() + hdist);
  const std::vector<std::uint16_t> cl_symbols = CodeLengthSymbols(all);
  std::vector<std::uint32_t> cl_freq(kCodeLengthSymbols, 0);
  for (const std::uint16_t s : cl_symbols) ++cl_freq[s & 0xff];
  const std::vector<std::uint8_t> cl_len = CodeLengths(cl_freq, kMaxCodeLengthBits);
  const std::vector<std::uint16_t> cl_code = Codes(cl_len);
  constexpr std::array<int, kCodeLengthSymbols> order = {16, 17, 18, 0, 8,  7, 9,  6, 10, 5,
                                                         11, 4,  12, 3, 13, 2, 14, 1, 15};
  int hclen = kCodeLengthSymbols;
  while (hclen > 4 && cl_len[order[hclen - 1]] == 0) --hclen;
  bits.Put(last ? 1 : 0, 1);
  bits.Put(2, 2);  // dynamic Huffman codes
  bits.Put(hlit - 257, 5);
  bits.Put(hdist - 1, 5);
  bits.Put(hclen - 4, 4);
  for (int k = 0; k < hclen; ++k) bits.Put(cl_len[order[k]], 3);
  constexpr std::array<int, 3> repeat_bits = {2, 3, 7};  // symbols 16, 17, 18
  for (const std::uint16_t s : cl_symbols) {
    const int symbol = s & 0xff;
    bits.Put(cl_code[symbol], cl_len[symbol]);
    if (symbol >= 16) bits.Put(s >> 8, repeat_bits[symbol - 16]);
  }
}

/// Tokens 0-255 (literals) and kMatch + 3 .. kMatch + 258 (runs) index one table.
constexpr std::size_t kTokenKinds = kMatch + kMaxMatch + 1;

/// Each token's literal/length symbol.
const std::array<std::uint16_t, kTokenKinds>& TokenSymbols() {
  static const std::array<std::uint16_t, kTokenKinds> table = [] {
    std::array<std::uint16_t, kTokenKinds> t{};
    for (std::uint32_t k = 0; k < kMatch; ++k) t[k] = static_cast<std::uint16_t>(k);
    for (int len = kMinMatch; len <= kMaxMatch; ++len) t[kMatch + len] = LengthCodes()[len].symbol;
    return t;
  }();
  return table;
}

/// Writes one block of dynamic codes: header, code tables, tokens, end of block.
void WriteBlock(const std::uint32_t* tokens, std::size_t count, bool last, BitWriter& bits) {
  const auto& length_codes = LengthCodes();
  const auto& symbols = TokenSymbols();
  std::vector<std::uint32_t> lit_freq(kLitLenSymbols, 0), dist_freq(kDistSymbols, 0);
  for (std::size_t t = 0; t < count; ++t) ++lit_freq[symbols[tokens[t]]];
  ++lit_freq[256];   // end of block
  dist_freq[0] = 1;  // distance 1 only; with CodeLengths' second symbol, a complete code
  const std::vector<std::uint8_t> lit_len = CodeLengths(lit_freq, kMaxBits);
  const std::vector<std::uint8_t> dist_len = CodeLengths(dist_freq, kMaxBits);
  // Header <= 17 + 19 * 3 + 316 * 14 bits; a token <= 15 + 5 + 15 bits; end of block.
  bits.Reserve(700 + 5 * count + 2);
  WriteCodes(lit_len, dist_len, last, bits);
  // Each token's bits: a literal's code, or a run's symbol, extra bits and distance code.
  const std::vector<std::uint16_t> lit_code = Codes(lit_len), dist_code = Codes(dist_len);
  std::array<std::uint32_t, kTokenKinds> token_bits{};
  std::array<std::uint8_t, kTokenKinds> token_count{};
  for (std::uint32_t k = 0; k < kMatch; ++k) {
    token_bits[k] = lit_code[k];
    token_count[k] = lit_len[k];
  }
  for (int len = kMinMatch; len <= kMaxMatch; ++len) {
    const LengthCode& lc = length_codes[len];
    const int symbol_bits = lit_len[lc.symbol];
    token_bits[kMatch + len] = lit_code[lc.symbol] | std::uint32_t{lc.extra} << symbol_bits |
                               std::uint32_t{dist_code[0]} << (symbol_bits + lc.extra_bits);
    token_count[kMatch + len] =
        static_cast<std::uint8_t>(symbol_bits + lc.extra_bits + dist_len[0]);
  }
  for (std::size_t t = 0; t < count; ++t) bits.Put(token_bits[tokens[t]], token_count[tokens[t]]);
  bits.Put(lit_code[256], lit_len[256]);
}

}  // namespace

bool DeflateRle(const std::vector<std::uint8_t>& raw, std::vector<std::uint8_t>& packed) {
  if (raw.size() > UINT32_MAX) return false;  // a frame is at most 1 GiB (the reader's bound)
  // RFC 1950 header: deflate with a 32 KiB window (CMF 0x78), no dictionary, "fastest"
  // compression level (FLEVEL 0), check bits making the pair a multiple of 31.
  packed.assign({0x78, 0x01});
  BitWriter bits(packed);
  Adler32 adler;
  std::array<std::uint32_t, kBlockTokens> tokens;  // one block's, tokenized as it is written
  std::size_t at = 0;
  do {
    const std::size_t count = Tokenize(raw, at, tokens.data(), tokens.size(), adler);
    WriteBlock(tokens.data(), count, at == raw.size(), bits);
  } while (at < raw.size());
  bits.Finish();
  const std::uint32_t checksum = adler.Value();
  for (int shift = 24; shift >= 0; shift -= 8)
    packed.push_back(static_cast<std::uint8_t>(checksum >> shift));
  return true;
}

}  // namespace dualgrid::outputs::replay
