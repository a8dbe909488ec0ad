// Data-parallel steps without MPI: two ranks as two threads whose all-reduce is a shared
// sum, one frame per rank and step, against one process with two frames per step. The
// same comparison through mpirun is in tests/cli/test_cli_train_mpi.cpp.
#include <doctest/doctest.h>

#include "nn/checkpoint.hpp"
#include "tests/support/data_fixtures.hpp"
#include "tests/support/train_options.hpp"
#include "train/trainer.hpp"

#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>

namespace {

// Sums the buffers of n threads; every caller gets the total.
class ThreadAllReduce {
 public:
  explicit ThreadAllReduce(int n) : n_(n) {}
  void operator()(std::vector<double>& buf) {
    std::unique_lock<std::mutex> lock(m_);
    const int generation = generation_;
    if (arrived_ == 0) sum_.assign(buf.size(), 0.0);
    REQUIRE(sum_.size() == buf.size());
    for (size_t i = 0; i < buf.size(); ++i) sum_[i] += buf[i];
    if (++arrived_ == n_) {
      result_ = sum_;
      arrived_ = 0;
      ++generation_;
      cv_.notify_all();
    } else {
      cv_.wait(lock, [&] { return generation_ != generation; });
    }
    buf = result_;
  }

 private:
  int n_, arrived_ = 0, generation_ = 0;
  std::vector<double> sum_, result_;
  std::mutex m_;
  std::condition_variable cv_;
};

}  // namespace

TEST_CASE("trainer: two ranks with one frame each match one process with two frames per step") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  gdsr_test::TempDir dir("trainer_ranks");
  gdsr::TrainOptions o = gdsr_test::tiny_train_options<gdsr::TrainOptions>();
  o.epochs = 2;  // 6 steps of 2 frames, patches and training noise on
  o.frames_per_step = 2;
  o.checkpoint = dir / "one.ckpt";
  std::vector<double> one_losses, two_losses;
  gdsr::train_gdsr({&d}, o, [&](const gdsr::TrainLog& L) { one_losses.push_back(L.loss); });

  ThreadAllReduce reduce(2);
  std::vector<std::thread> ranks;
  std::vector<std::string> errors(2);
  for (int r = 0; r < 2; ++r)
    ranks.emplace_back([&, r] {
      gdsr::TrainOptions p = o;
      p.frames_per_step = 1;
      p.rank = r;
      p.ranks = 2;
      p.allreduce_sum = [&](std::vector<double>& buf) { reduce(buf); };
      p.checkpoint = r == 0 ? dir / "two.ckpt" : "";
      try {
        gdsr::train_gdsr({&d}, p, [&](const gdsr::TrainLog& L) {
          if (r == 0) two_losses.push_back(L.loss);
        });
      } catch (const std::exception& e) {
        errors[static_cast<size_t>(r)] = e.what();
      }
    });
  for (auto& t : ranks) t.join();
  CHECK(errors[0].empty());
  CHECK(errors[1].empty());
  REQUIRE(one_losses.size() == 6);
  REQUIRE(two_losses.size() == 6);
  for (size_t i = 0; i < 6; ++i) {
    INFO("step " << i + 1);
    CHECK(two_losses[i] == one_losses[i]);
  }

  // The trainer sums per-frame float gradients in double in both cases, and a sum of two
  // doubles does not depend on the order: bit-identical, not just close (with more than two
  // ranks or frames per rank the grouping differs and only float tolerance holds).
  const nn::Checkpoint a = nn::read_checkpoint(dir / "one.ckpt"), b = nn::read_checkpoint(dir / "two.ckpt");
  REQUIRE(a.entries.size() == b.entries.size());
  double worst = 0;
  int params = 0;
  for (size_t i = 0; i < a.entries.size(); ++i) {
    if (a.entries[i].name.rfind("param/", 0) != 0) continue;
    ++params;
    const auto va = a.read<float>(a.entries[i].name), vb = b.read<float>(b.entries[i].name);
    for (size_t k = 0; k < va.size(); ++k)
      worst = std::max(worst, std::abs(double(va[k]) - vb[k]) / (1e-3 + std::abs(double(va[k]))));
  }
  MESSAGE("largest relative parameter difference, 2 ranks vs 1 process: " << worst);
  CHECK(params > 0);
  CHECK(worst == 0.0);
}
