#include "core/running_mean_std.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace segue {

RunningMeanStd::RunningMeanStd(int dim, double clip, double eps)
    : mean_(dim, 0.0), var_(dim, 1.0), ignored_(dim, 0), clip_(clip), eps_(eps) {
  refresh();
}

void RunningMeanStd::update(const float* rows, int64_t n, const Distributed* across) {
  if (n <= 0 && !across) return;
  const int d = dim();
  std::vector<double>& bmean = batch_mean_;
  std::vector<double>& bvar = batch_var_;
  // The batch's moments over every rank's rows: sums first, then squared deviations from
  // the common mean (two passes, as for one process).
  bmean.assign(d + 1, 0.0);
  bvar.assign(d, 0.0);
  for (int64_t r = 0; r < n; ++r)
    for (int j = 0; j < d; ++j) bmean[j] += rows[r * d + j];
  bmean[d] = double(n);
  if (across) across->sum(bmean.data(), bmean.size());
  const double count = bmean[d];
  bmean.pop_back();
  if (count <= 0) return;
  for (int j = 0; j < d; ++j) bmean[j] /= count;
  for (int64_t r = 0; r < n; ++r)
    for (int j = 0; j < d; ++j) {
      double c = rows[r * d + j] - bmean[j];
      bvar[j] += c * c;
    }
  if (across) across->sum(bvar.data(), bvar.size());
  for (int j = 0; j < d; ++j) bvar[j] /= count;
  n = int64_t(count);
  // Merge (count_, mean_, var_) with (n, bmean, bvar).
  double total = count_ + n;
  for (int j = 0; j < d; ++j) {
    double delta = bmean[j] - mean_[j];
    double m2 = var_[j] * count_ + bvar[j] * n + delta * delta * count_ * n / total;
    mean_[j] += delta * n / total;
    var_[j] = m2 / total;
  }
  count_ = total;
  refresh();
}

void RunningMeanStd::set(const std::vector<double>& mean, const std::vector<double>& var, double count) {
  if (mean.size() != mean_.size() || var.size() != var_.size()) throw Error("RunningMeanStd::set: wrong size");
  mean_ = mean;
  var_ = var;
  count_ = count;
  refresh();
}

void RunningMeanStd::ignore(int begin, int end) {
  if (begin < 0 || end > dim() || begin > end) throw Error("RunningMeanStd::ignore: range outside the input");
  std::fill(ignored_.begin() + begin, ignored_.begin() + end, 1);
  refresh();
}

void RunningMeanStd::refresh() {
  mean_f_.assign(mean_.begin(), mean_.end());
  inv_std_.resize(mean_.size());
  for (size_t j = 0; j < mean_.size(); ++j) {
    inv_std_[j] = ignored_[j] ? 0.0f : static_cast<float>(1.0 / std::sqrt(var_[j] + eps_));
    if (ignored_[j]) mean_f_[j] = 0.0f;
  }
}

void RunningMeanStd::normalize(const float* in, float* out) const {
  const float c = static_cast<float>(clip_);
  for (size_t j = 0; j < mean_f_.size(); ++j)
    out[j] = std::clamp((in[j] - mean_f_[j]) * inv_std_[j], -c, c);
}

void RunningMeanStd::save(torch::serialize::OutputArchive& ar, const std::string& p) const {
  auto opts = torch::TensorOptions().dtype(torch::kFloat64);
  ar.write(p + "mean", torch::tensor(mean_, opts));
  ar.write(p + "var", torch::tensor(var_, opts));
  ar.write(p + "count", torch::tensor({count_, clip_, eps_}, opts));
  ar.write(p + "ignored", torch::tensor(std::vector<int64_t>(ignored_.begin(), ignored_.end())));
}

void RunningMeanStd::load(torch::serialize::InputArchive& ar, const std::string& p) {
  torch::Tensor m, v, c;
  ar.read(p + "mean", m);
  ar.read(p + "var", v);
  ar.read(p + "count", c);
  mean_.assign(m.data_ptr<double>(), m.data_ptr<double>() + m.numel());
  var_.assign(v.data_ptr<double>(), v.data_ptr<double>() + v.numel());
  count_ = c[0].item<double>();
  clip_ = c[1].item<double>();
  eps_ = c[2].item<double>();
  // The saved mask joins the one this normaliser was built with (older archives have none).
  torch::Tensor ig;
  ignored_.resize(mean_.size(), 0);
  if (ar.try_read(p + "ignored", ig)) {
    if (ig.numel() != static_cast<int64_t>(mean_.size())) throw Error("RunningMeanStd::load: mask of the wrong size");
    auto v = ig.to(torch::kInt64).contiguous();
    for (int64_t j = 0; j < v.numel(); ++j) ignored_[j] |= v.data_ptr<int64_t>()[j] != 0;
  }
  refresh();
}

}  // namespace segue
