// The running normaliser against statistics computed in one pass over all data.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "core/rng.h"
#include "core/error.h"
#include "core/running_mean_std.h"

namespace segue {

TEST(RunningMeanStd, BatchedUpdatesEqualWholeDataStatistics) {
  Rng rng(7);
  const int d = 3, n = 1000;
  std::vector<float> data(n * d);
  for (int i = 0; i < n; ++i) {
    data[i * d + 0] = static_cast<float>(5 + 2 * rng.normal());
    data[i * d + 1] = static_cast<float>(-1 + 0.1 * rng.normal());
    data[i * d + 2] = static_cast<float>(rng.uniform(0, 10));
  }
  RunningMeanStd rms(d);
  // Uneven batches, including a single row.
  int sizes[] = {1, 99, 400, 250, 250};
  int at = 0;
  for (int s : sizes) {
    rms.update(&data[at * d], s);
    at += s;
  }
  ASSERT_EQ(at, n);
  for (int j = 0; j < d; ++j) {
    double mean = 0, var = 0;
    for (int i = 0; i < n; ++i) mean += data[i * d + j];
    mean /= n;
    for (int i = 0; i < n; ++i) var += (data[i * d + j] - mean) * (data[i * d + j] - mean);
    var /= n;
    EXPECT_NEAR(rms.mean()[j], mean, 1e-9 * std::max(1.0, std::abs(mean)));
    EXPECT_NEAR(rms.var()[j], var, 1e-9 * std::max(1.0, var));
  }
  EXPECT_EQ(rms.count(), n);
}

TEST(RunningMeanStd, NormalizeScalesAndClips) {
  RunningMeanStd rms(2, /*clip=*/5.0, /*eps=*/0.0);
  std::vector<float> rows{0, 10, 2, 10, 4, 10};  // column 0: mean 2, var 8/3; column 1 constant
  rms.update(rows.data(), 3);
  float in[2] = {2 + 2 * std::sqrt(8.0f / 3.0f), 1000}, out[2];
  RunningMeanStd with_eps(2, 5.0, 1e-8);
  with_eps.update(rows.data(), 3);
  with_eps.normalize(in, out);
  EXPECT_NEAR(out[0], 2.0, 1e-5);   // two standard deviations
  EXPECT_FLOAT_EQ(out[1], 5.0f);    // (1000-10)/sqrt(1e-8) clipped to the bound
}

TEST(RunningMeanStd, IgnoredInputsNormaliseToZeroAndTheMaskIsSaved) {
  RunningMeanStd rms(3, /*clip=*/5.0, /*eps=*/0.0);
  rms.ignore(1, 2);
  std::vector<float> rows{0, 7, 1, 2, -3, 3, 4, 500, 5};  // columns 0 and 2: var 8/3
  rms.update(rows.data(), 3);
  float in[3] = {3, 1e6f, 5}, out[3];
  rms.normalize(in, out);
  EXPECT_NEAR(out[0], 1.0 / std::sqrt(8.0 / 3.0), 1e-6);
  EXPECT_EQ(out[1], 0.0f);             // any value of an ignored input
  EXPECT_NEAR(out[2], 2.0 / std::sqrt(8.0 / 3.0), 1e-6);
  EXPECT_EQ(rms.inv_std()[1], 0.0f);   // what an exported policy multiplies it by
  EXPECT_NEAR(rms.mean()[1], 504.0 / 3, 1e-9);  // statistics are still kept

  torch::serialize::OutputArchive ar;
  rms.save(ar, "n_");
  std::stringstream bytes;
  ar.save_to(bytes);
  torch::serialize::InputArchive back;
  back.load_from(bytes);
  RunningMeanStd loaded(3, 5.0, 0.0);  // built without a mask: the saved one is restored
  loaded.load(back, "n_");
  EXPECT_TRUE(loaded.ignored(1));
  EXPECT_FALSE(loaded.ignored(0) || loaded.ignored(2));
  float again[3];
  loaded.normalize(in, again);
  EXPECT_EQ(again[1], 0.0f);
  EXPECT_FLOAT_EQ(again[0], out[0]);
  EXPECT_THROW(rms.ignore(2, 4), Error);
}

}  // namespace segue
