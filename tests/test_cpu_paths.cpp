// How a loop compiled several times picks its code path (cpu_paths.hpp): the paths this CPU
// runs, fastest first, and the one an EVCORNER_*_PATH variable names, else the fastest.
// Every detector with several paths picks through these two (eFAST, Arc*, FA-Harris, the
// event check).

#include <gtest/gtest.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "evcorner/arcstar.hpp"
#include "evcorner/cpu_paths.hpp"
#include "evcorner/efast.hpp"

namespace evcorner {
namespace {

constexpr const char* kVar = "EVCORNER_TEST_ONLY_PATH";

// Sets kVar for the scope (unset when `value` is null), and unsets it afterwards.
struct ScopedVar {
    explicit ScopedVar(const char* value) {
        if (value) ::setenv(kVar, value, 1);
        else ::unsetenv(kVar);
    }
    ~ScopedVar() { ::unsetenv(kVar); }
};

const std::vector<CodePath<int>> kThree{{"avx512", 1}, {"avx2", 2}, {"portable", 3}};

TEST(CpuPaths, TheVariableNamesAPath) {
    for (const CodePath<int>& p : kThree) {
        ScopedVar v(p.name);
        EXPECT_EQ(forced_or_fastest(kThree, kVar).fn, p.fn) << p.name;
    }
}

TEST(CpuPaths, UnsetOrUnknownTakesTheFastest) {
    {
        ScopedVar v(nullptr);
        EXPECT_EQ(forced_or_fastest(kThree, kVar).fn, 1);
    }
    for (const char* other : {"", "AVX2", "avx-2", "scalar", "avx512 "}) {
        ScopedVar v(other);
        EXPECT_EQ(forced_or_fastest(kThree, kVar).fn, 1) << "'" << other << "'";
    }
    // A path this CPU does not run is not in the list: the fastest of those it runs.
    const std::vector<CodePath<int>> no_avx512{{"avx2", 2}, {"portable", 3}};
    ScopedVar v("avx512");
    EXPECT_EQ(forced_or_fastest(no_avx512, kVar).fn, 2);
}

TEST(CpuPaths, RunnablePathsFastestFirstPortableLast) {
    const std::vector<CodePath<int>> paths = runnable_paths(1, 2, 3);
    std::vector<std::string> names;
    for (const CodePath<int>& p : paths) names.emplace_back(p.name);
    std::vector<std::string> expected;
    if (cpu_runs_avx512()) expected.emplace_back("avx512");
    if (cpu_runs_avx2()) expected.emplace_back("avx2");
    expected.emplace_back("portable");
    EXPECT_EQ(names, expected);
    for (const CodePath<int>& p : paths)
        EXPECT_EQ(p.fn, std::string(p.name) == "avx512" ? 1 : std::string(p.name) == "avx2" ? 2 : 3) << p.name;
}

// The detectors' own choice in this process. CTest runs every test in a process of its
// own; without EVCORNER_EFAST_PATH and EVCORNER_ARCSTAR_PATH set, both take the fastest.
TEST(CpuPaths, TheDetectorsTakeTheFastestUnlessForced) {
    const std::string fastest = runnable_paths(1, 2, 3).front().name;
    if (std::getenv("EVCORNER_EFAST_PATH") == nullptr) {
        EXPECT_EQ(std::string(efast_code_path()), fastest);
    }
    if (std::getenv("EVCORNER_ARCSTAR_PATH") == nullptr) {
        EXPECT_EQ(std::string(arcstar_code_path()), fastest);
    }
}

}  // namespace
}  // namespace evcorner
