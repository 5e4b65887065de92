#include "algorithms/mlp.h"

#include <cmath>

#include "core/error.h"

namespace segue {

Activation parse_activation(const std::string& name) {
  if (name == "tanh") return Activation::Tanh;
  if (name == "relu") return Activation::Relu;
  throw Error("unknown activation '" + name + "' (known: tanh, relu)");
}

std::string activation_name(Activation a) { return a == Activation::Tanh ? "tanh" : "relu"; }

namespace {
template <class T, class Stored>
std::vector<T> to_vector(const torch::Tensor& t, torch::ScalarType dtype) {
  auto c = t.detach().to(dtype).contiguous();
  return std::vector<T>(c.data_ptr<Stored>(), c.data_ptr<Stored>() + c.numel());
}
}  // namespace

std::vector<float> to_floats(const torch::Tensor& t) { return to_vector<float, float>(t, torch::kFloat32); }
std::vector<double> to_doubles(const torch::Tensor& t) { return to_vector<double, double>(t, torch::kFloat64); }
std::vector<int> to_ints(const torch::Tensor& t) { return to_vector<int, int64_t>(t, torch::kLong); }
torch::Tensor int64_tensor(const std::vector<int64_t>& v) { return torch::tensor(v, torch::kLong); }
torch::Tensor int_tensor(const std::vector<int>& v) { return int64_tensor({v.begin(), v.end()}); }
std::vector<int64_t> to_int64s(const torch::Tensor& t) { return to_vector<int64_t, int64_t>(t, torch::kLong); }

torch::Tensor text_tensor(const std::string& s) {
  return torch::tensor(std::vector<int64_t>(s.begin(), s.end()), torch::kLong);
}

std::string to_text(const torch::Tensor& t) {
  std::vector<int64_t> c = to_int64s(t);
  return std::string(c.begin(), c.end());
}

torch::nn::Sequential make_mlp(int in, const std::vector<int>& hidden, int out, Activation act,
                               double out_gain) {
  torch::nn::Sequential net;
  int width = in;
  auto add_linear = [&](int to, double gain) {
    torch::nn::Linear layer(width, to);
    torch::NoGradGuard no_grad;
    torch::nn::init::orthogonal_(layer->weight, gain);
    layer->bias.zero_();
    net->push_back(layer);
    width = to;
  };
  for (int h : hidden) {
    add_linear(h, std::sqrt(2.0));
    if (act == Activation::Tanh) net->push_back(torch::nn::Tanh());
    else net->push_back(torch::nn::ReLU());
  }
  add_linear(out, out_gain);
  return net;
}

EigenMlp::EigenMlp(const torch::nn::Sequential& net, Activation act) : act_(act) {
  for (const auto& module : net->children()) {
    if (auto* linear = module->as<torch::nn::Linear>()) {
      auto w = linear->weight.detach().to(torch::kFloat32).contiguous();
      auto b = linear->bias.detach().to(torch::kFloat32).contiguous();
      weights_.emplace_back(Eigen::Map<const RowMatrix>(w.data_ptr<float>(), w.size(0), w.size(1)));
      biases_.emplace_back(Eigen::Map<const Eigen::RowVectorXf>(b.data_ptr<float>(), b.size(0)));
    }
  }
}

EigenMlp::EigenMlp(const std::vector<torch::Tensor>& ws, const std::vector<torch::Tensor>& bs,
                   Activation act)
    : act_(act) {
  for (size_t i = 0; i < ws.size(); ++i) {
    auto w = ws[i].detach().to(torch::kFloat32).contiguous();
    auto b = bs[i].detach().to(torch::kFloat32).contiguous();
    if (w.dim() != 2 || b.dim() != 1 || b.size(0) != w.size(0) ||
        (i > 0 && w.size(1) != ws[i - 1].size(0)))
      throw Error("layer " + std::to_string(i) + " has inconsistent weight shapes");
    weights_.emplace_back(Eigen::Map<const RowMatrix>(w.data_ptr<float>(), w.size(0), w.size(1)));
    biases_.emplace_back(Eigen::Map<const Eigen::RowVectorXf>(b.data_ptr<float>(), b.size(0)));
  }
}

void EigenMlp::forward(const float* in, int batch, float* out, Workspace* ws) const {
  Workspace& layers = ws ? *ws : scratch_;
  layers.resize(weights_.size());
  Eigen::Map<const RowMatrix> x(in, batch, in_dim());
  for (size_t i = 0; i < weights_.size(); ++i) {
    RowMatrix& y = layers[i];
    y.resize(batch, weights_[i].rows());  // no-op once the batch size is settled
    if (i == 0) y.noalias() = x * weights_[i].transpose();
    else y.noalias() = layers[i - 1] * weights_[i].transpose();
    y.rowwise() += biases_[i];
    if (i + 1 < weights_.size()) {
      if (act_ == Activation::Tanh) y = y.array().tanh();
      else y = y.array().max(0.0f);
    }
  }
  Eigen::Map<RowMatrix>(out, batch, out_dim()) = layers.back();
}

size_t EigenMlp::parameter_count() const {
  size_t n = 0;
  for (size_t i = 0; i < weights_.size(); ++i) n += weights_[i].size() + biases_[i].size();
  return n;
}

std::vector<float> EigenMlp::parameters() const {
  std::vector<float> theta;
  theta.reserve(parameter_count());
  for (size_t i = 0; i < weights_.size(); ++i) {
    theta.insert(theta.end(), weights_[i].data(), weights_[i].data() + weights_[i].size());
    theta.insert(theta.end(), biases_[i].data(), biases_[i].data() + biases_[i].size());
  }
  return theta;
}

void EigenMlp::set_parameters(const std::vector<float>& theta) {
  if (theta.size() != parameter_count())
    throw Error("network has " + std::to_string(parameter_count()) + " parameters, got " +
                std::to_string(theta.size()));
  const float* p = theta.data();
  for (size_t i = 0; i < weights_.size(); ++i) {
    std::copy(p, p + weights_[i].size(), weights_[i].data());
    p += weights_[i].size();
    std::copy(p, p + biases_[i].size(), biases_[i].data());
    p += biases_[i].size();
  }
}

}  // namespace segue
