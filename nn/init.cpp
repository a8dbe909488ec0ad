#include "nn/init.hpp"

#include <cmath>
#include <complex>

namespace nn {

namespace {
template <class T> struct Fill {
  template <class Draw> static void run(ag::Tensor<T>& t, Draw draw) {
    for (auto& v : t.values()) v = static_cast<T>(draw());
  }
};
template <class R> struct Fill<std::complex<R>> {
  template <class Draw> static void run(ag::Tensor<std::complex<R>>& t, Draw draw) {
    for (auto& v : t.values()) {
      const R re = static_cast<R>(draw());
      const R im = static_cast<R>(draw());
      v = std::complex<R>(re, im);
    }
  }
};
}  // namespace

template <class T> void uniform_(ag::Tensor<T>& t, double lo, double hi, Rng& rng) {
  if (!(lo <= hi))
    throw ag::Error("nn::uniform_: empty range [" + std::to_string(lo) + ", " + std::to_string(hi) + ")");
  Fill<T>::run(t, [&] { return rng.uniform(lo, hi); });
}

template <class T> void normal_(ag::Tensor<T>& t, double mean, double std, Rng& rng) {
  Fill<T>::run(t, [&] { return rng.normal(mean, std); });
}

template <class T> void kaiming_uniform_(ag::Tensor<T>& t, int64_t fan_in, double a, Rng& rng) {
  if (fan_in <= 0) throw ag::Error("nn::kaiming_uniform_: fan_in must be positive");
  const double bound = std::sqrt(2.0 / (1.0 + a * a)) * std::sqrt(3.0 / static_cast<double>(fan_in));
  uniform_(t, -bound, bound, rng);
}

template <class T> void xavier_uniform_(ag::Tensor<T>& t, int64_t fan_in, int64_t fan_out, Rng& rng, double gain) {
  if (fan_in + fan_out <= 0) throw ag::Error("nn::xavier_uniform_: fan_in + fan_out must be positive");
  const double bound = gain * std::sqrt(6.0 / static_cast<double>(fan_in + fan_out));
  uniform_(t, -bound, bound, rng);
}

#define NN_INIT_INST(T)                                                  \
  template void uniform_(ag::Tensor<T>&, double, double, Rng&);          \
  template void normal_(ag::Tensor<T>&, double, double, Rng&);           \
  template void kaiming_uniform_(ag::Tensor<T>&, int64_t, double, Rng&); \
  template void xavier_uniform_(ag::Tensor<T>&, int64_t, int64_t, Rng&, double);
NN_INIT_INST(float)
NN_INIT_INST(double)
NN_INIT_INST(std::complex<float>)
NN_INIT_INST(std::complex<double>)
#undef NN_INIT_INST

}  // namespace nn
