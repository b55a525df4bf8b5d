// Counts eFAST corners in an Event-Camera-Dataset text file: the installed headers and
// library, used the way a downstream project would.
#include <evcorner/detector.hpp>
#include <evcorner/efast.hpp>
#include <evcorner/io/text_reader.hpp>

#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 2) return 2;
    const std::vector<evcorner::Event> events = evcorner::io::read_text_file(argv[1]);
    evcorner::EFast det(evcorner::kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    std::printf("%zu\n", evcorner::detect(det, std::span<const evcorner::Event>(events), flags));
}
