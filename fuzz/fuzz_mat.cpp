// libFuzzer target: the MATLAB .mat reader on arbitrary bytes (see fuzz_common.hpp). libmatio
// opens files by path only, so the bytes go through the temporary file like every target's.
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return evcorner::fuzz::run(data, size, "mat");
}
