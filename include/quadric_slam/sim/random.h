// A small, fast, seedable random generator for the simulator (SplitMix64), so that every image
// row or frame can own an independent stream derived from (seed, frame, row) and the output does
// not depend on how work is split across threads.
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>

namespace quadric_slam {

class SimRandom {
 public:
  using result_type = std::uint64_t;

  explicit SimRandom(std::uint64_t seed) : state_(seed) {}
  // A stream for (seed, a, b): well separated for neighbouring a, b.
  SimRandom(std::uint64_t seed, std::uint64_t a, std::uint64_t b)
      : state_(mix(mix(seed ^ 0x9e3779b97f4a7c15ULL) ^ mix(a + 0x632be59bd9b4e019ULL) ^
                   mix(b * 0xd1b54a32d192ed03ULL + 1))) {}

  static constexpr result_type min() { return 0; }
  static constexpr result_type max() { return std::numeric_limits<result_type>::max(); }

  result_type operator()() {
    state_ += 0x9e3779b97f4a7c15ULL;
    return mix(state_);
  }

  // Uniform in [0, 1).
  double uniform() { return static_cast<double>((*this)() >> 11) * (1.0 / 9007199254740992.0); }

  // Standard normal (Box-Muller; the second value is kept for the next call).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 1e-300)
      u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

 private:
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace quadric_slam
