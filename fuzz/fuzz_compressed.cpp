// libFuzzer target: format detection and the decompressing input (gzip, zstd, bzip2, xz)
// under the text and CSV readers, on arbitrary bytes (see fuzz_common.hpp). "auto" runs
// the whole detection: every magic of the unsupported kinds, and the text readers.
#include "fuzz_common.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    return evcorner::fuzz::run(data, size, "auto");
}
