#pragma once
// evcorner's vector code paths (AVX2, AVX-512) on x86-64 with GCC or Clang: the
// instruction sets each is compiled for, and whether this CPU runs it. A detector's batch
// loop (and NMS's neighbourhood test) is compiled once per path (gnu::target) and chosen
// at run time from these; the portable path runs everywhere.

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define EVCORNER_HAVE_AVX2_SEARCH 1
/// The instruction sets every AVX-512 path is compiled for (any CPU with the four AVX-512
/// subsets cpu_runs_avx512() asks for has the others).
#define EVCORNER_AVX512_TARGET "avx512f,avx512vl,avx512bw,avx512dq,avx2,bmi,bmi2,popcnt,lzcnt"
/// Around AVX-512 code: GCC 12 warns that the intrinsics' undefined operands
/// (_mm512_undefined_epi32: a masked operation's pass-through, a cast's upper half) are used
/// uninitialised once inlined; they are never read (all-ones masks) or are overwritten.
#if defined(__clang__)
#define EVCORNER_AVX512_WARNINGS_OFF \
    _Pragma("GCC diagnostic push") _Pragma("GCC diagnostic ignored \"-Wuninitialized\"")
#else
#define EVCORNER_AVX512_WARNINGS_OFF                                                   \
    _Pragma("GCC diagnostic push") _Pragma("GCC diagnostic ignored \"-Wuninitialized\"") \
        _Pragma("GCC diagnostic ignored \"-Wmaybe-uninitialized\"")
#endif
#define EVCORNER_AVX512_WARNINGS_ON _Pragma("GCC diagnostic pop")
#endif

#include <cstdlib>
#include <cstring>
#include <vector>

namespace evcorner {

/// Whether this CPU runs the AVX-512 paths: AVX-512 F, VL, BW and DQ (false off x86-64).
inline bool cpu_runs_avx512() noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
           __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#else
    return false;
#endif
}

/// Whether this CPU runs the AVX2 paths (false off x86-64).
inline bool cpu_runs_avx2() noexcept {
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2");
#else
    return false;
#endif
}

/// A code path of a loop compiled several times: its name ("avx512", "avx2", "portable")
/// and its entry point.
template <class Fn>
struct CodePath {
    const char* name;
    Fn fn;
};

/// The paths of a loop this CPU runs, fastest first: `avx512` and `avx2` where the CPU
/// runs them (and the build has them), `portable` always.
template <class Fn>
std::vector<CodePath<Fn>> runnable_paths([[maybe_unused]] Fn avx512, [[maybe_unused]] Fn avx2, Fn portable) {
    std::vector<CodePath<Fn>> paths;
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    if (cpu_runs_avx512()) paths.push_back({"avx512", avx512});
    if (cpu_runs_avx2()) paths.push_back({"avx2", avx2});
#endif
    paths.push_back({"portable", portable});
    return paths;
}

/// The path that environment variable `env` names (EVCORNER_EFAST_PATH=portable, ...) among
/// `paths`, those this CPU runs, fastest first, each with a `name`; the fastest when `env`
/// is unset or names none of them.
template <class Path>
const Path& forced_or_fastest(const std::vector<Path>& paths, const char* env) noexcept {
    if (const char* forced = std::getenv(env))
        for (const Path& p : paths)
            if (std::strcmp(forced, p.name) == 0) return p;
    return paths.front();
}

}  // namespace evcorner
