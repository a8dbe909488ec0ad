#include "autograd/gradcheck_suite.hpp"

#include "autograd/autograd.hpp"

#include <random>

namespace ag {
namespace {

using Fn = std::function<Tensord(const std::vector<Tensord>&)>;

struct Case {
  std::string op;
  Fn f;
  std::vector<Shape> shapes;
  double lo = -1, hi = 1;  // input range (positive ranges for log/sqrt/pow)
};

// WIRE and other complex ops are checked through real leaves: z = re + i im, and the
// output mapped back to [real | imag] columns.
Tensord split(const Tensorcd& z) { return concat_cols<double>({real(z), imag(z)}); }

std::vector<Case> cases() {
  using V = const std::vector<Tensord>&;
  std::vector<Case> c;
  c.push_back({"add (row broadcast)", [](V x) { return add(x[0], x[1]); }, {{4, 3}, {1, 3}}});
  c.push_back({"sub (col broadcast)", [](V x) { return sub(x[0], x[1]); }, {{4, 3}, {4, 1}}});
  c.push_back({"mul", [](V x) { return mul(x[0], x[1]); }, {{4, 3}, {4, 3}}});
  c.push_back({"div", [](V x) { return div(x[0], x[1]); }, {{4, 3}, {4, 3}}, 0.5, 2});
  c.push_back({"exp", [](V x) { return exp(x[0]); }, {{4, 3}}});
  c.push_back({"log", [](V x) { return log(x[0]); }, {{4, 3}}, 0.5, 2});
  c.push_back({"sqrt", [](V x) { return sqrt(x[0]); }, {{4, 3}}, 0.5, 2});
  c.push_back({"sin", [](V x) { return sin(x[0]); }, {{4, 3}}});
  c.push_back({"cos", [](V x) { return cos(x[0]); }, {{4, 3}}});
  c.push_back({"tanh", [](V x) { return tanh(x[0]); }, {{4, 3}}});
  c.push_back({"abs", [](V x) { return abs(x[0]); }, {{4, 3}}, 0.2, 1});
  c.push_back({"pow 2.5", [](V x) { return pow(x[0], 2.5); }, {{4, 3}}, 0.5, 2});
  c.push_back({"relu", [](V x) { return relu(x[0]); }, {{4, 3}}, 0.2, 1});
  c.push_back({"leaky_relu", [](V x) { return leaky_relu(x[0], 0.02); }, {{4, 3}}, -1, -0.2});
  c.push_back({"sigmoid", [](V x) { return sigmoid(x[0]); }, {{4, 3}}});
  c.push_back({"clamp", [](V x) { return clamp(x[0], -2.0, 2.0); }, {{4, 3}}});
  c.push_back({"atan2", [](V x) { return atan2(x[0], x[1]); }, {{4, 3}, {4, 3}}});
  c.push_back({"matmul", [](V x) { return matmul(x[0], x[1]); }, {{4, 3}, {3, 5}}});
  c.push_back({"linear", [](V x) { return linear(x[0], x[1], x[2]); }, {{4, 3}, {5, 3}, {1, 5}}});
  c.push_back({"transpose", [](V x) { return transpose(x[0]); }, {{4, 3}}});
  c.push_back({"sum_rows / mean_cols", [](V x) { return add(sum_rows(x[0]), mean(mean_cols(x[0]))); }, {{4, 3}}});
  c.push_back({"concat / slice",
               [](V x) {
                 return slice_cols(concat_cols<double>({x[0], x[1]}), 1, 4);
               },
               {{4, 3}, {4, 2}}});
  c.push_back({"index_select_rows", [](V x) { return index_select_rows(x[0], {3, 0, 0, 2}); }, {{4, 3}}});
  c.push_back({"scatter_add_rows", [](V x) { return scatter_add_rows(x[0], {1, 0, 1, 3}, 5); }, {{4, 3}}});
  c.push_back({"add_gathered_rows",
               [](V x) {
                 return add_gathered_rows(x[0], x[1], {2, 0, 2, 1, 0}, x[2], {0, 0, 1, 3, 2});
               },
               {{5, 3}, {3, 3}, {4, 3}}});
  c.push_back({"scatter_mean_rows", [](V x) { return scatter_mean_rows(x[0], {1, 0, 1, 3}, 5); }, {{4, 3}}});
  c.push_back({"interpolate_rows",
               [](V x) {
                 return interpolate_rows(x[0], {0, 1, 2, 3, 2, 1}, x[1]);
               },
               {{4, 3}, {2, 3}}});
  c.push_back({"dot_rows", [](V x) { return dot_rows(x[0], x[1]); }, {{4, 3}, {4, 3}}});
  c.push_back({"cross3", [](V x) { return cross3(x[0], x[1]); }, {{4, 3}, {4, 3}}});
  c.push_back({"norm_rows", [](V x) { return norm_rows(x[0]); }, {{4, 3}}});
  c.push_back({"normalize_rows", [](V x) { return normalize_rows(x[0], 1e-12); }, {{4, 3}}});
  c.push_back({"channel_norm", [](V x) { return channel_norm(x[0], 1e-5); }, {{6, 3}}});
  c.push_back({"layer_norm", [](V x) { return layer_norm(x[0], 1e-5); }, {{4, 5}}});
  c.push_back({"l1_loss", [](V x) { return l1_loss(x[0], x[1]); }, {{4, 3}, {4, 3}}});
  c.push_back({"mse_loss", [](V x) { return mse_loss(x[0], x[1]); }, {{4, 3}, {4, 3}}});
  c.push_back({"grouped_linear",
               [](V x) {
                 return grouped_linear(x[0], x[1], x[2], {1, 0, 1, 1, 0}, 2);
               },
               {{5, 3}, {2, 6}, {2, 2}}});
  c.push_back({"complex linear (complex_from, real, imag)",
               [](V x) { return split(linear(complex_from(x[0], x[1]), complex_from(x[2], x[3]), Tensorcd())); },
               {{4, 3}, {4, 3}, {2, 3}, {2, 3}}});
  c.push_back({"complex mul / modulus",
               [](V x) { return modulus(mul(complex_from(x[0], x[1]), complex_from(x[2], x[3]))); },
               {{4, 3}, {4, 3}, {4, 3}, {4, 3}}});
  c.push_back({"complex grouped_linear",
               [](V x) {
                 return split(grouped_linear(complex_from(x[0], x[1]), complex_from(x[2], x[3]),
                                             complex_from(x[4], x[5]), {0, 1, 1, 0}, 2));
               },
               {{4, 3}, {4, 3}, {2, 6}, {2, 6}, {2, 2}, {2, 2}}});
  c.push_back(
      {"wire", [](V x) { return split(wire(complex_from(x[0], x[1]), 5.0, 10.0)); }, {{4, 3}, {4, 3}}, -0.15, 0.15});
  c.push_back({"square", [](V x) { return square(x[0]); }, {{4, 3}}});
  c.push_back(
      {"neg / mul_scalar / add_scalar", [](V x) { return add_scalar(mul_scalar(neg(x[0]), 2.5), 0.5); }, {{4, 3}}});
  c.push_back(
      {"sum / mean / mean_rows / sum_cols",
       [](V x) {
         return concat_cols<double>({add(sum_cols(x[0]), mean(x[0])), transpose(add(mean_rows(x[0]), sum(x[0])))});
       },
       {{4, 3}}});
  c.push_back({"concat_rows / slice_rows / reshape",
               [](V x) {
                 return reshape(slice_rows(concat_rows<double>({x[0], x[1]}), 1, 5), {3, 4});
               },
               {{4, 3}, {2, 3}}});
  c.push_back(
      {"linear_leaky_relu", [](V x) { return linear_leaky_relu(x[0], x[1], x[2], 0.02); }, {{4, 3}, {5, 3}, {1, 5}}});
  c.push_back({"complex div",
               [](V x) { return split(div(complex_from(x[0], x[1]), complex_from(x[2], x[3]))); },
               {{4, 3}, {4, 3}, {4, 3}, {4, 3}},
               0.5,
               2});
  c.push_back({"complex grouped_linear_planes",
               [](V x) {
                 return split(grouped_linear_planes(complex_from(x[0], x[1]), x[2], x[3], 1, 7, {0, 0, 1, 1}, 2));
               },
               {{4, 3}, {4, 3}, {2, 10}, {2, 10}}});
  c.push_back({"complex add (row broadcast)",
               [](V x) { return split(add(complex_from(x[0], x[1]), complex_from(x[2], x[3]))); },
               {{4, 3}, {4, 3}, {1, 3}, {1, 3}}});
  c.push_back({"complex sub (col broadcast)",
               [](V x) { return split(sub(complex_from(x[0], x[1]), complex_from(x[2], x[3]))); },
               {{4, 3}, {4, 3}, {4, 1}, {4, 1}}});
  // Times a complex w, so both parts of the upstream gradient reach complex_from_real.
  c.push_back({"complex_from_real",
               [](V x) { return split(mul(complex_from_real(x[0]), complex_from(x[1], x[2]))); },
               {{4, 3}, {4, 3}, {4, 3}}});
  c.push_back({"conv2d_3x3", [](V x) { return conv2d_3x3(x[0], x[1], x[2]); }, {{1, 2, 5, 4}, {3, 2, 3, 3}, {1, 3}}});
  c.push_back({"avg_pool2x2", [](V x) { return avg_pool2x2(x[0]); }, {{1, 2, 4, 6}}});
  c.push_back({"max_pool2x2", [](V x) { return max_pool2x2(x[0]); }, {{1, 2, 4, 6}}});
  return c;
}

}  // namespace

std::vector<std::string> gradcheck_suite_ops() {
  std::vector<std::string> names;
  for (const Case& c : cases()) names.push_back(c.op);
  return names;
}

std::vector<NamedGradCheck> run_gradcheck_suite(unsigned seed, const std::function<void(int, int)>& progress) {
  std::mt19937_64 rng(seed);
  const std::vector<Case> all = cases();
  std::vector<NamedGradCheck> out;
  for (const Case& c : all) {
    std::uniform_real_distribution<double> u(c.lo, c.hi);
    std::vector<Tensord> inputs;
    for (const Shape& s : c.shapes) {
      std::vector<double> v(static_cast<size_t>(numel_of(s)));
      for (double& x : v) x = u(rng);
      inputs.push_back(Tensord::from(s, v));
    }
    NamedGradCheck r;
    r.op = c.op;
    r.result = gradcheck(c.f, inputs);
    out.push_back(r);
    if (progress) progress(static_cast<int>(out.size()), static_cast<int>(all.size()));
  }
  return out;
}

}  // namespace ag
