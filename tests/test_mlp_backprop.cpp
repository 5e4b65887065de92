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
