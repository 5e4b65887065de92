#pragma once
// Multi-layer perceptrons, twice: a LibTorch module for training, and an Eigen mirror
// for per-step inference. A 26-32-32-6 network costs ~2k multiply-adds; a LibTorch call
// costs far more in dispatch than that, so rollouts run the Eigen copy, per environment
// on the thread stepping it (checked equal to LibTorch in tests).
#include <torch/torch.h>

#include <Eigen/Dense>
#include <string>
#include <vector>

namespace segue {

enum class Activation { Tanh, Relu };
Activation parse_activation(const std::string& name);  // throws segue::Error
std::string activation_name(Activation a);

// A tensor's values as a plain vector (any dtype, any layout), for the Eigen side and
// for reading archives.
std::vector<float> to_floats(const torch::Tensor& t);
std::vector<double> to_doubles(const torch::Tensor& t);
std::vector<int> to_ints(const torch::Tensor& t);
std::vector<int64_t> to_int64s(const torch::Tensor& t);
// And back, as int64 tensors (how archives keep integers).
torch::Tensor int64_tensor(const std::vector<int64_t>& v);
torch::Tensor int_tensor(const std::vector<int>& v);
// Text in an archive: one int64 per character.
torch::Tensor text_tensor(const std::string& s);
std::string to_text(const torch::Tensor& t);

// Linear layers in→hidden...→out, `act` between them, none after the last. Hidden layers
// get orthogonal init with gain sqrt(2); the last layer uses `out_gain` (small for a
// policy head so initial actions are near zero).
torch::nn::Sequential make_mlp(int in, const std::vector<int>& hidden, int out, Activation act,
                               double out_gain);

class EigenMlp {
 public:
  using RowMatrix = Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  EigenMlp() = default;
  // Copies the Linear layers of `net` (as built by make_mlp).
  EigenMlp(const torch::nn::Sequential& net, Activation act);
  // From plain weight tensors W_i [out, in] and biases b_i [out].
  EigenMlp(const std::vector<torch::Tensor>& weights, const std::vector<torch::Tensor>& biases,
           Activation act);
  // Each layer's output; kept between calls so a steady batch size allocates nothing.
  using Workspace = std::vector<RowMatrix>;
  // in: [batch, in_dim] row-major; out: [batch, out_dim]. `ws`: the caller's workspace,
  // for threads running one network at once (each its own); without, the network's own.
  void forward(const float* in, int batch, float* out, Workspace* ws = nullptr) const;
  int in_dim() const { return weights_.empty() ? 0 : static_cast<int>(weights_.front().cols()); }
  int out_dim() const { return weights_.empty() ? 0 : static_cast<int>(weights_.back().rows()); }
  Activation activation() const { return act_; }
  const std::vector<RowMatrix>& weights() const { return weights_; }
  const std::vector<Eigen::RowVectorXf>& biases() const { return biases_; }
  // Every weight and bias as one vector, layer by layer (W_i row-major, then b_i).
  size_t parameter_count() const;
  std::vector<float> parameters() const;
  void set_parameters(const std::vector<float>& theta);  // throws segue::Error on a size mismatch

 private:
  std::vector<RowMatrix> weights_;  // [out, in]
  std::vector<Eigen::RowVectorXf> biases_;
  Activation act_ = Activation::Tanh;
  mutable Workspace scratch_;
};

}  // namespace segue
