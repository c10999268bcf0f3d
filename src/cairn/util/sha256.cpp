#include "cairn/util/sha256.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace cairn {

namespace {

using u32 = std::uint32_t;

/// The first 32 bits of the fractional part of x (FIPS 180-4 Sec. 4.2.2 and 5.3.3 define the
/// constants this way from square and cube roots of the first primes).
u32 fraction_bits(long double x) {
  const long double frac = x - std::floor(x);
  return static_cast<u32>(std::floor(std::ldexp(frac, 32)));
}

struct Constants {
  std::array<u32, 64> k{};
  std::array<u32, 8> h0{};
  Constants() {
    int found = 0;
    for (int p = 2; found < 64; ++p) {
      bool prime = true;
      for (int d = 2; d * d <= p; ++d) prime = prime && p % d != 0;
      if (!prime) continue;
      k[found] = fraction_bits(std::cbrt(static_cast<long double>(p)));
      if (found < 8) h0[found] = fraction_bits(std::sqrt(static_cast<long double>(p)));
      ++found;
    }
  }
};

u32 rotr(u32 x, int n) { return (x >> n) | (x << (32 - n)); }

}  // namespace

std::string sha256_hex(std::string_view data) {
  static const Constants c;
  // Padding (Sec. 5.1.1): a 1 bit, zeros, and the message length in bits as 64-bit big endian.
  std::vector<unsigned char> msg(data.begin(), data.end());
  const std::uint64_t bits = static_cast<std::uint64_t>(data.size()) * 8;
  msg.push_back(0x80);
  while (msg.size() % 64 != 56) msg.push_back(0);
  for (int i = 7; i >= 0; --i) msg.push_back(static_cast<unsigned char>(bits >> (8 * i)));

  std::array<u32, 8> h = c.h0;
  std::array<u32, 64> w{};
  for (std::size_t block = 0; block < msg.size(); block += 64) {
    // Message schedule and compression (Sec. 6.2.2).
    for (int t = 0; t < 16; ++t) {
      const unsigned char* b = &msg[block + 4 * static_cast<std::size_t>(t)];
      w[t] = (u32(b[0]) << 24) | (u32(b[1]) << 16) | (u32(b[2]) << 8) | u32(b[3]);
    }
    for (int t = 16; t < 64; ++t) {
      const u32 s0 = rotr(w[t - 15], 7) ^ rotr(w[t - 15], 18) ^ (w[t - 15] >> 3);
      const u32 s1 = rotr(w[t - 2], 17) ^ rotr(w[t - 2], 19) ^ (w[t - 2] >> 10);
      w[t] = w[t - 16] + s0 + w[t - 7] + s1;
    }
    u32 a = h[0], b = h[1], cc = h[2], d = h[3], e = h[4], f = h[5], g = h[6], hh = h[7];
    for (int t = 0; t < 64; ++t) {
      const u32 t1 = hh + (rotr(e, 6) ^ rotr(e, 11) ^ rotr(e, 25)) + ((e & f) ^ (~e & g)) + c.k[t] + w[t];
      const u32 t2 = (rotr(a, 2) ^ rotr(a, 13) ^ rotr(a, 22)) + ((a & b) ^ (a & cc) ^ (b & cc));
      hh = g;
      g = f;
      f = e;
      e = d + t1;
      d = cc;
      cc = b;
      b = a;
      a = t1 + t2;
    }
    h[0] += a; h[1] += b; h[2] += cc; h[3] += d; h[4] += e; h[5] += f; h[6] += g; h[7] += hh;
  }
  static const char* hex = "0123456789abcdef";
  std::string out;
  for (u32 word : h)
    for (int i = 7; i >= 0; --i) out += hex[(word >> (4 * i)) & 0xf];
  return out;
}

}  // namespace cairn
