// libFuzzer target: the ATIS .bin reader (N-MNIST, N-Caltech101) on arbitrary bytes (see fuzz_common.hpp).
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return evcorner::fuzz::run(data, size, "atis-bin");
}
