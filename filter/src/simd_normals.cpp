// PhiloxLanes and PredictionNormalLanes (simd_normals.hpp): Philox rounds and Box-Muller on
// Highway lanes. Every lane operation is the scalar code's IEEE operation in the same order (no
// FMA on the pinned SSE4 target), so the values are the scalar path's bit for bit.
#include "dualgrid/filter/simd_normals.hpp"

#include <algorithm>
#include <cstring>
#include <initializer_list>

#include <hwy/highway.h>

namespace dualgrid::filter::detail {

namespace hn = hwy::HWY_NAMESPACE;

namespace {

using DU = hn::ScalableTag<std::uint32_t>;
using DI = hn::RebindToSigned<DU>;
using DF = hn::RebindToFloat<DU>;
using DU64 = hn::Repartition<std::uint64_t, DU>;
using VU = hn::Vec<DU>;
using VF = hn::Vec<DF>;

constexpr std::uint32_t kPurposePredict = 10;  // RngPurpose::kFilterPredict

// 32 x 32 -> 64-bit products of every lane: low and high halves.
inline void MulHiLo(std::uint32_t m, VU x, VU& hi, VU& lo) {
  const DU du;
  const DU64 d64;
  const VU mv = hn::Set(du, m);
  const auto even = hn::MulEven(x, mv);  // lanes 0, 2
  const auto odd = hn::MulEven(hn::BitCast(du, hn::ShiftRight<32>(hn::BitCast(d64, x))), mv);
  lo = hn::OddEven(hn::BitCast(du, hn::ShiftLeft<32>(odd)), hn::BitCast(du, even));
  hi = hn::OddEven(hn::BitCast(du, odd), hn::BitCast(du, hn::ShiftRight<32>(even)));
}

// Ten Philox rounds on kU independent states x[u] = (x0, x1, x2, x3) with key (k0, k1),
// interleaved: the rounds' multiply chains of the states overlap.
constexpr int kU = 4;
inline void Rounds(std::uint32_t k0, std::uint32_t k1, VU (&x)[kU][4]) {
  const DU du;
  for (int round = 0; round < 10; ++round) {
    if (round > 0) {
      k0 += 0x9E3779B9u;
      k1 += 0xBB67AE85u;
    }
    for (int u = 0; u < kU; ++u) {
      VU hi0, lo0, hi1, lo1;
      MulHiLo(0xD2511F53u, x[u][0], hi0, lo0);
      MulHiLo(0xCD9E8D57u, x[u][2], hi1, lo1);
      x[u][0] = hn::Xor(hn::Xor(hi1, x[u][1]), hn::Set(du, k0));
      x[u][1] = lo1;
      x[u][2] = hn::Xor(hn::Xor(hi0, x[u][3]), hn::Set(du, k1));
      x[u][3] = lo0;
    }
  }
}

// 24-bit uniform in [0, 1) of each raw lane (ToUnit24).
inline VF Unit24(VU r) {
  const DF df;
  const DI di;
  return hn::Mul(hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(r))),
                 hn::Set(df, 1.0f / 16777216.0f));
}

// FastLog (fast_normal.hpp) per lane, x in (0, 1].
inline VF Log(VF x) {
  const DF df;
  const DI di;
  const auto bits = hn::BitCast(di, x);
  const auto e = hn::Sub(hn::And(hn::ShiftRight<23>(bits), hn::Set(di, 0xFF)), hn::Set(di, 127));
  const VF m =
      hn::BitCast(df, hn::Or(hn::And(bits, hn::Set(di, 0x007FFFFF)), hn::Set(di, 0x3F800000)));
  const VF one = hn::Set(df, 1.0f);
  const VF t = hn::Div(hn::Sub(m, one), hn::Add(m, one)), t2 = hn::Mul(t, t);
  constexpr float c3 = 1.0f / 3, c5 = 1.0f / 5, c7 = 1.0f / 7, c9 = 1.0f / 9;
  VF p = hn::Add(hn::Set(df, c7), hn::Mul(t2, hn::Set(df, c9)));
  p = hn::Add(hn::Set(df, c5), hn::Mul(t2, p));
  p = hn::Add(hn::Set(df, c3), hn::Mul(t2, p));
  p = hn::Add(one, hn::Mul(t2, p));
  const VF l = hn::Mul(hn::Mul(hn::Set(df, 2.0f), t), p);
  return hn::Add(hn::Mul(hn::ConvertTo(df, e), hn::Set(df, 0.69314718f)), l);
}

// FastSinCos2Pi (fast_normal.hpp) per lane, u in [0, 1).
inline void SinCos2Pi(VF u, VF& s, VF& c) {
  const DF df;
  const DI di;
  const VF x = hn::Mul(u, hn::Set(df, 4.0f));
  const auto q = hn::ConvertTo(di, x);  // truncation, x >= 0
  const VF f = hn::Mul(hn::Sub(x, hn::ConvertTo(df, q)), hn::Set(df, 1.57079632679f));
  const VF f2 = hn::Mul(f, f);
  const auto poly = [&](std::initializer_list<float> k) {  // k0 + f2 (k1 + f2 (...)), Horner
    const float* c = k.end();
    VF p = hn::Set(df, *--c);
    while (c != k.begin()) p = hn::Add(hn::Set(df, *--c), hn::Mul(f2, p));
    return p;
  };
  const VF sn = hn::Mul(f, poly({1.0f, -1.0f / 6, 1.0f / 120, -1.0f / 5040, 1.0f / 362880}));
  const VF cs = poly({1.0f, -0.5f, 1.0f / 24, -1.0f / 720, 1.0f / 40320, -1.0f / 3628800});
  const auto swap = hn::RebindMask(df, hn::Ne(hn::And(q, hn::Set(di, 1)), hn::Zero(di)));
  const VF s0 = hn::IfThenElse(swap, cs, sn), c0 = hn::IfThenElse(swap, sn, cs);
  const auto neg_s = hn::RebindMask(df, hn::Ne(hn::And(q, hn::Set(di, 2)), hn::Zero(di)));
  const auto neg_c =
      hn::RebindMask(df, hn::Ne(hn::And(hn::Add(q, hn::Set(di, 1)), hn::Set(di, 2)), hn::Zero(di)));
  s = hn::IfThenElse(neg_s, hn::Neg(s0), s0);
  c = hn::IfThenElse(neg_c, hn::Neg(c0), c0);
}

// Box-Muller per lane from the log's argument v in (0, 1]: a = r cos, b = r sin with
// r = sqrt(-2 log(v)), the angle 2 pi u2.
inline void BoxMullerOf(VF v, VF u2, VF& a, VF& b) {
  const DF df;
  const VF r = hn::Sqrt(hn::Mul(hn::Set(df, -2.0f), Log(v)));
  VF s, c;
  SinCos2Pi(u2, s, c);
  a = hn::Mul(r, c);
  b = hn::Mul(r, s);
}

// BoxMuller (fast_normal.hpp) per lane: the log of 1 - u1.
inline void BoxMuller(VF u1, VF u2, VF& a, VF& b) {
  BoxMullerOf(hn::Sub(hn::Set(DF(), 1.0f), u1), u2, a, b);
}

// Counters of kU vectors of particles from index0 on: (step lo, step hi, index, purpose|block).
inline void Counters(std::uint64_t step, std::uint32_t purpose, std::uint32_t block,
                     std::uint32_t index0, VU (&x)[kU][4]) {
  const DU du;
  const auto lanes = static_cast<std::uint32_t>(hn::Lanes(du));
  for (int u = 0; u < kU; ++u) {
    x[u][0] = hn::Set(du, static_cast<std::uint32_t>(step));
    x[u][1] = hn::Set(du, static_cast<std::uint32_t>(step >> 32));
    x[u][2] = hn::Iota(du, index0 + static_cast<std::uint32_t>(u) * lanes);
    x[u][3] = hn::Set(du, (purpose << 24) + block);
  }
}

// The first `valid` lanes of v to p (all of them with one store).
template <class D>
inline void Put(D d, hn::Vec<D> v, hn::TFromD<D>* p, std::size_t valid) {
  if (valid == hn::Lanes(d)) {
    hn::StoreU(v, d, p);
    return;
  }
  alignas(64) hn::TFromD<D> buf[HWY_MAX_BYTES / sizeof(hn::TFromD<D>)];
  hn::Store(v, d, buf);
  std::memcpy(p, buf, valid * sizeof(buf[0]));
}

// The first `valid` lanes from p, the others zero (all of them with one load).
template <class D>
inline hn::Vec<D> Get(D d, const hn::TFromD<D>* p, std::size_t valid) {
  if (valid == hn::Lanes(d)) return hn::LoadU(d, p);
  alignas(64) hn::TFromD<D> buf[HWY_MAX_BYTES / sizeof(hn::TFromD<D>)] = {};
  std::memcpy(buf, p, valid * sizeof(buf[0]));
  return hn::Load(d, buf);
}

}  // namespace

void PhiloxLanes(std::uint64_t seed, std::uint32_t purpose, std::uint64_t step, std::uint32_t first,
                 std::int64_t n, std::uint32_t block, std::uint32_t* out0, std::uint32_t* out1,
                 std::uint32_t* out2, std::uint32_t* out3) {
  const DU du;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(du));
  const auto k0 = static_cast<std::uint32_t>(seed), k1 = static_cast<std::uint32_t>(seed >> 32);
  std::uint32_t* const out[4] = {out0, out1, out2, out3};
  for (std::int64_t k = 0; k < n; k += kU * lanes) {
    VU x[kU][4];
    Counters(step, purpose, block, first + static_cast<std::uint32_t>(k), x);
    Rounds(k0, k1, x);
    for (int u = 0; u < kU; ++u) {
      const std::int64_t at = k + u * lanes;
      if (at >= n) break;
      const auto valid = static_cast<std::size_t>(std::min(lanes, n - at));
      for (int c = 0; c < 4; ++c) Put(du, x[u][c], out[c] + at, valid);
    }
  }
}

void PredictionNormalLanes(std::uint64_t seed, std::uint64_t step, std::uint32_t first,
                           std::int64_t n, float* g0, float* g1, float* g2, float* g3) {
  const DF df;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(df));
  const auto k0 = static_cast<std::uint32_t>(seed), k1 = static_cast<std::uint32_t>(seed >> 32);
  float* const g[4] = {g0, g1, g2, g3};
  for (std::int64_t k = 0; k < n; k += kU * lanes) {
    VU x[kU][4];
    Counters(step, kPurposePredict, 0, first + static_cast<std::uint32_t>(k), x);
    Rounds(k0, k1, x);
    VF out[kU][4];
    for (int u = 0; u < kU; ++u) {
      BoxMuller(Unit24(x[u][0]), Unit24(x[u][1]), out[u][0], out[u][1]);
      BoxMuller(Unit24(x[u][2]), Unit24(x[u][3]), out[u][2], out[u][3]);
    }
    for (int u = 0; u < kU; ++u) {
      const std::int64_t at = k + u * lanes;
      if (at >= n) break;
      const auto valid = static_cast<std::size_t>(std::min(lanes, n - at));
      for (int c = 0; c < 4; ++c) Put(df, out[u][c], g[c] + at, valid);
    }
  }
}

void Unit24Lanes(const std::uint32_t* r, std::int64_t n, float* out) {
  const DU du;
  const DF df;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(du));
  for (std::int64_t k = 0; k < n; k += lanes) {
    const auto valid = static_cast<std::size_t>(std::min(lanes, n - k));
    Put(df, Unit24(Get(du, r + k, valid)), out + k, valid);
  }
}

void Normal2Lanes(const std::uint32_t* r1, const std::uint32_t* r2, std::int64_t n, float* a,
                  float* b) {
  const DU du;
  const DF df;
  const DI di;
  const std::int64_t lanes = static_cast<std::int64_t>(hn::Lanes(du));
  for (std::int64_t k = 0; k < n; k += lanes) {
    const auto valid = static_cast<std::size_t>(std::min(lanes, n - k));
    // ((r1 >> 8) + 1) / 2^24: exact in float (at most 2^24 before the power-of-two scale).
    const VF m = hn::ConvertTo(df, hn::BitCast(di, hn::ShiftRight<8>(Get(du, r1 + k, valid))));
    const VF v = hn::Mul(hn::Add(m, hn::Set(df, 1.0f)), hn::Set(df, 1.0f / 16777216.0f));
    VF va, vb;
    BoxMullerOf(v, Unit24(Get(du, r2 + k, valid)), va, vb);
    Put(df, va, a + k, valid);
    Put(df, vb, b + k, valid);
  }
}

}  // namespace dualgrid::filter::detail
