#include "algorithms/mlp_backprop.h"

#include "core/error.h"

// The BLAS LibTorch itself calls (libblas.so.3: OpenBLAS where installed), column-major.
extern "C" void sgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
                       const float* alpha, const float* a, const int* lda, const float* b, const int* ldb,
                       const float* beta, float* c, const int* ldc);

namespace segue {
namespace {

// C = op(A) op(B) (+ C with `accumulate`), row-major.
void gemm(bool transpose_a, bool transpose_b, int m, int n, int k, const float* a, int lda,
          const float* b, int ldb, float* c, int ldc, bool accumulate = false) {
  // Row-major C = op(A) op(B) is column-major C^T = op(B)^T op(A)^T, and a row-major
  // matrix read column-major is its transpose: swap the operands, keep the flags.
  const char ta = transpose_b ? 'T' : 'N', tb = transpose_a ? 'T' : 'N';
  const float one = 1.0f, beta = accumulate ? 1.0f : 0.0f;
  sgemm_(&ta, &tb, &n, &m, &k, &one, b, &ldb, a, &lda, &beta, c, &ldc);
}

// A parameter's values for reading and its gradient for writing, asked for at every use
// rather than kept: the module owns them (a first use allocates the gradient).
const float* values_of(const torch::Tensor& p) { return p.data_ptr<float>(); }
float* gradient_of(torch::Tensor p) {
  if (!p.grad().defined()) p.mutable_grad() = torch::zeros_like(p);
  return p.mutable_grad().data_ptr<float>();
}
}  // namespace

MlpBackprop::MlpBackprop(torch::nn::Sequential net, Activation act) : act_(act) {
  for (const auto& module : net->children())
    if (auto linear = std::dynamic_pointer_cast<torch::nn::LinearImpl>(module)) layers_.emplace_back(linear);
  if (layers_.empty()) throw Error("MlpBackprop: the network has no Linear layer");
  out_.resize(layers_.size());
  deltas_.resize(layers_.size());
  tangents_.resize(layers_.size());
  offsets_.push_back(0);
  for (const auto& layer : layers_) offsets_.push_back(offsets_.back() + layer->weight.numel() + layer->bias.numel());
}

const MlpBackprop::RowMatrix& MlpBackprop::forward(const float* x, int batch) {
  x_ = x, batch_ = batch;
  const float* in = x;
  for (size_t i = 0; i < layers_.size(); ++i) {
    const auto& w = layers_[i]->weight;
    const int fan_out = int(w.size(0)), fan_in = int(w.size(1));
    RowMatrix& y = out_[i];
    y.resize(batch, fan_out);  // no-op once the batch size is settled
    gemm(false, true, batch, fan_out, fan_in, in, fan_in, values_of(w), fan_in, y.data(), fan_out);  // x W^T
    y.rowwise() += Eigen::Map<const Eigen::RowVectorXf>(values_of(layers_[i]->bias), fan_out);
    if (i + 1 < layers_.size()) {
      if (act_ == Activation::Tanh) y = y.array().tanh();
      else y = y.array().max(0.0f);
    }
    in = y.data();
  }
  return out_.back();
}

void MlpBackprop::times_activation_slope(RowMatrix& m, const RowMatrix& h) const {
  if (act_ == Activation::Tanh) m.array() *= 1.0f - h.array().square();
  else m.array() *= (h.array() > 0.0f).cast<float>();
}

void MlpBackprop::backward(const RowMatrix& dy, float* flat) {
  if (dy.rows() != batch_ || dy.cols() != out_.back().cols())
    throw Error("MlpBackprop::backward: the gradient's shape is not the last forward()'s output's");
  deltas_.back() = dy;
  for (size_t i = layers_.size(); i-- > 0;) {
    const auto& w = layers_[i]->weight;
    const int fan_out = int(w.size(0)), fan_in = int(w.size(1));
    const RowMatrix& delta = deltas_[i];  // dL/d(layer i's pre-activation)
    const float* in = i == 0 ? x_ : out_[i - 1].data();
    float* dw = flat ? flat + offsets_[i] : gradient_of(w);
    float* db = flat ? dw + w.numel() : gradient_of(layers_[i]->bias);
    // dL/dW_i = delta^T in, dL/db_i = sum over rows of delta.
    gemm(true, false, fan_out, fan_in, batch_, delta.data(), fan_out, in, fan_in, dw, fan_in);
    Eigen::Map<Eigen::RowVectorXf>(db, fan_out) = delta.colwise().sum();
    if (i == 0) break;
    // Back through W_i and the activation below it (its derivative from its output).
    RowMatrix& below = deltas_[i - 1];
    below.resize(batch_, fan_in);
    gemm(false, false, batch_, fan_in, fan_out, delta.data(), fan_out, values_of(w), fan_in, below.data(), fan_in);
    times_activation_slope(below, out_[i - 1]);
  }
}

const MlpBackprop::RowMatrix& MlpBackprop::jvp(const float* direction) {
  // Forward-mode through z_i = h_{i-1} W_i^T + b_i, h_i = act(z_i), the input held fixed:
  // dz_i = dh_{i-1} W_i^T + h_{i-1} dW_i^T + db_i, dh_i = act'(z_i) dz_i.
  for (size_t i = 0; i < layers_.size(); ++i) {
    const auto& w = layers_[i]->weight;
    const int fan_out = int(w.size(0)), fan_in = int(w.size(1));
    const float* dw = direction + offsets_[i];
    const float* in = i == 0 ? x_ : out_[i - 1].data();
    RowMatrix& t = tangents_[i];
    t.resize(batch_, fan_out);
    gemm(false, true, batch_, fan_out, fan_in, in, fan_in, dw, fan_in, t.data(), fan_out);
    t.rowwise() += Eigen::Map<const Eigen::RowVectorXf>(dw + w.numel(), fan_out);
    if (i > 0)
      gemm(false, true, batch_, fan_out, fan_in, tangents_[i - 1].data(), fan_in, values_of(w), fan_in, t.data(),
           fan_out, /*accumulate=*/true);
    if (i + 1 < layers_.size()) times_activation_slope(t, out_[i]);
  }
  return tangents_.back();
}

}  // namespace segue
