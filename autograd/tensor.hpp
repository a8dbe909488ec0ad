// Reverse-mode automatic differentiation, the core: a Tensor is a handle to a Node in a
// graph; every op creates a new Node holding its value, its parents and a closure that
// pushes the output gradient back into the parents' gradients. backward() runs those
// closures in reverse topological order (micrograd, with dense arrays instead of scalars).
//
// Scalars: float, double, std::complex<float>, std::complex<double>. Storage is one
// contiguous row-major array; most ops work on 2-D tensors (rows x cols), conv/pool on
// 4-D N x C x H x W.
//
// Complex gradients follow the convention of PyTorch: for a real loss L and a complex
// tensor z = a + ib, grad(z) = dL/da + i dL/db. Hence for a holomorphic y = f(z),
// grad(z) = conj(f'(z)) * grad(y).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <complex>
#include <cstdint>
#include <functional>
#include <initializer_list>
#include <memory>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

namespace ag {

using Shape = std::vector<int64_t>;
using Index = std::vector<int64_t>;  // row indices for gather / scatter

std::string shape_str(const Shape& s);
int64_t numel_of(const Shape& s);

// Thrown for every misuse: wrong shapes, bad indices, backward from a non-scalar, ...
struct Error : std::runtime_error {
  using std::runtime_error::runtime_error;
};

template <class T> struct is_complex : std::false_type {};
template <class T> struct is_complex<std::complex<T>> : std::true_type {};
template <class T> inline constexpr bool is_complex_v = is_complex<T>::value;

template <class T> struct real_of { using type = T; };
template <class T> struct real_of<std::complex<T>> { using type = T; };
template <class T> using real_t = typename real_of<T>::type;

template <class T> using RowMat = Eigen::Matrix<T, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
template <class T> using MatMap = Eigen::Map<RowMat<T>>;
template <class T> using ConstMatMap = Eigen::Map<const RowMat<T>>;

// ---- grad mode -------------------------------------------------------------------------
bool grad_enabled();
// Inference scope: ops inside record no graph. RAII, nests, per thread.
class NoGradGuard {
 public:
  NoGradGuard();
  ~NoGradGuard();
  NoGradGuard(const NoGradGuard&) = delete;
  NoGradGuard& operator=(const NoGradGuard&) = delete;

 private:
  bool previous_;
};

// ---- storage -----------------------------------------------------------------------------
// A tensor's elements: a std::vector whose resize() leaves new real elements uninitialised
// (default-init, not value-init), so that an op that writes every element of its output does
// not first zero it in one serial pass (new_output_overwritten). assign() fills as usual.
template <class T> struct DefaultInitAllocator : std::allocator<T> {
  template <class U> struct rebind { using other = DefaultInitAllocator<U>; };
  DefaultInitAllocator() = default;
  template <class U> DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U> void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) { ::new (p) U; }
  template <class U, class... A> void construct(U* p, A&&... a) { ::new (p) U(std::forward<A>(a)...); }
};
template <class T> using Storage = std::vector<T, DefaultInitAllocator<T>>;
template <class T> bool operator==(const Storage<T>& a, const std::vector<T>& b) {
  return std::equal(a.begin(), a.end(), b.begin(), b.end());
}
template <class T> std::vector<T> to_vector(const Storage<T>& v) { return std::vector<T>(v.begin(), v.end()); }

// v := n copies of x; threaded for large n (a serial fill of a 270 MB output was 4% of a
// paper-preset inference frame).
template <class T> void fill(Storage<T>& v, int64_t n, T x);

// dst[0, n) = src[0, n) for a first gradient (Node::claim_whole_grad returned true), else +=.
template <class T> void write_or_add(T* dst, const T* src, int64_t n, bool first) {
  if (first)
    std::copy(src, src + n, dst);
  else
    for (int64_t i = 0; i < n; ++i) dst[i] += src[i];
}

// ---- graph nodes -----------------------------------------------------------------------
struct NodeBase {
  virtual ~NodeBase() = default;
  bool requires_grad = false;
  std::vector<std::shared_ptr<NodeBase>> parents;
  std::function<void()> backward_fn;  // reads this node's grad, adds (or first writes) into parents'
  // Set when a backward() without retain_graph released this intermediate's history: a later
  // backward() that reaches it throws instead of treating it as a leaf.
  bool freed = false;
  // True only while this node's own backward_fn runs in a backward() without retain_graph:
  // nothing reads this node's gradient after that op, so the op may hand the buffer to a
  // parent (Node::take_grad) instead of copying it.
  bool grad_is_last_use = false;
  virtual void zero_grad() = 0;
  virtual void seed_grad_one() = 0;  // grad := 1 (scalar root)
  virtual void settle_grad() = 0;    // see Node::settle_grad
  virtual int64_t numel() const = 0;
};

// Column ranges [begin, end) of a 2-D tensor, sorted and disjoint.
using ColumnRanges = std::vector<std::pair<int64_t, int64_t>>;

template <class T> struct Node final : NodeBase {
  Shape shape;
  Storage<T> value;
  Storage<T> grad;  // empty until something flows in; then same size as value
  // Columns of grad that were allocated by claim_grad_columns and that nobody has written
  // yet: their contents are undefined until settle_grad() zeroes them.
  ColumnRanges unwritten_columns;

  // Before adding into grad: allocates it zeroed, or zeroes its unwritten columns.
  void ensure_grad() {
    if (grad.empty())
      fill(grad, numel(), T(0));
    else
      settle_grad();
  }
  // For an op that will WRITE, not add, every row of the given columns of this 2-D tensor's
  // gradient (GDSR's field: each layer's block of the hyper-network's output planes). The
  // op then needs neither a zero fill nor a read of the old values: a fresh gradient is ~3
  // weight-sized passes over memory instead of 5. grad_columns_unwritten says whether all of
  // `cols` are free (grad empty, or those columns still unwritten); claim_grad_columns
  // (only then) allocates grad without zeroing on first use and marks `cols` written. The
  // backward pass settles each node (leaves too) once every op that feeds its gradient ran.
  bool grad_columns_unwritten(const ColumnRanges& cols) const;
  void claim_grad_columns(const ColumnRanges& cols);
  // The same for an op about to give every element of the gradient a value: true if nothing
  // has flowed in yet (grad is then allocated unset and the op writes it), false after
  // ensure_grad (the op adds). Saves the zero fill and a read of every first gradient.
  bool claim_whole_grad();
  // For an op whose gradient for this input is its output's gradient unchanged (add, sub's
  // first operand), called after the op's other parts have read `out`'s gradient: takes over
  // that buffer (no allocation, no copy) and returns true if nothing has flowed into this
  // node yet, `out` has the same size and its gradient is at its last use (see
  // NodeBase::grad_is_last_use). Otherwise returns false and changes nothing; the op then
  // writes or adds as usual.
  bool take_grad(Node& out);
  void settle_grad() override;  // zeroes the unwritten columns; then grad is a plain gradient
  void zero_grad() override { grad.clear(), unwritten_columns.clear(); }
  void seed_grad_one() override { fill(grad, numel(), T(1)), unwritten_columns.clear(); }
  int64_t numel() const override { return static_cast<int64_t>(value.size()); }
};

// Tests set this to fill every gradient that claim_whole_grad or claim_grad_columns allocates
// with NaN, so that an element an op fails to write, or an unwritten column settle_grad
// misses, shows up instead of reading as a lucky zero (large fresh blocks come from the OS
// already zeroed).
extern bool g_poison_claimed_grads;

// Run reverse mode from `root` (which must hold exactly one element). Leaves keep their
// gradients; intermediates are released afterwards unless retain_graph is true. Throws
// ag::Error (and changes nothing) if the graph reaches an intermediate released by an earlier
// backward(): a second backward() of the same loss, or a new loss built on a released
// intermediate, would otherwise give its inputs no gradient silently. Keep the graph with
// retain_graph = true, or detach() the intermediate to use it as a constant.
void backward_from(const std::shared_ptr<NodeBase>& root, bool retain_graph = false);

// ---- the tensor handle -------------------------------------------------------------------
template <class T> class Tensor {
 public:
  using Scalar = T;

  Tensor() = default;
  explicit Tensor(std::shared_ptr<Node<T>> n) : n_(std::move(n)) {}

  // Construction. `requires_grad` marks a leaf (parameter or input to differentiate).
  static Tensor zeros(const Shape& shape, bool requires_grad = false);
  static Tensor full(const Shape& shape, T v, bool requires_grad = false);
  static Tensor from(const Shape& shape, const std::vector<T>& values, bool requires_grad = false);
  static Tensor from(const Shape& shape, Storage<T> values, bool requires_grad = false);
  static Tensor from(const Shape& shape, std::initializer_list<T> values, bool requires_grad = false) {
    return from(shape, Storage<T>(values), requires_grad);
  }
  static Tensor scalar(T v, bool requires_grad = false) { return full({1, 1}, v, requires_grad); }
  // A 2-D tensor copied from an Eigen matrix expression (any storage order).
  template <class Derived> static Tensor from_eigen(const Eigen::MatrixBase<Derived>& m, bool requires_grad = false) {
    Tensor t = zeros({m.rows(), m.cols()}, requires_grad);
    t.mat() = m;
    return t;
  }

  bool defined() const { return static_cast<bool>(n_); }
  const Shape& shape() const { return node().shape; }
  int64_t dim() const { return static_cast<int64_t>(node().shape.size()); }
  int64_t size(int64_t d) const;
  int64_t rows() const;  // 2-D only
  int64_t cols() const;  // 2-D only
  int64_t numel() const { return static_cast<int64_t>(node().value.size()); }

  T* data() { return node().value.data(); }
  const T* data() const { return node().value.data(); }
  Storage<T>& values() { return node().value; }
  const Storage<T>& values() const { return node().value; }
  T item() const;  // the single element of a one-element tensor
  T at(int64_t r, int64_t c) const { return data()[r * cols() + c]; }

  MatMap<T> mat();  // 2-D view as an Eigen row-major matrix
  ConstMatMap<T> mat() const;

  // Gradients (leaves, or retained intermediates). Empty if nothing flowed in.
  const Storage<T>& grad() const { return node().grad; }
  bool has_grad() const { return !node().grad.empty(); }
  ConstMatMap<T> grad_mat() const;
  void zero_grad() { node().zero_grad(); }

  bool requires_grad() const { return node().requires_grad; }
  Tensor& set_requires_grad(bool on);

  // d(this)/d(leaves); this must be a one-element tensor.
  void backward(bool retain_graph = false) const { backward_from(n_, retain_graph); }
  // A new leaf with the same values and no history.
  Tensor detach() const;
  Tensor clone() const { return detach(); }

  Node<T>& node() const {
    if (!n_) throw Error("use of an undefined tensor");
    return *n_;
  }
  const std::shared_ptr<Node<T>>& node_ptr() const { return n_; }

 private:
  std::shared_ptr<Node<T>> n_;
};

using Tensorf = Tensor<float>;
using Tensord = Tensor<double>;
using Tensorcf = Tensor<std::complex<float>>;
using Tensorcd = Tensor<std::complex<double>>;

// ---- helpers every op uses ------------------------------------------------------------------
// A fresh output tensor (no history yet) with the given shape, zero-filled.
template <class T> Tensor<T> new_output(const Shape& shape) { return Tensor<T>::zeros(shape); }
// The same with its elements left unset (complex ones are still zeroed by their
// constructor): only for an op that then writes every element.
template <class T> Tensor<T> new_output_overwritten(const Shape& shape) {
  auto n = std::make_shared<Node<T>>();
  n->shape = shape;
  n->value.resize(static_cast<size_t>(numel_of(shape)));
  return Tensor<T>(std::move(n));
}

// Attach history to an op's output: if grad mode is on and any parent requires grad, the
// output requires grad, keeps its parents alive and stores `fn` as its backward. `fn`
// should capture raw Node pointers (parents are kept alive by `parents`).
void record(NodeBase& out, std::vector<std::shared_ptr<NodeBase>> parents, std::function<void()> fn);

// Rows processed per OpenMP chunk are large enough to amortise thread start-up.
inline constexpr int64_t kParallelMin = 16384;

// Shape checks with messages naming the op and both shapes.
void check_same_shape(const char* op, const Shape& a, const Shape& b);
void check_2d(const char* op, const Shape& a);

}  // namespace ag
