#pragma once
/// @file SplitMix64.h
/// A tiny, fully specified pseudo-random generator (Steele, Lea & Flood 2014, "Fast splittable
/// pseudorandom number generators"). Unlike std:: distributions its output is identical on every
/// platform and standard library, so a seed reproduces the same breathing bit for bit.

#include <cstdint>

namespace pneuma::sim::pattern {

class SplitMix64 {
 public:
  /// @param seed  the stream's start; a state() passed here continues that stream exactly
  explicit SplitMix64(std::uint64_t seed = 0) : m_state(seed) {}
  /// The generator's whole state (for exact restarts).
  std::uint64_t state() const { return m_state; }

  /// Next 64 random bits.
  std::uint64_t next() {
    std::uint64_t z = (m_state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  /// Uniform double in [-1, 1) from the top 53 bits.
  double symmetric() { return static_cast<double>(next() >> 11) * 0x1.0p-52 - 1.0; }

 private:
  std::uint64_t m_state;
};

}  // namespace pneuma::sim::pattern
