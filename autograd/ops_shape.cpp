#include "autograd/ops_shape.hpp"

#include <algorithm>
#include <cstring>
#include <string>

namespace ag {

// ---- concat_cols ----------------------------------------------------------------------------
template <class T> Tensor<T> concat_cols(const std::vector<Tensor<T>>& xs) {
  if (xs.empty()) throw Error("concat_cols: no tensors given");
  check_2d("concat_cols", xs[0].shape());
  const int64_t R = xs[0].rows();
  std::vector<int64_t> off{0};
  for (const auto& x : xs) {
    check_2d("concat_cols", x.shape());
    if (x.rows() != R)
      throw Error("concat_cols: row counts differ, " + shape_str(xs[0].shape()) + " vs " + shape_str(x.shape()));
    off.push_back(off.back() + x.cols());
  }
  const int64_t C = off.back();
  auto out = new_output_overwritten<T>({R, C});  // every column copied below
  T* o = out.data();
  for (size_t k = 0; k < xs.size(); ++k) {
    const T* s = xs[k].data();
    const int64_t c = xs[k].cols(), o0 = off[k];
#pragma omp parallel for if (R * c > kParallelMin)
    for (int64_t r = 0; r < R; ++r) std::copy(s + r * c, s + (r + 1) * c, o + r * C + o0);
  }
  std::vector<std::shared_ptr<NodeBase>> parents;
  std::vector<Node<T>*> nodes;
  for (const auto& x : xs) {
    parents.push_back(x.node_ptr());
    nodes.push_back(&x.node());
  }
  record(out.node(), std::move(parents), [nodes, off, R, C, on = &out.node()] {
    for (size_t k = 0; k < nodes.size(); ++k) {
      Node<T>* xn = nodes[k];
      if (!xn->requires_grad) continue;
      const bool first = xn->claim_whole_grad();
      const int64_t c = off[k + 1] - off[k], o0 = off[k];
      T* g = xn->grad.data();
      const T* go = on->grad.data();
#pragma omp parallel for if (R * c > kParallelMin)
      for (int64_t r = 0; r < R; ++r) write_or_add(g + r * c, go + r * C + o0, c, first);
    }
  });
  return out;
}

// ---- concat_rows ----------------------------------------------------------------------------
template <class T> Tensor<T> concat_rows(const std::vector<Tensor<T>>& xs) {
  if (xs.empty()) throw Error("concat_rows: no tensors given");
  check_2d("concat_rows", xs[0].shape());
  const int64_t C = xs[0].cols();
  std::vector<int64_t> off{0};  // element offsets
  for (const auto& x : xs) {
    check_2d("concat_rows", x.shape());
    if (x.cols() != C)
      throw Error("concat_rows: column counts differ, " + shape_str(xs[0].shape()) + " vs " + shape_str(x.shape()));
    off.push_back(off.back() + x.numel());
  }
  int64_t R = 0;
  for (const auto& x : xs) R += x.rows();
  auto out = new_output_overwritten<T>({R, C});  // every part copied below
  for (size_t k = 0; k < xs.size(); ++k)
    std::copy(xs[k].values().begin(), xs[k].values().end(), out.values().begin() + off[k]);
  std::vector<std::shared_ptr<NodeBase>> parents;
  std::vector<Node<T>*> nodes;
  for (const auto& x : xs) {
    parents.push_back(x.node_ptr());
    nodes.push_back(&x.node());
  }
  record(out.node(), std::move(parents), [nodes, off, on = &out.node()] {
    for (size_t k = 0; k < nodes.size(); ++k) {
      Node<T>* xn = nodes[k];
      if (!xn->requires_grad) continue;
      const bool first = xn->claim_whole_grad();
      const int64_t n = off[k + 1] - off[k];
      T* g = xn->grad.data();
      const T* go = on->grad.data() + off[k];
      write_or_add(g, go, n, first);
    }
  });
  return out;
}

// ---- slice_cols -------------------------------------------------------------------------------
template <class T> Tensor<T> slice_cols(const Tensor<T>& x, int64_t begin, int64_t end) {
  check_2d("slice_cols", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  if (begin < 0 || end < begin || end > C)
    throw Error("slice_cols: range [" + std::to_string(begin) + ", " + std::to_string(end) +
                ") outside the columns of " + shape_str(x.shape()));
  const int64_t c = end - begin;
  auto out = new_output_overwritten<T>({R, c});  // every row copied below
  const T* s = x.data();
  T* o = out.data();
#pragma omp parallel for if (R * c > kParallelMin)
  for (int64_t r = 0; r < R; ++r) std::copy(s + r * C + begin, s + r * C + end, o + r * c);
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), R, C, c, begin] {
    if (!xn->requires_grad) return;
    // The first gradient of these columns is written (GDSR's edge MLPs slice one weight three
    // ways); columns no slice writes are zeroed when x is settled.
    const ColumnRanges cols{{begin, begin + c}};
    const bool first = c > 0 && xn->grad_columns_unwritten(cols);
    if (first)
      xn->claim_grad_columns(cols);
    else
      xn->ensure_grad();
    T* g = xn->grad.data();
    const T* go = on->grad.data();
#pragma omp parallel for if (R * c > kParallelMin)
    for (int64_t r = 0; r < R; ++r) write_or_add(g + r * C + begin, go + r * c, c, first);
  });
  return out;
}

// ---- slice_rows -------------------------------------------------------------------------------
template <class T> Tensor<T> slice_rows(const Tensor<T>& x, int64_t begin, int64_t end) {
  check_2d("slice_rows", x.shape());
  const int64_t R = x.rows(), C = x.cols();
  if (begin < 0 || end < begin || end > R)
    throw Error("slice_rows: range [" + std::to_string(begin) + ", " + std::to_string(end) + ") outside the rows of " +
                shape_str(x.shape()));
  auto out = new_output_overwritten<T>({end - begin, C});  // copied below
  std::copy(x.data() + begin * C, x.data() + end * C, out.data());
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node(), begin, C] {
    if (!xn->requires_grad) return;
    xn->ensure_grad();
    T* g = xn->grad.data() + begin * C;
    const T* go = on->grad.data();
    const int64_t n = static_cast<int64_t>(on->grad.size());
    for (int64_t i = 0; i < n; ++i) g[i] += go[i];
  });
  return out;
}

// ---- reshape ------------------------------------------------------------------------------------
template <class T> Tensor<T> reshape(const Tensor<T>& x, const Shape& shape) {
  if (numel_of(shape) != x.numel())
    throw Error("reshape: element counts differ, " + shape_str(x.shape()) + " vs " + shape_str(shape));
  auto out = Tensor<T>::from(shape, x.values());
  record(out.node(), {x.node_ptr()}, [xn = &x.node(), on = &out.node()] {
    if (!xn->requires_grad || xn->take_grad(*on)) return;  // the same elements: hand the buffer over
    const bool first = xn->claim_whole_grad();
    write_or_add(xn->grad.data(), on->grad.data(), static_cast<int64_t>(on->grad.size()), first);
  });
  return out;
}

#define AG_INSTANTIATE(T)                                               \
  template Tensor<T> concat_cols<T>(const std::vector<Tensor<T>>&);     \
  template Tensor<T> concat_rows<T>(const std::vector<Tensor<T>>&);     \
  template Tensor<T> slice_cols<T>(const Tensor<T>&, int64_t, int64_t); \
  template Tensor<T> slice_rows<T>(const Tensor<T>&, int64_t, int64_t); \
  template Tensor<T> reshape<T>(const Tensor<T>&, const Shape&);
AG_INSTANTIATE(float)
AG_INSTANTIATE(double)
AG_INSTANTIATE(std::complex<float>)
AG_INSTANTIATE(std::complex<double>)
#undef AG_INSTANTIATE

}  // namespace ag
