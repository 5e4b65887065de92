#pragma once
// The switch margin m: q_ab switches where Q(switch) > Q(stay) + m (the paper: m = 0).
// Where pi_ab already hands over near the best point, a learnt q_ab's estimation noise makes
// it switch early for nothing; choosing m on states of S_a held out of training keeps that
// from costing. A margin above r_s - r_f never switches before the interval's end (With TP).
#include <vector>

#include "algorithms/policy.h"
#include "hrl/switch_interval.h"

namespace segue {

struct MarginChoice {
  std::vector<double> margins, success;  // pi_b's success rate from the held-out starts, per margin
  double margin = 0;                     // the chosen one
};

// From each of S_a's states first_start.. (the held-out ones), pi_ab runs through the
// interval (its path does not depend on the margin); each margin's hand-over point is the
// first state where Q(switch) > Q(stay) + m under `q_ab` (margin 0), else the interval's
// end; pi_b is judged from each distinct point once. The chosen margin is the one with the
// highest success, the larger on ties.
MarginChoice choose_margin(SwitchInterval& interval, const Policy& q_ab, std::vector<double> margins,
                           int first_start);

}  // namespace segue
