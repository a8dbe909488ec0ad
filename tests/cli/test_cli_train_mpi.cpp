// `mpirun -np 2 gdsr train` (a build with -DGDSR_MPI=ON): two ranks with one frame each
// per step against one process with two frames per step, and a rank error ending the run.
#include "nn/checkpoint.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>

using gdsr_test::gdsr_run;
using gdsr_test::Run;
using gdsr_test::TempDir;

TEST_CASE("cli train mpi: two ranks with one frame each match one process with two frames per step") {
#ifndef GDSR_WITH_MPI
  MESSAGE("SKIPPED: this build has no MPI (cmake -DGDSR_MPI=ON with Debian libopenmpi-dev and openmpi-bin)");
  return;
#else
  REQUIRE_MESSAGE(std::system("command -v mpirun >/dev/null 2>&1") == 0, "mpirun not found (Debian openmpi-bin)");
  TempDir dir("cli_train_mpi");
  const std::string data = dir / "wave";
  gdsr::write_dataset(data, gdsr_test::wave_dataset());
  const std::string args = std::string("train --data '") + data + "' --config '" + GDSR_SOURCE_DIR +
                           "/configs/tiny.json' --no-vgg --patches 2 --patch-size 32 --epochs 4 --log-every 0";
  const Run one = gdsr_run(dir, args + " --frames-per-step 2 --out '" + (dir / "one") + "'");
  REQUIRE(one.status == 0);
  // As root, Open MPI wants both variables; --oversubscribe: the machine may have fewer cores.
  const std::string mpirun = "env OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 mpirun -np 2 --oversubscribe ";
  const std::string out = dir / "mpi.out", err = dir / "mpi.err";
  const std::string cmd = mpirun + "'" + GDSR_BINARY_DIR + "/gdsr' " + args + " --frames-per-step 1 --out '" +
                          (dir / "two") + "' >'" + out + "' 2>'" + err + "'";
  const int rc = std::system(cmd.c_str());
  INFO("stdout: " << gdsr_test::slurp(out) << "\nstderr: " << gdsr_test::slurp(err));
  REQUIRE(rc == 0);
  const std::string printed = gdsr_test::slurp(out);
  CHECK(printed.find("2 ranks, 1 frame(s) per rank and step") != std::string::npos);
  CHECK(printed.find("all-reduce:") != std::string::npos);
  CHECK(printed.find("trained 12 steps") != std::string::npos);  // printed once, by rank 0

  const nn::Checkpoint a = nn::read_checkpoint(dir / "one/model.ckpt"), b = nn::read_checkpoint(dir / "two/model.ckpt");
  CHECK(b.step == 12);
  REQUIRE(a.entries.size() == b.entries.size());
  // Per-frame gradients summed in double in pairs in both runs: equal bit for bit (with more
  // ranks the grouping differs and float tolerance is what holds).
  int differ = 0;
  for (size_t i = 0; i < a.entries.size(); ++i) differ += a.entries[i].bytes != b.entries[i].bytes;
  CHECK(differ == 0);

  // A bad flag on every rank: one error line per rank, a non-zero exit, no hang.
  const std::string bad = mpirun + "'" + GDSR_BINARY_DIR + "/gdsr' " + args + " --lr -1 --out '" + (dir / "bad") +
                          "' >'" + out + "' 2>'" + err + "'";
  CHECK(std::system(bad.c_str()) != 0);
  CHECK(gdsr_test::slurp(err).find("gdsr: error: train: --lr must be finite and > 0") != std::string::npos);
  CHECK_FALSE(std::filesystem::exists(dir / "bad"));
#endif
}
