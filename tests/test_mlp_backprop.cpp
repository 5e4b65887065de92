// Backpropagation by hand (algorithms/mlp_backprop.h) and the hand-written optimiser step
// (algorithms/optimizer_step.h) against LibTorch's autograd, clip_grad_norm_ and Adam.
#include <gtest/gtest.h>

#include "algorithms/mlp.h"
#include "algorithms/mlp_backprop.h"
#include "algorithms/optimizer_step.h"

namespace segue {
namespace {

double max_difference(const torch::Tensor& a, const torch::Tensor& b) { return (a - b).abs().max().item<double>(); }

std::vector<torch::Tensor> clones(const std::vector<torch::Tensor>& ts) {
  std::vector<torch::Tensor> out;
  for (const auto& t : ts) out.push_back(t.detach().clone());
  return out;
}

}  // namespace

TEST(MlpBackprop, ForwardAndGradientsEqualAutograd) {
  for (Activation act : {Activation::Tanh, Activation::Relu}) {
    torch::manual_seed(7);
    auto net = make_mlp(5, {7, 4}, 3, act, 1.0);
    auto x = torch::randn({6, 5}), dy = torch::randn({6, 3});
    MlpBackprop backprop(net, act);
    const auto& y = backprop.forward(x.data_ptr<float>(), 6);
    auto want_y = net->forward(x);
    EXPECT_LT(max_difference(torch::from_blob(const_cast<float*>(y.data()), {6, 3}), want_y), 1e-6);
    (want_y * dy).sum().backward();
    const std::vector<torch::Tensor> autograd = clones([&] {
      std::vector<torch::Tensor> g;
      for (const auto& p : net->parameters()) g.push_back(p.grad());
      return g;
    }());
    for (auto& p : net->parameters()) p.mutable_grad().fill_(123.0f);  // overwritten, not added to
    backprop.backward(Eigen::Map<const MlpBackprop::RowMatrix>(dy.data_ptr<float>(), 6, 3));
    const auto params = net->parameters();
    ASSERT_EQ(params.size(), autograd.size());
    for (size_t i = 0; i < params.size(); ++i)
      EXPECT_LT(max_difference(params[i].grad(), autograd[i]), 1e-5) << activation_name(act) << " parameter " << i;
  }
}

TEST(MlpBackprop, DirectionalDerivativeByFiniteDifferencesAndTheFlatGradient) {
  torch::manual_seed(8);
  auto net = make_mlp(5, {7, 4}, 3, Activation::Tanh, 1.0);
  auto x = torch::randn({6, 5}), dy = torch::randn({6, 3});
  MlpBackprop backprop(net, Activation::Tanh);
  std::vector<torch::Tensor> params = net->parameters();
  int64_t count = 0;
  for (const auto& p : params) count += p.numel();
  ASSERT_EQ(backprop.parameter_count(), count);
  auto v = torch::randn({count});
  backprop.forward(x.data_ptr<float>(), 6);
  const MlpBackprop::RowMatrix jv = backprop.jvp(v.data_ptr<float>());
  // (f(theta + eps v) - f(theta - eps v)) / (2 eps), in double.
  net->to(torch::kFloat64);
  auto theta = torch::cat([&] {
    std::vector<torch::Tensor> flat;
    for (const auto& p : net->parameters()) flat.push_back(p.detach().reshape(-1).clone());
    return flat;
  }());
  auto output_at = [&](const torch::Tensor& at) {
    torch::NoGradGuard no_grad;
    int64_t k = 0;
    for (auto& p : net->parameters()) p.copy_(at.slice(0, k, k + p.numel()).view_as(p)), k += p.numel();
    return net->forward(x.to(torch::kFloat64));
  };
  const double eps = 1e-4;
  auto v64 = v.to(torch::kFloat64);
  auto fd = (output_at(theta + eps * v64) - output_at(theta - eps * v64)) / (2 * eps);
  output_at(theta);
  net->to(torch::kFloat32);
  auto got = torch::from_blob(const_cast<float*>(jv.data()), {6, 3}).to(torch::kFloat64);
  EXPECT_LT(max_difference(got, fd), 1e-4 * std::max(1.0, fd.abs().max().item<double>())) << got << fd;
  // backward(dy, flat) is backward(dy)'s gradients laid end to end (to rounding: Eigen may
  // vectorise a sum differently into another address).
  MlpBackprop again(net, Activation::Tanh);
  again.forward(x.data_ptr<float>(), 6);
  std::vector<float> flat(count);
  const MlpBackprop::RowMatrix g = Eigen::Map<const MlpBackprop::RowMatrix>(dy.data_ptr<float>(), 6, 3);
  again.backward(g, flat.data());
  again.backward(g);
  std::vector<torch::Tensor> grads;
  for (const auto& p : net->parameters()) grads.push_back(p.grad().reshape(-1));
  EXPECT_LT(max_difference(torch::tensor(flat), torch::cat(grads)), 1e-6);  // the same sums, rounded alike
}

TEST(OptimizerStep, ClipGradNormAsLibTorch) {
  for (double max_norm : {0.5, 100.0}) {  // scaled down, and left alone
    torch::manual_seed(1);
    std::vector<torch::Tensor> a{torch::zeros({3, 4}, torch::requires_grad()), torch::zeros({5}, torch::requires_grad())};
    for (auto& p : a) p.mutable_grad() = torch::randn(p.sizes());
    std::vector<torch::Tensor> b = clones(a);
    for (size_t i = 0; i < a.size(); ++i) b[i].requires_grad_(), b[i].mutable_grad() = a[i].grad().clone();
    const double norm = clip_grad_norm(a, max_norm);
    EXPECT_NEAR(norm, torch::nn::utils::clip_grad_norm_(b, max_norm), 1e-5);
    for (size_t i = 0; i < a.size(); ++i) EXPECT_LT(max_difference(a[i].grad(), b[i].grad()), 1e-7);
  }
}

TEST(OptimizerStep, AdamAsLibTorchAndSharesItsState) {
  // The same gradients through adam_step and through Adam::step: the parameters agree
  // step by step, and LibTorch's step continues from the state adam_step left (so a
  // checkpoint's optimiser state means the same to either).
  torch::manual_seed(2);
  std::vector<torch::Tensor> mine{torch::randn({4, 3}).requires_grad_(), torch::randn({3}).requires_grad_()};
  std::vector<torch::Tensor> theirs = clones(mine);
  for (auto& p : theirs) p.requires_grad_();
  const std::vector<torch::Tensor> initial = clones(mine);
  const auto options = torch::optim::AdamOptions(3e-2).eps(1e-5);
  torch::optim::Adam adam_mine(mine, options), adam_theirs(theirs, options);
  for (int step = 0; step < 6; ++step) {
    for (size_t i = 0; i < mine.size(); ++i) {
      auto g = torch::randn(mine[i].sizes());
      mine[i].mutable_grad() = g.clone(), theirs[i].mutable_grad() = g.clone();
    }
    if (step < 4) adam_step(adam_mine);
    else adam_mine.step();
    adam_theirs.step();
    for (size_t i = 0; i < mine.size(); ++i)
      EXPECT_LT(max_difference(mine[i], theirs[i]), 1e-6) << "step " << step << " parameter " << i;
  }
  // The steps moved the parameters (by about lr each): the comparison compared something.
  EXPECT_GT(max_difference(mine[0], initial[0]), 0.05);
}

TEST(OptimizerStep, AdamRefusesWhatItDoesNotImplement) {
  std::vector<torch::Tensor> p{torch::zeros({2}, torch::requires_grad())};
  p[0].mutable_grad() = torch::ones({2});
  torch::optim::Adam decayed(p, torch::optim::AdamOptions(1e-3).weight_decay(0.1));
  EXPECT_THROW(adam_step(decayed), std::exception);
}

}  // namespace segue
