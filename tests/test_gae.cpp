// GAE on a two-environment rollout, against values worked out by hand.
#include <gtest/gtest.h>

#include "algorithms/gae.h"

namespace segue {

TEST(Gae, MatchesHandComputedExample) {
  // T = 3, N = 2, gamma = 0.9, lambda = 0.8. Env 0 ends at t = 1; env 1 runs on.
  const int T = 3, N = 2;
  std::vector<float> rewards{1, 0, /*t1*/ 2, 1, /*t2*/ 0.5, 1};
  std::vector<float> values{0.5, 1, /*t1*/ 1, 2, /*t2*/ 0.25, 3};
  std::vector<uint8_t> dones{0, 0, 1, 0, 0, 0};
  std::vector<float> last{4, 5};
  std::vector<float> adv, ret;
  compute_gae(rewards, values, dones, last, T, N, 0.9, 0.8, adv, ret);
  // Env 0: t2: delta = 0.5 + 0.9*4 - 0.25 = 3.85, A = 3.85
  //        t1 (done): delta = 2 - 1 = 1, A = 1 (no bootstrap across the end)
  //        t0: delta = 1 + 0.9*1 - 0.5 = 1.4, A = 1.4 + 0.72*1 = 2.12
  // Env 1: t2: delta = 1 + 0.9*5 - 3 = 2.5, A = 2.5
  //        t1: delta = 1 + 0.9*3 - 2 = 1.7, A = 1.7 + 0.72*2.5 = 3.5
  //        t0: delta = 0 + 0.9*2 - 1 = 0.8, A = 0.8 + 0.72*3.5 = 3.32
  std::vector<float> want_adv{2.12f, 3.32f, 1.0f, 3.5f, 3.85f, 2.5f};
  for (int i = 0; i < T * N; ++i) {
    EXPECT_NEAR(adv[i], want_adv[i], 1e-5) << "index " << i;
    EXPECT_NEAR(ret[i], want_adv[i] + values[i], 1e-5) << "index " << i;
  }
}

TEST(Gae, LambdaOneGivesDiscountedReturnMinusValue) {
  // With lambda = 1 and no dones, A_t + V_t is the discounted return bootstrapped at T.
  const int T = 4, N = 1;
  std::vector<float> r{1, 2, 3, 4}, v{0.3f, -1, 2, 0.5f};
  std::vector<uint8_t> d(T, 0);
  std::vector<float> adv, ret;
  compute_gae(r, v, d, {10}, T, N, 0.5, 1.0, adv, ret);
  // G_0 = 1 + .5*2 + .25*3 + .125*4 + .0625*10 = 3.875
  EXPECT_NEAR(ret[0], 3.875, 1e-5);
  EXPECT_NEAR(ret[3], 4 + 0.5 * 10, 1e-5);
}

}  // namespace segue
