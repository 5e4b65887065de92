#pragma once
// Backpropagation through a make_mlp network by hand: the forward pass keeps each layer's
// output, the backward pass writes every weight's and bias's gradient into its .grad().
// It reads and writes the LibTorch module's own tensors, so checkpoints, export and
// autograd elsewhere see one network. Why: on networks of
// 32 or 64 units autograd's per-operator dispatch and bookkeeping cost more than the
// arithmetic; here the matrix products go straight to BLAS and the element-wise work runs
// in Eigen (checked equal to autograd in tests; docs/speed.md has the timings).
#include <torch/torch.h>

#include <Eigen/Dense>
#include <vector>

#include "algorithms/mlp.h"

namespace segue {

class MlpBackprop {
 public:
  using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  MlpBackprop(torch::nn::Sequential net, Activation act);

  // x: [batch, in] row-major, kept by pointer until backward(). Returns the output
  // [batch, out], valid until the next forward().
  const RowMatrix& forward(const float* x, int batch);
  // dy: dL/d(output) [batch, out] of the last forward(); sets each parameter's .grad() to
  // dL/d(parameter) (overwriting it, so there is nothing to zero first). With `flat`, the
  // same gradient is written there instead, as one vector in the module's parameter order
  // (each layer's weight, row-major, then its bias), parameter_count() long.
  void backward(const RowMatrix& dy, float* flat = nullptr);
  // J v: the output's first-order change [batch, out] at the last forward()'s input when
  // the parameters move along `direction` (flat, in parameter order); J is d(output)/
  // d(parameters). With backward(dy, flat) (J^T dy) it gives Gauss-Newton and Fisher
  // products without forming J (TRPO's Fisher-vector product, algorithms/natural_gradient.h).
  const RowMatrix& jvp(const float* direction);
  int64_t parameter_count() const { return offsets_.back(); }

 private:
  // m *= act'(z) elementwise, from the activation's output h = act(z).
  void times_activation_slope(RowMatrix& m, const RowMatrix& h) const;
  std::vector<torch::nn::Linear> layers_;  // the module's own
  Activation act_;
  const float* x_ = nullptr;
  int batch_ = 0;
  std::vector<RowMatrix> out_;   // each layer's output, after its activation
  std::vector<RowMatrix> deltas_;  // dL/d(each layer's pre-activation)
  std::vector<RowMatrix> tangents_;  // jvp(): each layer's output's change
  std::vector<int64_t> offsets_;     // where each layer's weight starts in a flat vector, then the end
};

}  // namespace segue
