// Counts eFAST corners in an Event-Camera-Dataset text file ("t x y p" lines, seconds)
// with the core component alone: the umbrella header, the events parsed here.
#include <evcorner/evcorner.hpp>

#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

// "51.980788001" -> microseconds, nearest (the library's text reader rounds the same way).
static std::int64_t micros(const std::string& s) {
    const auto dot = s.find('.');
    std::int64_t ns = std::stoll(s.substr(0, dot)) * 1000000000;
    if (dot != std::string::npos) {
        std::string frac = s.substr(dot + 1, 9);
        frac.resize(9, '0');
        ns += std::stoll(frac);
    }
    return (ns + 500) / 1000;
}

int main(int argc, char** argv) {
    if (argc != 2) return 2;
    std::ifstream in(argv[1]);
    std::vector<evcorner::Event> events;
    std::string t;
    int x = 0, y = 0, p = 0;
    while (in >> t >> x >> y >> p)
        events.push_back({micros(t), static_cast<std::uint16_t>(x), static_cast<std::uint16_t>(y),
                          static_cast<std::uint8_t>(p)});
    if (!in.eof()) return 3;
    evcorner::EFast det(evcorner::kDavis240);
    std::vector<std::uint8_t> flags(events.size());
    std::printf("%zu\n", evcorner::detect(det, std::span<const evcorner::Event>(events), flags));
}
