#include "evcorner/sim/texture.hpp"

#include <algorithm>
#include <cmath>

#include "evcorner/sim/random.hpp"

namespace evcorner::sim {

std::vector<double> background_image(const Background& b, SensorSize size, std::uint64_t seed) {
    const std::size_t w = static_cast<std::size_t>(size.width), h = static_cast<std::size_t>(size.height);
    std::vector<double> img(w * h, b.intensity);
    if (!b.textured || b.amplitude == 0) return img;
    std::vector<double> noise(w * h, 0.0);
    double weight = 1.0, total = 0.0;
    Random rng(seed, 0x7e47);
    std::vector<std::size_t> col_cell;
    std::vector<double> col_t;
    for (int o = 0; o < b.octaves; ++o) {
        const double cell = b.scale_px / std::pow(2.0, o);
        const std::size_t gw = static_cast<std::size_t>(std::ceil(size.width / cell)) + 2;
        const std::size_t gh = static_cast<std::size_t>(std::ceil(size.height / cell)) + 2;
        std::vector<double> lattice(gw * gh);
        for (double& v : lattice) v = 2.0 * rng.uniform() - 1.0;
        // Each column's lattice cell and smoothstep weight, computed once per octave.
        col_cell.resize(w);
        col_t.resize(w);
        for (std::size_t x = 0; x < w; ++x) {
            const double fx = (static_cast<double>(x) + 0.5) / cell;
            const std::size_t ix = static_cast<std::size_t>(fx);
            const double tx = fx - static_cast<double>(ix);
            col_cell[x] = ix;
            col_t[x] = tx * tx * (3 - 2 * tx);
        }
        for (std::size_t y = 0; y < h; ++y) {
            const double fy = (static_cast<double>(y) + 0.5) / cell;
            const std::size_t iy = static_cast<std::size_t>(fy);
            double ty = fy - static_cast<double>(iy);
            ty = ty * ty * (3 - 2 * ty);
            for (std::size_t x = 0; x < w; ++x) {
                const double tx = col_t[x];
                const double* r0 = &lattice[iy * gw + col_cell[x]];
                const double* r1 = r0 + gw;
                const double top = r0[0] + (r0[1] - r0[0]) * tx, bot = r1[0] + (r1[1] - r1[0]) * tx;
                noise[y * w + x] += weight * (top + (bot - top) * ty);
            }
        }
        total += weight;
        weight /= 2;
    }
    for (std::size_t i = 0; i < img.size(); ++i) img[i] = std::clamp(b.intensity + b.amplitude * noise[i] / total, 0.0, 1.0);
    return img;
}

}  // namespace evcorner::sim
