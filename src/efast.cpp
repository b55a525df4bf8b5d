// The batch loop of eFAST, compiled twice: portable, and for AVX2 (chosen once at run
// time from the CPU's features). Both produce identical flags; tests hold them to the
// oracle and the goldens.

#include "evcorner/efast.hpp"

#include <cstdlib>
#include <cstring>

namespace evcorner {

namespace {

std::size_t detect_portable(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return det.run<ScalarSearch>(events, is_corner);
}

#ifdef EVCORNER_HAVE_AVX2_SEARCH
// flatten: every call inside is inlined, so the whole per-event path is compiled for
// AVX2 here and nowhere else (no AVX2 copy of a shared inline function can leak).
[[gnu::target("avx2"), gnu::flatten]] std::size_t detect_avx2(EFast& det, std::span<const Event> events,
                                                               std::span<std::uint8_t> is_corner) noexcept {
    return det.run<Avx2Search>(events, is_corner);
}
#endif

using Loop = std::size_t (*)(EFast&, std::span<const Event>, std::span<std::uint8_t>) noexcept;

struct Choice {
    Loop loop;
    const char* name;
};

Choice choose() noexcept {
    // EVCORNER_EFAST_PATH=portable forces the portable loop (to compare the two).
    const char* forced = std::getenv("EVCORNER_EFAST_PATH");
    if (forced != nullptr && std::strcmp(forced, "portable") == 0) return {detect_portable, "portable"};
#ifdef EVCORNER_HAVE_AVX2_SEARCH
    __builtin_cpu_init();
    if (__builtin_cpu_supports("avx2")) return {detect_avx2, "avx2"};
#endif
    return {detect_portable, "portable"};
}

const Choice& choice() noexcept {
    static const Choice c = choose();
    return c;
}

}  // namespace

std::size_t detect(EFast& det, std::span<const Event> events, std::span<std::uint8_t> is_corner) noexcept {
    return choice().loop(det, events, is_corner);
}

const char* efast_code_path() noexcept { return choice().name; }

}  // namespace evcorner
