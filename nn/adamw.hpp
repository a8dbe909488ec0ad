// AdamW (Loshchilov & Hutter 2019) with the update rule of torch.optim.AdamW
// (PyTorch 2.x, single-tensor path, maximize = false). For each parameter p with gradient
// g and its own step count t (incremented before use; parameters without a gradient are
// skipped and their t does not advance):
//     p   <- p * (1 - lr * weight_decay)                  (decoupled weight decay)
//     m   <- beta1 * m + (1 - beta1) * g               (computed as m + (1-beta1)(g-m), torch's lerp)
//     v   <- beta2 * v + (1 - beta2) * g^2
//     vmax <- max(vmax, v)                                 (amsgrad only)
//     bc1 = 1 - beta1^t,  bc2 = 1 - beta2^t
//     denom = sqrt(amsgrad ? vmax : v) / sqrt(bc2) + eps
//     p   <- p - (lr / bc1) * m / denom
// State m, v, vmax is kept in the parameter's scalar type; bc1, bc2, lr / bc1 in double.
// Complex parameters are treated as pairs of reals (PyTorch's view_as_real): g^2 and max
// are per real and imaginary part.
#pragma once

#include "autograd/tensor.hpp"

#include <complex>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace nn {

struct AdamWOptions {
  double lr = 1e-3;
  double beta1 = 0.9, beta2 = 0.999;
  double eps = 1e-8;
  double weight_decay = 1e-2;
  bool amsgrad = false;
};

// Refuses (ag::Error naming the option) what the update cannot take: lr not finite or < 0,
// beta1 or beta2 outside [0, 1) (at 1 the bias correction 1 - beta^t is 0), eps not finite or
// <= 0 (at 0 an entry whose gradient and moments are 0 becomes 0 / 0 = NaN), weight_decay not
// finite or < 0.
void check_adamw_options(const AdamWOptions& o);

// R: float or double. Holds handles to the parameters (real ones and complex<R> ones).
template <class R> class AdamW {
 public:
  struct Slot {  // one parameter and its state (public for checkpoints and tests)
    std::string name;
    std::shared_ptr<ag::NodeBase> node;
    bool complex = false;
    int64_t step = 0;
    std::vector<R> m, v, vmax;  // 2 * numel reals for complex parameters; vmax only with amsgrad
    int64_t reals() const;      // number of real values in the parameter
  };

  explicit AdamW(AdamWOptions opt = {}) : opt_(opt) { check_adamw_options(opt_); }
  AdamW(const std::vector<std::pair<std::string, ag::Tensor<R>>>& params, AdamWOptions opt = {});

  void add(const std::string& name, const ag::Tensor<R>& p);
  void add(const std::string& name, const ag::Tensor<std::complex<R>>& p);
  template <class Named> void add_all(const Named& named) {
    for (const auto& [n, p] : named) add(n, p);
  }

  // One update of every parameter that has a gradient. Does not clear gradients.
  void step();
  // Clears the gradients of all parameters.
  void zero_grad();

  double lr() const { return opt_.lr; }
  void set_lr(double lr) {
    AdamWOptions o = opt_;
    o.lr = lr;
    check_adamw_options(o);
    opt_.lr = lr;
  }
  const AdamWOptions& options() const { return opt_; }
  int64_t steps_taken() const { return steps_; }  // calls to step()
  void set_steps_taken(int64_t s) { steps_ = s; }
  std::vector<Slot>& slots() { return slots_; }
  const std::vector<Slot>& slots() const { return slots_; }

 private:
  AdamWOptions opt_;
  std::vector<Slot> slots_;
  int64_t steps_ = 0;
};

}  // namespace nn
