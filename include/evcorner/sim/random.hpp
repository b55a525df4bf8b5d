#pragma once
// The simulator's random numbers: SplitMix64 (Steele, Lea, Flood 2014) and the few
// distributions it needs, written out so that a seed gives the same scene on every
// compiler and standard library (std::normal_distribution's algorithm is unspecified).

#include <cmath>
#include <cstdint>
#include <numbers>

namespace evcorner::sim {

class Random {
public:
    explicit Random(std::uint64_t seed) noexcept : state_(seed) {}
    /// An independent stream for one purpose (`salt`) of one seed.
    Random(std::uint64_t seed, std::uint64_t salt) noexcept : state_(seed ^ (salt * 0xD1B54A32D192ED03ull)) { next(); }

    std::uint64_t next() noexcept {
        std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
        z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
        z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
        return z ^ (z >> 31);
    }
    /// Skips the next n numbers (SplitMix64's state moves by a constant per number).
    void skip(std::uint64_t n) noexcept { state_ += n * 0x9E3779B97F4A7C15ull; }
    /// Uniform in [0, 1).
    double uniform() noexcept { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
    /// Uniform in (0, 1].
    double uniform_open() noexcept { return static_cast<double>((next() >> 11) + 1) * 0x1.0p-53; }
    /// Uniform integer in [0, n).
    std::uint64_t below(std::uint64_t n) noexcept { return static_cast<std::uint64_t>(uniform() * static_cast<double>(n)); }
    /// Exponential with the given mean.
    double exponential(double mean) noexcept { return -mean * std::log(uniform_open()); }
    /// Standard normal (Box-Muller, one of the pair).
    double normal() noexcept {
        return std::sqrt(-2.0 * std::log(uniform_open())) * std::cos(2.0 * std::numbers::pi * uniform());
    }

private:
    std::uint64_t state_;
};

}  // namespace evcorner::sim
