// Graph mechanics: backward rules, accumulation, no-grad scope, detach, freeing.
#include "tests/support/ag_test_util.hpp"

using namespace agt;

TEST_CASE("core: backward from a non-scalar throws") {
  Tensord x = randn({3, 2}, 1).set_requires_grad(true);
  const Tensord y = x * x;
  CHECK_THROWS_WITH_AS(y.backward(), doctest::Contains("one-element"), ag::Error);
  CHECK_THROWS_AS(randn({1, 1}, 2).backward(), ag::Error);  // no grad required
}

TEST_CASE("core: gradients accumulate over two backward calls") {
  Tensord x = randn({3, 2}, 3).set_requires_grad(true);
  sum(x * x).backward();
  const std::vector<double> g1 = ag::to_vector(x.grad());
  sum(x * x).backward();
  for (size_t i = 0; i < g1.size(); ++i) {
    CHECK(g1[i] == doctest::Approx(2 * x.values()[i]));
    CHECK(x.grad()[i] == doctest::Approx(2 * g1[i]));
  }
  x.zero_grad();
  CHECK_FALSE(x.has_grad());
  // retained graph run twice accumulates into leaves, not into intermediates
  const Tensord y = ag::tanh(x);
  const Tensord l = sum(y * y);
  l.backward(true);
  const std::vector<double> g2 = ag::to_vector(x.grad());
  l.backward();
  for (size_t i = 0; i < g2.size(); ++i) CHECK(x.grad()[i] == doctest::Approx(2 * g2[i]));
}

TEST_CASE("core: NoGradGuard records nothing, nests, restores") {
  Tensord x = randn({3, 2}, 4).set_requires_grad(true);
  {
    ag::NoGradGuard ng;
    CHECK_FALSE(ag::grad_enabled());
    {
      ag::NoGradGuard inner;
      CHECK_FALSE(ag::grad_enabled());
    }
    CHECK_FALSE(ag::grad_enabled());
    const Tensord y = ag::normalize_rows(ag::linear(x, randn({4, 2}, 5), Tensord()));
    CHECK_FALSE(y.requires_grad());
    CHECK(y.node().parents.empty());
    CHECK_FALSE(static_cast<bool>(y.node().backward_fn));
    CHECK_THROWS_AS(sum(y).backward(), ag::Error);
  }
  CHECK(ag::grad_enabled());
  CHECK(sum(x).requires_grad());
}

TEST_CASE("core: detach cuts the graph") {
  Tensord x = randn({3, 2}, 6).set_requires_grad(true);
  const Tensord y = x * x;
  const Tensord d = y.detach();
  CHECK_FALSE(d.requires_grad());
  CHECK(d.values() == y.values());
  sum(d * x).backward();  // d is a constant: grad = d
  for (size_t i = 0; i < d.values().size(); ++i) CHECK(x.grad()[i] == doctest::Approx(d.values()[i]));
}

TEST_CASE("core: intermediates are freed after backward") {
  Tensord x = randn({4, 3}, 7).set_requires_grad(true);
  std::weak_ptr<ag::Node<double>> mid;
  Tensord loss;
  {
    const Tensord h = ag::channel_norm(ag::relu(x * 2.0));
    mid = h.node_ptr();
    loss = ag::mean(ag::square(h));
  }
  CHECK_FALSE(mid.expired());  // kept alive by the graph
  loss.backward();
  CHECK(mid.expired());  // released: the loss node dropped its parents
  CHECK(x.has_grad());
  CHECK(loss.node().parents.empty());
}

TEST_CASE("core: a small real model is the same in float32 and float64 within 1e-5") {
  const Tensord x = randn({32, 6}, 8), w1 = randn({8, 6}, 9, 0.4), w2 = randn({3, 8}, 10, 0.4),
                b = randn({1, 8}, 11, 0.1), t = randn({32, 3}, 12);
  auto model = [](const auto& x, const auto& w1, const auto& b, const auto& w2, const auto& t) {
    using T = typename std::decay_t<decltype(x)>::Scalar;
    auto h = ag::leaky_relu(ag::channel_norm(ag::linear(x, w1, b)), T(0.02));
    auto y = ag::linear(ag::layer_norm(h), w2, std::decay_t<decltype(x)>());
    auto g = ag::scatter_mean_rows(ag::index_select_rows(y, {0, 5, 7, 31, 2}), {0, 1, 0, 1, 1}, 2);
    return ag::mse_loss(y, t) + ag::mean(ag::norm_rows(g));
  };
  Tensorf xf = to_float(x), w1f = to_float(w1).set_requires_grad(true);
  Tensord w1d = w1.detach().set_requires_grad(true);
  const Tensord ld = model(x, w1d, b, w2, t);
  const Tensorf lf = model(xf, w1f, to_float(b), to_float(w2), to_float(t));
  CHECK(std::abs(double(lf.item()) - ld.item()) < 1e-5);
  ld.backward();
  lf.backward();
  double err = 0;
  for (size_t i = 0; i < w1d.grad().size(); ++i) err = std::max(err, std::abs(double(w1f.grad()[i]) - w1d.grad()[i]));
  CHECK(err < 1e-5);
}

TEST_CASE("core: a second backward through a freed graph throws") {
  Tensord x = randn({3, 2}, 13).set_requires_grad(true);
  const Tensord l = sum(ag::tanh(x) * x);
  l.backward();
  const std::vector<double> g = ag::to_vector(x.grad());
  CHECK_THROWS_WITH_AS(l.backward(), doctest::Contains("retain_graph"), ag::Error);
  CHECK(x.grad() == g);  // nothing changed by the refused call
}

TEST_CASE("core: a freed intermediate in a new graph throws instead of acting as a leaf") {
  Tensord x = randn({3, 2}, 14).set_requires_grad(true);
  const Tensord h = ag::tanh(x);
  sum(h * h).backward();
  const std::vector<double> g = ag::to_vector(x.grad());
  const Tensord l2 = sum(h * 3.0);
  CHECK_THROWS_WITH_AS(l2.backward(), doctest::Contains("detach"), ag::Error);
  CHECK(x.grad() == g);
  // detach() makes the intent explicit: h is a constant, x gets only the direct term
  const Tensord l3 = sum(h.detach() * x);
  l3.backward();
  for (size_t i = 0; i < g.size(); ++i) CHECK(x.grad()[i] == doctest::Approx(g[i] + h.values()[i]));
}

TEST_CASE("core: a retained intermediate reused in a second loss gets its inputs a gradient") {
  Tensord x = randn({3, 2}, 15).set_requires_grad(true);
  const Tensord h = x * x;
  sum(h).backward(true);
  x.zero_grad();
  sum(h * 3.0).backward();
  for (size_t i = 0; i < x.values().size(); ++i) CHECK(x.grad()[i] == doctest::Approx(6 * x.values()[i]));
}

// Ops whose outputs skip zeroing (new_output_overwritten) must write every element: each runs
// right after a NaN-filled tensor of its output's size is freed, so that it gets that memory.
TEST_CASE("core: outputs left unset at allocation are written everywhere (recycled NaN memory)") {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Tensord x = randn({37, 11}, 3), w = randn({13, 11}, 4), b = randn({1, 13}, 5), y = randn({37, 11}, 6);
  const ag::Index rows = rand_index(37, 37, 7);
  auto run = [&](const char* what, const ag::Shape& shape, auto op) {
    const double* recycled = nullptr;
    {
      const Tensord junk = Tensord::full(shape, nan);
      recycled = junk.data();
    }
    const Tensord out = op();
    CAPTURE(what);
    CHECK(all_finite(out.values()));
    return out.data() == recycled;
  };
  int reused = 0;
  reused += run("linear", {37, 13}, [&] { return ag::linear(x, w, b); });
  reused += run("linear_leaky_relu", {37, 13}, [&] { return ag::linear_leaky_relu(x, w, b, 0.1); });
  reused += run("index_select_rows", {37, 11}, [&] { return ag::index_select_rows(x, rows); });
  reused += run("add", {37, 11}, [&] { return x + y; });
  reused += run("tanh", {37, 11}, [&] { return ag::tanh(x); });
  MESSAGE(reused << " of 5 outputs landed in the freed NaN memory");
  CHECK(reused >= 3);  // the test is only meaningful if the allocator hands that memory back
}

// Columns claimed for writing are the op's to fill; the rest of a claimed gradient is zeroed
// before anything reads it (Node::settle_grad), and later adders see a plain gradient.
TEST_CASE("core: gradient columns claimed for writing, the rest zeroed when settled") {
  ag::Node<double> n;
  n.shape = {3, 10};
  n.value.assign(30, 1.0);
  const ag::ColumnRanges a{{2, 5}, {7, 8}};
  CHECK(n.grad_columns_unwritten(a));
  n.claim_grad_columns(a);
  CHECK(n.unwritten_columns == ag::ColumnRanges{{0, 2}, {5, 7}, {8, 10}});
  CHECK(std::isnan(n.grad[0]));  // poisoned: not yet zeroed
  for (int64_t r = 0; r < 3; ++r)
    for (const auto& [b, e] : a)
      for (int64_t c = b; c < e; ++c) n.grad[r * 10 + c] = 10.0 * r + c;
  CHECK_FALSE(n.grad_columns_unwritten({{4, 6}}));  // column 4 is written
  CHECK(n.grad_columns_unwritten({{5, 7}, {9, 10}}));
  CHECK_THROWS_WITH_AS(n.claim_grad_columns({{1, 3}}), doctest::Contains("already"), ag::Error);
  n.claim_grad_columns({{5, 7}});
  for (int64_t r = 0; r < 3; ++r) n.grad[r * 10 + 5] = n.grad[r * 10 + 6] = -1.0;
  n.ensure_grad();  // an op about to add: the unwritten columns 0, 1, 8, 9 become zero
  CHECK(n.unwritten_columns.empty());
  for (int64_t r = 0; r < 3; ++r)
    for (int64_t c = 0; c < 10; ++c) {
      CAPTURE(r);
      CAPTURE(c);
      const double want = (c >= 2 && c < 5) || c == 7 ? 10.0 * r + c : (c == 5 || c == 6) ? -1.0 : 0.0;
      CHECK(n.grad[r * 10 + c] == want);
    }
  CHECK_FALSE(n.grad_columns_unwritten({{0, 1}}));  // a settled gradient holds every column
  n.zero_grad();
  CHECK(n.grad_columns_unwritten({{0, 10}}));
}

// The first gradient into a tensor is written, later ones added (Node::claim_whole_grad):
// mul(x, x) writes a's part and adds b's into the same buffer; x also feeds tanh and a linear
// layer, and a second backward adds to all of it. Claimed buffers start as NaN here.
TEST_CASE("core: first gradients written, later ones added, also when both operands are one tensor") {
  Tensord x = randn({6, 4}, 11), w = randn({3, 4}, 12);
  x.set_requires_grad(true);
  w.set_requires_grad(true);
  auto loss = [&] {
    return ag::add(ag::add(ag::sum(ag::mul(x, x)), ag::sum(ag::tanh(x))), ag::sum(ag::linear(x, w, Tensord())));
  };
  loss().backward();
  for (int pass = 1; pass <= 2; ++pass) {
    CAPTURE(pass);
    for (int64_t r = 0; r < 6; ++r)
      for (int64_t c = 0; c < 4; ++c) {
        const double v = x.at(r, c), t = std::tanh(v);
        double want = 2 * v + (1 - t * t);
        for (int64_t o = 0; o < 3; ++o) want += w.at(o, c);
        CHECK(x.grad()[r * 4 + c] == doctest::Approx(pass * want).epsilon(1e-12));
      }
    for (int64_t o = 0; o < 3; ++o)
      for (int64_t c = 0; c < 4; ++c) {
        double want = 0;
        for (int64_t r = 0; r < 6; ++r) want += x.at(r, c);
        CHECK(w.grad()[o * 4 + c] == doctest::Approx(pass * want).epsilon(1e-12));
      }
    if (pass == 1) loss().backward();
  }
}

// add and sub hand their output's gradient buffer to a fresh operand (Node::take_grad)
// instead of copying it, only when nothing reads that gradient again.
TEST_CASE("core: a passed-through gradient is handed over only at its last use") {
  ag::Node<double> out, a, b;
  out.shape = a.shape = b.shape = {2, 3};
  out.value.assign(6, 0.0), a.value.assign(6, 0.0), b.value.assign(6, 0.0);
  out.grad.assign(6, 2.0);
  CHECK_FALSE(a.take_grad(out));  // not at its last use (retain_graph, or outside backward)
  out.grad_is_last_use = true;
  b.grad.assign(6, 1.0);
  CHECK_FALSE(b.take_grad(out));  // b already has a gradient: the op adds instead
  CHECK_FALSE(out.take_grad(out));
  const double* buffer = out.grad.data();
  CHECK(a.take_grad(out));
  CHECK(a.grad.data() == buffer);
  CHECK(out.grad.empty());
  CHECK(a.grad == ag::Storage<double>(6, 2.0));

  // Through backward: values are right whether the buffer moved or not, and a retained graph
  // keeps every intermediate's gradient readable and gives the same result twice.
  auto check = [](bool retain) {
    CAPTURE(retain);
    Tensord x = randn({4, 3}, 21).set_requires_grad(true), y = randn({4, 3}, 22).set_requires_grad(true);
    const Tensord w = randn({4, 3}, 23);
    const Tensord s = ag::add(x, y), d = ag::sub(s, ag::mul(y, y)), t = ag::add(d, d);
    ag::sum(ag::mul(t, w)).backward(retain);
    if (retain) CHECK(s.grad() == (w * 2.0).values());
    for (int64_t i = 0; i < 12; ++i) {
      CHECK(x.grad()[i] == doctest::Approx(2 * w.values()[i]).epsilon(1e-15));
      CHECK(y.grad()[i] == doctest::Approx(2 * w.values()[i] * (1 - 2 * y.values()[i])).epsilon(1e-15));
    }
    if (!retain) return;
    const ag::Storage<double> gx = x.grad(), gy = y.grad();
    x.zero_grad(), y.zero_grad();
    ag::sum(ag::mul(t, w)).backward();
    CHECK(x.grad() == gx);
    CHECK(y.grad() == gy);
  };
  check(false);
  check(true);
}
