// Deterministic random numbers (initialisation, noise, test data): xoshiro256** seeded
// through splitmix64, so a seed gives the same stream on every platform and compiler
// (unlike std:: distributions).
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>

namespace nn {

class Rng {
 public:
  explicit Rng(uint64_t seed) {
    uint64_t z = seed;
    for (auto& s : s_) s = splitmix(z);
  }
  // 64 random bits.
  uint64_t next() {
    const uint64_t r = rotl(s_[1] * 5, 7) * 9;
    const uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return r;
  }
  // Uniform in [lo, hi) with 53 random bits.
  double uniform(double lo, double hi) { return lo + (hi - lo) * (static_cast<double>(next() >> 11) * 0x1.0p-53); }
  // Gaussian (Box-Muller, both values used).
  double normal(double mean, double std) {
    if (has_spare_) {
      has_spare_ = false;
      return mean + std * spare_;
    }
    double u1;
    do u1 = uniform(0.0, 1.0);
    while (u1 <= 0.0);
    const double u2 = uniform(0.0, 1.0);
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(6.283185307179586 * u2);
    has_spare_ = true;
    return mean + std * r * std::cos(6.283185307179586 * u2);
  }
  // Uniform integer in [0, n), n > 0.
  uint64_t below(uint64_t n) { return next() % n; }

  // The whole generator state (for checkpoints): the four xoshiro words, the spare Gaussian
  // as its IEEE bits, and whether the spare is pending. set_state(state()) continues the
  // stream exactly.
  struct State {
    uint64_t s[4];
    uint64_t spare_bits;
    bool has_spare;
  };
  State state() const {
    State st{{s_[0], s_[1], s_[2], s_[3]}, 0, has_spare_};
    std::memcpy(&st.spare_bits, &spare_, sizeof spare_);
    return st;
  }
  void set_state(const State& st) {
    for (int i = 0; i < 4; ++i) s_[i] = st.s[i];
    std::memcpy(&spare_, &st.spare_bits, sizeof spare_);
    has_spare_ = st.has_spare;
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  static uint64_t splitmix(uint64_t& z) {
    z += 0x9e3779b97f4a7c15ULL;
    uint64_t r = z;
    r = (r ^ (r >> 30)) * 0xbf58476d1ce4e5b9ULL;
    r = (r ^ (r >> 27)) * 0x94d049bb133111ebULL;
    return r ^ (r >> 31);
  }
  uint64_t s_[4];
  double spare_ = 0;
  bool has_spare_ = false;
};

}  // namespace nn
