// Base class of layers and models: a registry of named parameters and child modules.
// Names are dotted paths in registration order, e.g. "encoder.0.linear1.weight".
// Parameters are leaf tensors with requires_grad = true; the registry holds handles to the
// same nodes as the layer's members, so updating values in place (optimizer, checkpoint
// load, copy_parameters) is seen by both.
#pragma once

#include "autograd/tensor.hpp"

#include <map>
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
    if (!t.defined()) throw ag::Error("Module::register_parameter: undefined tensor '" + name + "'");
    t.set_requires_grad(true);
    entries_.push_back(Entry{name, std::move(t), nullptr});
    return entries_.back().param;
  }
  template <class M> std::shared_ptr<M> register_module(const std::string& name, std::shared_ptr<M> m) {
    check_name(name);
    if (!m) throw ag::Error("Module::register_module: null module '" + name + "'");
    entries_.push_back(Entry{name, ag::Tensor<T>(), std::static_pointer_cast<Module<T>>(m)});
    return m;
  }

 private:
  struct Entry {  // a parameter or a child module
    std::string name;
    ag::Tensor<T> param;
    std::shared_ptr<Module<T>> child;
  };
  void check_name(const std::string& name) const {
    if (name.empty() || name.find('.') != std::string::npos)
      throw ag::Error("Module: invalid name '" + name + "' (non-empty, no dots)");
    for (auto& e : entries_)
      if (e.name == name) throw ag::Error("Module: duplicate name '" + name + "'");
  }
  void collect(const std::string& prefix, std::vector<std::pair<std::string, ag::Tensor<T>>>& out) const {
    for (auto& e : entries_) {
      if (e.child)
        e.child->collect(prefix + e.name + ".", out);
      else
        out.emplace_back(prefix + e.name, e.param);
    }
  }

  // register_parameter's reference is only valid until the next registration; layers
  // copy the handle into their members right away.
  std::vector<Entry> entries_;
};

// Copies parameter values between modules of the same architecture (e.g. float <-> double),
// matched by name; throws when names or shapes differ.
template <class A, class B> void copy_parameters(const Module<A>& from, Module<B>& to) {
  const auto src = from.named_parameters();
  auto dst = to.named_parameters();
  if (src.size() != dst.size())
    throw ag::Error("copy_parameters: " + std::to_string(src.size()) + " parameters in the source vs " +
                    std::to_string(dst.size()) + " in the destination");
  std::map<std::string, const ag::Tensor<A>*> by_name;
  for (const auto& [n, t] : src) by_name[n] = &t;
  // Check everything first, so that a refused copy leaves the destination unchanged.
  for (const auto& [n, t] : dst) {
    const auto it = by_name.find(n);
    if (it == by_name.end()) throw ag::Error("copy_parameters: '" + n + "' is not in the source");
    if (it->second->shape() != t.shape())
      throw ag::Error("copy_parameters: '" + n + "' has shape " + ag::shape_str(it->second->shape()) + " vs " +
                      ag::shape_str(t.shape()));
  }
  for (auto& [n, t] : dst) {
    const auto& s = by_name[n]->values();
    auto& d = t.values();
    for (size_t k = 0; k < s.size(); ++k) d[k] = static_cast<B>(s[k]);
  }
}

}  // namespace nn
