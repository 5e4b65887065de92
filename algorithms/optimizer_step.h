#pragma once
// The optimiser's step on gradients already in each parameter's .grad(), as loops over
// the tensors' memory: LibTorch's own (clip_grad_norm_, Adam::step) spend a few operator
// dispatches per parameter tensor, which for a 32 x 32 network cost more than the
// arithmetic. Same rules and the same optimiser state (so checkpoints are unchanged),
// checked equal to LibTorch's in tests.
#include <torch/torch.h>

#include <vector>

namespace segue {

// The gradients' joint L2 norm; where it exceeds max_norm, every gradient is scaled by
// max_norm / (norm + 1e-6), as torch::nn::utils::clip_grad_norm_ does. Returns the norm
// before scaling.
double clip_grad_norm(const std::vector<torch::Tensor>& params, double max_norm);

// One step of Adam (Kingma & Ba 2015, Algorithm 1, with LibTorch's eps placement:
// theta -= lr / (1 - b1^t) * m / (sqrt(v) / sqrt(1 - b2^t) + eps)) on every parameter of
// `adam` that has a gradient, reading and updating adam's own per-parameter state.
// Weight decay and AMSGrad, which no learner here uses, are refused.
void adam_step(torch::optim::Adam& adam);

}  // namespace segue
