// Checkpoints: bit-exact round trip of parameters and optimizer state, refusal of
// corrupted, truncated and mismatching files.
#include "autograd/autograd.hpp"
#include "nn/checkpoint.hpp"
#include "nn/mlp.hpp"

#include <doctest/doctest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

namespace {
namespace fs = std::filesystem;

std::string tmp_path(const std::string& name) {
  const fs::path dir = fs::path(GDSR_BINARY_DIR) / "test_tmp";
  fs::create_directories(dir);
  return (dir / name).string();
}

std::vector<char> read_all(const std::string& p) {
  std::ifstream f(p, std::ios::binary);
  return std::vector<char>((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}
void write_all(const std::string& p, const std::vector<char>& b) {
  std::ofstream f(p, std::ios::binary | std::ios::trunc);
  f.write(b.data(), static_cast<std::streamsize>(b.size()));
}

// A few training steps so that the optimizer state is non-trivial.
template <class T> void train(nn::MLPStack<T>& net, nn::AdamW<T>& opt, int steps, uint64_t seed) {
  nn::Rng rng(seed);
  for (int s = 0; s < steps; ++s) {
    ag::Tensor<T> x = ag::Tensor<T>::zeros({16, 3});
    for (auto& v : x.values()) v = static_cast<T>(rng.normal(0, 1));
    opt.zero_grad();
    ag::mean(ag::square(net.forward(x))).backward();
    opt.step();
  }
}

template <class A, class B> bool bits_equal(const A& a, const B& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
}
}  // namespace

TEST_CASE("checkpoint: parameters, optimizer state, step and metadata round-trip bit-exactly") {
  for (bool ams : {false, true}) {
    nn::Rng r1(1), r2(2);
    nn::MLPStack<float> a({3, 8, 4}, true, true, r1), b({3, 8, 4}, true, true, r2);
    nn::AdamWOptions o;
    o.amsgrad = ams;
    o.lr = 3e-3;
    nn::AdamW<float> oa(a.named_parameters(), o), ob(b.named_parameters(), o);
    train(a, oa, 5, 10);
    const std::string path = tmp_path(ams ? "roundtrip_ams.ckpt" : "roundtrip.ckpt");
    nn::save_checkpoint(path, a, &oa, 1234, R"({"config":"tiny","epoch":3})");
    CHECK_FALSE(fs::exists(path + ".tmp"));

    const nn::Checkpoint ck = nn::load_checkpoint(path, b, &ob);
    CHECK(ck.step == 1234);
    CHECK(ck.metadata == R"({"config":"tiny","epoch":3})");
    auto pa = a.named_parameters(), pb = b.named_parameters();
    for (size_t i = 0; i < pa.size(); ++i) CHECK(bits_equal(pa[i].second.values(), pb[i].second.values()));
    CHECK(ob.steps_taken() == 5);
    CHECK(ob.lr() == oa.lr());
    for (size_t i = 0; i < oa.slots().size(); ++i) {
      CHECK(oa.slots()[i].step == ob.slots()[i].step);
      CHECK(bits_equal(oa.slots()[i].m, ob.slots()[i].m));
      CHECK(bits_equal(oa.slots()[i].v, ob.slots()[i].v));
      CHECK(bits_equal(oa.slots()[i].vmax, ob.slots()[i].vmax));
    }
    // Resumed training continues exactly as uninterrupted training.
    train(a, oa, 3, 99);
    train(b, ob, 3, 99);
    pa = a.named_parameters();
    pb = b.named_parameters();
    for (size_t i = 0; i < pa.size(); ++i) CHECK(bits_equal(pa[i].second.values(), pb[i].second.values()));
    // Saving again gives the identical file.
    const std::string again = tmp_path("again.ckpt");
    nn::save_checkpoint(path, a, &oa, 7, "{}");
    nn::save_checkpoint(again, b, &ob, 7, "{}");
    CHECK(read_all(path) == read_all(again));
  }
}

TEST_CASE("checkpoint: a flipped byte, truncation or trailing bytes are refused naming the file") {
  nn::Rng rng(3);
  nn::MLPStack<double> net({2, 5, 2}, false, false, rng);
  const std::string path = tmp_path("good.ckpt"), bad = tmp_path("bad.ckpt");
  nn::save_checkpoint<double>(path, net, nullptr, 1, "{}");
  const std::vector<char> good = read_all(path);
  REQUIRE(good.size() > 100);

  // Flip a byte in the payload, in the header's checksum, in the magic.
  for (size_t pos : {good.size() / 2, good.size() - 1, size_t(40), size_t(25), size_t(2)}) {
    std::vector<char> b = good;
    b[pos] ^= 0x10;
    write_all(bad, b);
    INFO("flipped byte " << pos);
    CHECK_THROWS_WITH_AS(nn::load_checkpoint<double>(bad, net, nullptr), doctest::Contains("bad.ckpt"), ag::Error);
  }
  for (size_t keep : {size_t(0), size_t(10), size_t(32), good.size() / 2, good.size() - 1}) {
    write_all(bad, std::vector<char>(good.begin(), good.begin() + static_cast<long>(keep)));
    INFO("truncated to " << keep);
    CHECK_THROWS_WITH_AS(nn::read_checkpoint(bad), doctest::Contains("bad.ckpt"), ag::Error);
  }
  CHECK_THROWS_WITH_AS(nn::read_checkpoint(bad), doctest::Contains("truncated"), ag::Error);
  std::vector<char> longer = good;
  longer.push_back(0);
  write_all(bad, longer);
  CHECK_THROWS_WITH_AS(nn::read_checkpoint(bad), doctest::Contains("trailing"), ag::Error);
  CHECK_THROWS_WITH_AS(nn::read_checkpoint(tmp_path("does_not_exist.ckpt")), doctest::Contains("does_not_exist"),
                       ag::Error);
  // The model is untouched by refused loads.
  nn::Rng rng2(3);
  nn::MLPStack<double> same({2, 5, 2}, false, false, rng2);
  CHECK(net.named_parameters()[0].second.values() == same.named_parameters()[0].second.values());
}

TEST_CASE("checkpoint: name, shape, dtype and optimizer mismatches are refused") {
  nn::Rng rng(4);
  nn::MLPStack<float> net({2, 5, 2}, false, false, rng);
  const std::string path = tmp_path("mismatch.ckpt");
  nn::save_checkpoint<float>(path, net, nullptr, 0, "{}");

  nn::MLPStack<float> wider({2, 6, 2}, false, false, rng);
  CHECK_THROWS_WITH_AS(nn::load_checkpoint<float>(path, wider, nullptr), doctest::Contains("0.linear1.weight"),
                       ag::Error);
  nn::MLPStack<float> deeper({2, 5, 2, 2}, false, false, rng);
  CHECK_THROWS_WITH_AS(nn::load_checkpoint<float>(path, deeper, nullptr), doctest::Contains("missing"), ag::Error);
  nn::MLPStack<float> shallower({2, 5}, false, false, rng);
  CHECK_THROWS_WITH_AS(nn::load_checkpoint<float>(path, shallower, nullptr), doctest::Contains("not in the model"),
                       ag::Error);
  nn::MLPStack<double> dbl({2, 5, 2}, false, false, rng);
  CHECK_THROWS_WITH_AS(nn::load_checkpoint<double>(path, dbl, nullptr), doctest::Contains("float32"), ag::Error);
  nn::AdamW<float> opt(net.named_parameters());
  CHECK_THROWS_WITH_AS(nn::load_checkpoint<float>(path, net, &opt), doctest::Contains("optimizer"), ag::Error);
}

TEST_CASE("checkpoint: an optimizer lr outside its domain is refused before the model changes") {
  nn::Rng rng(5);
  nn::MLPStack<float> net({3, 5, 2}, false, false, rng);
  nn::AdamW<float> opt(net.named_parameters());
  train(net, opt, 2, 6);
  const std::string path = tmp_path("nan_lr.ckpt");
  nn::save_checkpoint<float>(path, net, &opt, 2, "{}");
  // The options' first entry (lr) set to NaN, and the file rewritten with a valid checksum.
  nn::Checkpoint ck = nn::read_checkpoint(path);
  bool found = false;
  for (nn::CheckpointEntry& e : ck.entries)
    if (e.name == "adamw/#options") {
      const double nan = std::numeric_limits<double>::quiet_NaN();
      std::memcpy(e.bytes.data(), &nan, sizeof nan);
      found = true;
    }
  REQUIRE(found);
  nn::write_checkpoint(path, ck);

  nn::MLPStack<float> other({3, 5, 2}, false, false, rng);
  nn::AdamW<float> other_opt(other.named_parameters());
  const std::vector<float> before = ag::to_vector(other.named_parameters().front().second.values());
  CHECK_THROWS_WITH_AS(nn::load_checkpoint<float>(path, other, &other_opt), doctest::Contains("lr must be"), ag::Error);
  CHECK(bits_equal(other.named_parameters().front().second.values(), before));  // untouched
  CHECK(other_opt.lr() == 1e-3);
  std::remove(path.c_str());
}
