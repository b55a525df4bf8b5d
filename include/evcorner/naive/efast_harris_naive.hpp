#pragma once
// The eFAST -> Harris cascade written plainly from its definition, as an oracle for the
// fast path: the naive eFAST and the naive Harris each see every event; an event is a
// corner iff both say so; its score is Harris's when eFAST says corner, else NaN.

#include <limits>

#include "evcorner/event.hpp"
#include "evcorner/naive/efast_naive.hpp"
#include "evcorner/naive/harris_naive.hpp"
#include "evcorner/sensor.hpp"

namespace evcorner::naive {

class EFastHarrisNaive {
public:
    EFastHarrisNaive(SensorSize size, int window = 9, int nl = 25, double k = 0.04, double threshold = 8)
        : efast_(size), harris_(size, window, nl, k, threshold) {}

    bool process(const Event& e) {
        const bool efast = efast_.process(e);
        const bool harris = harris_.process(e);
        score_ = efast ? harris_.last_score() : std::numeric_limits<double>::quiet_NaN();
        return efast && harris;
    }
    double last_score() const { return score_; }

private:
    EFastNaive efast_;
    HarrisNaive harris_;
    double score_ = std::numeric_limits<double>::quiet_NaN();
};

}  // namespace evcorner::naive
