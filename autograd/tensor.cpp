#include "autograd/tensor.hpp"

#include <limits>
#include <sstream>
#include <unordered_set>

namespace ag {

std::string shape_str(const Shape& s) {
  std::ostringstream o;
  o << '[';
  for (size_t i = 0; i < s.size(); ++i) o << (i ? " x " : "") << s[i];
  o << ']';
  return o.str();
}

int64_t numel_of(const Shape& s) {
  int64_t n = 1;
  for (int64_t d : s) {
    if (d < 0) throw Error("negative dimension in shape " + shape_str(s));
    n *= d;
  }
  return n;
}

void check_same_shape(const char* op, const Shape& a, const Shape& b) {
  if (a != b) throw Error(std::string(op) + ": shapes differ, " + shape_str(a) + " vs " + shape_str(b));
}

void check_2d(const char* op, const Shape& a) {
  if (a.size() != 2) throw Error(std::string(op) + ": needs a 2-D tensor (rows x cols), got " + shape_str(a));
}

// ---- grad mode --------------------------------------------------------------------------
namespace {
thread_local bool g_grad_enabled = true;
}
bool grad_enabled() { return g_grad_enabled; }
NoGradGuard::NoGradGuard() : previous_(g_grad_enabled) { g_grad_enabled = false; }
NoGradGuard::~NoGradGuard() { g_grad_enabled = previous_; }

void record(NodeBase& out, std::vector<std::shared_ptr<NodeBase>> parents, std::function<void()> fn) {
  if (!g_grad_enabled) return;
  bool any = false;
  for (const auto& p : parents) any = any || (p && p->requires_grad);
  if (!any) return;
  out.requires_grad = true;
  out.parents = std::move(parents);
  out.backward_fn = std::move(fn);
}

// ---- backward ----------------------------------------------------------------------------
void backward_from(const std::shared_ptr<NodeBase>& root, bool retain_graph) {
  if (!root) throw Error("backward: undefined tensor");
  if (root->numel() != 1)
    throw Error("backward: needs a one-element tensor, got " + std::to_string(root->numel()) +
                " elements (reduce with sum or mean first)");
  if (!root->requires_grad) throw Error("backward: the tensor does not require grad");
  if (root->freed)
    throw Error(
        "backward: this graph was already freed by an earlier backward(); pass retain_graph = true to the first "
        "backward() to run it twice");

  // Iterative post-order DFS -> topological order (parents before children).
  std::vector<NodeBase*> order;
  std::unordered_set<NodeBase*> seen;
  std::vector<std::pair<NodeBase*, size_t>> stack{{root.get(), 0}};
  seen.insert(root.get());
  while (!stack.empty()) {
    auto& [node, next] = stack.back();
    if (next < node->parents.size()) {
      NodeBase* p = node->parents[next++].get();
      if (p && p->freed)
        throw Error(
            "backward: the graph uses an intermediate tensor whose history an earlier backward() freed, so its "
            "inputs would get no gradient; use retain_graph = true there, or detach() the tensor to use it as a "
            "constant");
      if (p && p->requires_grad && seen.insert(p).second) stack.push_back({p, 0});
    } else {
      order.push_back(node);
      stack.pop_back();
    }
  }

  // Intermediates start from zero (matters when a graph is retained and run twice).
  for (NodeBase* n : order)
    if (n->backward_fn) n->zero_grad(), n->grad_is_last_use = false;
  root->seed_grad_one();
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    NodeBase* n = *it;
    n->settle_grad();  // every op that adds into n has run; columns nobody wrote become 0
    if (!n->backward_fn) continue;
    n->grad_is_last_use = !retain_graph;
    n->backward_fn();
    n->grad_is_last_use = false;
  }
  if (!retain_graph) {
    // Free intermediates: drop closures and edges; gradients of non-leaves are released.
    for (NodeBase* n : order) {
      if (n->backward_fn) {
        n->backward_fn = nullptr;
        n->zero_grad();
        n->parents.clear();
        n->freed = true;
      }
    }
  }
}

template <class T> void fill(Storage<T>& v, int64_t n, T x) {
  if (n < (int64_t(1) << 20)) {
    v.assign(static_cast<size_t>(n), x);
    return;
  }
  v.clear();
  v.resize(static_cast<size_t>(n));
  T* p = v.data();
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < n; ++i) p[i] = x;
}

// ---- gradient claims (see Node) -------------------------------------------------------------
bool g_poison_claimed_grads = false;

namespace {
// A claimed gradient buffer: elements unset (NaN when tests poison claims).
template <class T> void allocate_unset(Storage<T>& grad, size_t n) {
  grad.resize(n);
  if (g_poison_claimed_grads) std::fill(grad.begin(), grad.end(), T(std::numeric_limits<real_t<T>>::quiet_NaN()));
}
}  // namespace

template <class T> bool Node<T>::grad_columns_unwritten(const ColumnRanges& cols) const {
  if (grad.empty()) return true;
  for (const auto& [b, e] : cols) {
    bool inside = false;
    for (const auto& [ub, ue] : unwritten_columns) inside = inside || (ub <= b && e <= ue);
    if (!inside) return false;
  }
  return true;
}

template <class T> void Node<T>::claim_grad_columns(const ColumnRanges& cols) {
  check_2d("claim_grad_columns", shape);
  if (!grad_columns_unwritten(cols)) throw Error("claim_grad_columns: the columns already hold a gradient");
  if (grad.empty()) {
    allocate_unset(grad, value.size());
    unwritten_columns = {{0, shape[1]}};
  }
  for (const auto& [b, e] : cols) {
    ColumnRanges rest;
    for (const auto& [ub, ue] : unwritten_columns) {
      if (ub < b) rest.push_back({ub, std::min(ue, b)});
      if (e < ue) rest.push_back({std::max(ub, e), ue});
    }
    unwritten_columns = std::move(rest);
  }
}

template <class T> bool Node<T>::claim_whole_grad() {
  if (!grad.empty()) {
    settle_grad();
    return false;
  }
  allocate_unset(grad, value.size());
  return true;
}

template <class T> bool Node<T>::take_grad(Node& out) {
  if (&out == this || !grad.empty() || !out.grad_is_last_use || out.grad.size() != value.size() ||
      !out.unwritten_columns.empty())
    return false;
  grad = std::move(out.grad);
  out.grad.clear();  // moved-from: make it empty for certain
  return true;
}

template <class T> void Node<T>::settle_grad() {
  if (unwritten_columns.empty()) return;
  const int64_t rows = shape[0], cols = shape[1];
  T* g = grad.data();
#pragma omp parallel for schedule(static) if (numel() > (int64_t(1) << 20))
  for (int64_t r = 0; r < rows; ++r)
    for (const auto& [b, e] : unwritten_columns) std::fill(g + r * cols + b, g + r * cols + e, T(0));
  unwritten_columns.clear();
}

template struct Node<float>;
template struct Node<double>;
template struct Node<std::complex<float>>;
template struct Node<std::complex<double>>;

template void fill(Storage<float>&, int64_t, float);
template void fill(Storage<double>&, int64_t, double);
template void fill(Storage<std::complex<float>>&, int64_t, std::complex<float>);
template void fill(Storage<std::complex<double>>&, int64_t, std::complex<double>);

// ---- Tensor -----------------------------------------------------------------------------------
template <class T> Tensor<T> Tensor<T>::zeros(const Shape& shape, bool requires_grad) {
  return full(shape, T(0), requires_grad);
}

template <class T> Tensor<T> Tensor<T>::full(const Shape& shape, T v, bool requires_grad) {
  auto n = std::make_shared<Node<T>>();
  n->shape = shape;
  fill(n->value, numel_of(shape), v);
  n->requires_grad = requires_grad;
  return Tensor<T>(std::move(n));
}

template <class T> Tensor<T> Tensor<T>::from(const Shape& shape, const std::vector<T>& values, bool requires_grad) {
  return from(shape, Storage<T>(values.begin(), values.end()), requires_grad);
}

template <class T> Tensor<T> Tensor<T>::from(const Shape& shape, Storage<T> values, bool requires_grad) {
  if (static_cast<int64_t>(values.size()) != numel_of(shape))
    throw Error("Tensor::from: " + std::to_string(values.size()) + " values for shape " + shape_str(shape));
  auto n = std::make_shared<Node<T>>();
  n->shape = shape;
  n->value = std::move(values);
  n->requires_grad = requires_grad;
  return Tensor<T>(std::move(n));
}

template <class T> int64_t Tensor<T>::size(int64_t d) const {
  const Shape& s = shape();
  if (d < 0) d += static_cast<int64_t>(s.size());
  if (d < 0 || d >= static_cast<int64_t>(s.size()))
    throw Error("size(" + std::to_string(d) + ") of a tensor of shape " + shape_str(s));
  return s[d];
}

template <class T> int64_t Tensor<T>::rows() const {
  check_2d("rows", shape());
  return shape()[0];
}

template <class T> int64_t Tensor<T>::cols() const {
  check_2d("cols", shape());
  return shape()[1];
}

template <class T> T Tensor<T>::item() const {
  if (numel() != 1) throw Error("item: tensor of shape " + shape_str(shape()) + " is not one element");
  return data()[0];
}

template <class T> MatMap<T> Tensor<T>::mat() {
  check_2d("mat", shape());
  return MatMap<T>(data(), shape()[0], shape()[1]);
}

template <class T> ConstMatMap<T> Tensor<T>::mat() const {
  check_2d("mat", shape());
  return ConstMatMap<T>(data(), shape()[0], shape()[1]);
}

template <class T> ConstMatMap<T> Tensor<T>::grad_mat() const {
  check_2d("grad_mat", shape());
  if (node().grad.empty()) throw Error("grad_mat: no gradient has flowed into this tensor");
  return ConstMatMap<T>(node().grad.data(), shape()[0], shape()[1]);
}

template <class T> Tensor<T>& Tensor<T>::set_requires_grad(bool on) {
  node().requires_grad = on;
  return *this;
}

template <class T> Tensor<T> Tensor<T>::detach() const { return from(shape(), values(), false); }

template class Tensor<float>;
template class Tensor<double>;
template class Tensor<std::complex<float>>;
template class Tensor<std::complex<double>>;

}  // namespace ag
