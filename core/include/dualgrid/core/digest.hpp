// A 64-bit FNV-1a digest of bytes, for content-keyed caches and determinism checks (not a
// cryptographic hash: collisions are improbable, not impossible to make on purpose).
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

namespace dualgrid {

class Fnv1a64 {
 public:
  /// Adds `bytes` to the digest (the digest of a sequence is that of its concatenation).
  void Add(std::string_view bytes) {
    for (const char c : bytes) hash_ = (hash_ ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  }
  std::uint64_t value() const { return hash_; }
  /// 16 lower-case hex digits.
  std::string Hex() const {
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash_));
    return text;
  }

 private:
  std::uint64_t hash_ = 14695981039346656037ull;
};

}  // namespace dualgrid
