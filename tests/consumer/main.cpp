// Counts eFAST corners in an Event-Camera-Dataset text file: the installed headers and
// library, used the way a downstream project would: the detector itself, and the
// detection pipeline (which must agree).
#include <evcorner/detector.hpp>
#include <evcorner/efast.hpp>
#include <evcorner/io/open.hpp>
#include <evcorner/io/text_reader.hpp>
#include <evcorner/pipeline/detect.hpp>

#include <cstdio>
#include <vector>

int main(int argc, char** argv) {
    if (argc != 2) return 2;
    const std::vector<evcorner::Event> events = evcorner::io::read_text_file(argv[1]);
    evcorner::EFast det(evcorner::kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    const std::size_t corners = evcorner::detect(det, std::span<const evcorner::Event>(events), flags);

    const auto reader = evcorner::io::open_event_reader(argv[1]);
    evcorner::pipeline::CollectSink collect;
    evcorner::pipeline::DetectSink* sinks[] = {&collect};
    const evcorner::pipeline::DetectSummary s = evcorner::pipeline::run_detect(*reader, {}, sinks);
    if (s.corners != corners || collect.corners.size() != corners) {
        std::printf("pipeline found %llu corners, the detector %zu\n", static_cast<unsigned long long>(s.corners), corners);
        return 1;
    }
    std::printf("%zu\n", corners);
}
