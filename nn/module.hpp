// Base class of layers and models: a registry of named parameters and child modules.
// Names are dotted paths in registration order, e.g. "encoder.0.linear1.weight".
// Parameters are leaf tensors with requires_grad = true; the registry holds handles to the
// same nodes as the layer's members, so updating values in place (optimizer, checkpoint
// load, copy_parameters) is seen by both.
#pragma once

#include "autograd/tensor.hpp"

#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace nn {

template <class T> class Module {
 public:
  using Scalar = T;
  Module() = default;
  virtual ~Module() = default;
  Module(const Module&) = delete;  // a copy would share parameter nodes silently
  Module& operator=(const Module&) = delete;

  // All parameters, recursively, with dotted names, in registration order.
  std::vector<std::pair<std::string, ag::Tensor<T>>> named_parameters() const {
    std::vector<std::pair<std::string, ag::Tensor<T>>> out;
    collect("", out);
    return out;
  }
  std::vector<ag::Tensor<T>> parameters() const {
    std::vector<ag::Tensor<T>> out;
    for (auto& [name, t] : named_parameters()) out.push_back(t);
    return out;
  }
  int64_t num_parameters() const {
    int64_t n = 0;
    for (auto& [name, t] : named_parameters()) n += t.numel();
    return n;
  }
  void zero_grad() {
    for (auto& [name, t] : named_parameters()) t.zero_grad();
  }
  // Freeze or unfreeze all parameters (frozen ones receive no gradient).
  void set_requires_grad(bool on) {
    for (auto& [name, t] : named_parameters()) t.set_requires_grad(on);
  }

 protected:
  ag::Tensor<T>& register_parameter(const std::string& name, ag::Tensor<T> t) {
    check_name(name);
    t.set_requires_grad(true);
    params_.emplace_back(name, std::move(t));
    return params_.back().second;
  }
  template <class M> std::shared_ptr<M> register_module(const std::string& name, std::shared_ptr<M> m) {
    check_name(name);
    if (!m) throw ag::Error("Module::register_module: null module '" + name + "'");
    children_.emplace_back(name, std::static_pointer_cast<Module<T>>(m));
    return m;
  }

 private:
  void check_name(const std::string& name) const {
    if (name.empty() || name.find('.') != std::string::npos)
      throw ag::Error("Module: invalid name '" + name + "' (non-empty, no dots)");
    for (auto& p : params_)
      if (p.first == name) throw ag::Error("Module: duplicate parameter name '" + name + "'");
    for (auto& c : children_)
      if (c.first == name) throw ag::Error("Module: duplicate child name '" + name + "'");
  }
  void collect(const std::string& prefix, std::vector<std::pair<std::string, ag::Tensor<T>>>& out) const {
    for (auto& [n, t] : params_) out.emplace_back(prefix + n, t);
    for (auto& [n, c] : children_) c->collect(prefix + n + ".", out);
  }

  // std::vector of pairs: register_parameter's reference is only valid until the next
  // registration; layers copy the handle into their members right away.
  std::vector<std::pair<std::string, ag::Tensor<T>>> params_;
  std::vector<std::pair<std::string, std::shared_ptr<Module<T>>>> children_;
};

// Copies parameter values between modules of the same architecture (e.g. float <-> double),
// matched by name; throws when names or shapes differ.
template <class A, class B> void copy_parameters(const Module<A>& from, Module<B>& to) {
  auto src = from.named_parameters();
  auto dst = to.named_parameters();
  if (src.size() != dst.size())
    throw ag::Error("copy_parameters: " + std::to_string(src.size()) + " parameters vs " +
                    std::to_string(dst.size()));
  for (size_t i = 0; i < src.size(); ++i) {
    if (src[i].first != dst[i].first)
      throw ag::Error("copy_parameters: parameter " + std::to_string(i) + " is '" + src[i].first +
                      "' in the source and '" + dst[i].first + "' in the destination");
    if (src[i].second.shape() != dst[i].second.shape())
      throw ag::Error("copy_parameters: '" + src[i].first + "' has shape " +
                      ag::shape_str(src[i].second.shape()) + " vs " + ag::shape_str(dst[i].second.shape()));
    const auto& s = src[i].second.values();
    auto& d = dst[i].second.values();
    for (size_t k = 0; k < s.size(); ++k) d[k] = static_cast<B>(s[k]);
  }
}

}  // namespace nn
