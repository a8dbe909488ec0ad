// Issue #15 leftovers: a failed or killed write leaves no temp behind (and a stale one does
// not disturb the next run; a kill at any rename of a replace loses nothing), the VGG weights
// are found from any working folder, and import-md refuses coordinates a float32 dataset
// cannot hold.
#include "tests/support/cli_fixtures.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <unistd.h>

using gdsr_test::check_one_line_error;
using gdsr_test::count_prefixed;
using gdsr_test::gdsr_run;
using gdsr_test::import_to;
using gdsr_test::Run;
using gdsr_test::slurp;
using gdsr_test::TempDir;
using gdsr_test::write_exports;
namespace fs = std::filesystem;

namespace {

// A pid no process has: pid_max itself (pids are below it).
std::string dead_pid() {
  long max = 4194304;
  std::ifstream("/proc/sys/kernel/pid_max") >> max;
  return std::to_string(max);
}

// Every file under `dir` with its bytes, in path order (to show nothing changed).
std::string folder_bytes(const std::string& dir) {
  std::vector<std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  std::string all;
  for (const auto& f : files) all += f + "\n" + slurp(f) + "\n";
  return all;
}

// strace kills gdsr at its n-th rename(2) (fault injection); empty when strace cannot run.
std::string kill_at_rename(int n) {
  static const bool ok = std::system("strace -f -o /dev/null true >/dev/null 2>&1") == 0;
  if (!ok) return "";
  return "strace -f -o /dev/null -e trace=rename -e inject=rename:signal=KILL:when=" + std::to_string(n) + " ";
}

// The shell runs gdsr with files limited to `kb` KiB and SIGXFSZ ignored: a write beyond
// fails with EFBIG, as on a full disk.
std::string small_disk(int kb) { return "trap '' XFSZ; ulimit -f " + std::to_string(kb * 2) + "; "; }

}  // namespace

TEST_CASE("cli writes: a dataset write that fails on a full disk removes its temp folder") {
  TempDir dir("writes_full");
  write_exports(dir, 3);
  REQUIRE(gdsr_run(dir, import_to(dir, dir / "ds")).status == 0);
  const std::string before = folder_bytes(dir / "ds");
  // 16 KiB holds the manifest and the OBJs but not the 256x256 UV raster.
  const Run r = gdsr_run(dir, import_to(dir, dir / "ds"), small_disk(16));
  check_one_line_error(r, "ds.tmp.");
  CHECK(count_prefixed(dir.path.string(), "ds.") == 0);
  CHECK(folder_bytes(dir / "ds") == before);
  const Run fresh = gdsr_run(dir, import_to(dir, dir / "new"), small_disk(16));
  CHECK(fresh.status == 1);
  CHECK(count_prefixed(dir.path.string(), "new") == 0);
}

TEST_CASE("cli writes: temps left by a killed run are removed and do not disturb the next run") {
  TempDir dir("writes_stale");
  write_exports(dir, 3);
  REQUIRE(gdsr_run(dir, import_to(dir, dir / "ds")).status == 0);
  // A killed dataset write (pid gone) and one still running (this test's pid).
  const std::string dead = dir / ("ds.tmp." + dead_pid()), live = dir / ("ds.tmp." + std::to_string(::getpid()));
  for (const std::string& t : {dead, live}) {
    fs::create_directories(t);
    std::ofstream(t + "/manifest.json") << "{\"half\": ";
  }
  // A user's folder that only looks like a temp is left alone (it holds a folder).
  const std::string lookalike = dir / ("ds.tmp.1" + dead_pid());
  fs::create_directories(lookalike + "/photos");
  // A killed prediction write: a half array beside a complete prediction.
  const std::string pred = dir / "pred";
  gdsr_test::write_pred(pred, gdsr_test::wave_dataset(3).hr_frames, 0, dir / "ds", 3);
  std::ofstream(pred + "/pred_hr.bin.tmp." + dead_pid()) << "GDSRARR";

  REQUIRE(gdsr_run(dir, import_to(dir, dir / "ds")).status == 0);
  CHECK_FALSE(fs::exists(dead));
  CHECK(fs::exists(live + "/manifest.json"));
  CHECK(fs::exists(lookalike + "/photos"));
  CHECK(gdsr_run(dir, "data check --data '" + (dir / "ds") + "'").status == 0);
  const Run ev = gdsr_run(dir, "eval --no-export --pred '" + pred + "' --data '" + (dir / "ds") + "'");
  CHECK(ev.status == 0);
  if (ev.status != 0) MESSAGE("stderr: " << ev.err);
}

TEST_CASE("cli writes: train finds the default VGG weights from any working folder") {
  TempDir dir("writes_vgg");
  gdsr::write_dataset(dir / "ds", gdsr_test::wave_dataset(3));
  const std::string train = "train --data '" + (dir / "ds") + "' --config '" + GDSR_SOURCE_DIR +
                            "/configs/tiny.json' --patches 1 --patch-size 32 --max-steps 1 --log-every 0 --out '" +
                            (dir / "run") + "'";
  const Run r = gdsr_run(dir, train, "cd / && env -u GDSR_VGG19_WEIGHTS ");
  CHECK(r.status == 0);
  if (r.status != 0) MESSAGE("stderr: " << r.err);
  CHECK(r.err.find("VGG19") == std::string::npos);
  CHECK(fs::exists(dir / "run/model.ckpt"));
}

TEST_CASE("cli writes: import-md refuses coordinates beyond the float range naming the file") {
  TempDir dir("writes_float");
  write_exports(dir, 3);
  std::string obj = slurp(dir / "hr/f1.obj");
  obj.replace(obj.find("v ") + 2, obj.find(' ', obj.find("v ") + 2) - obj.find("v ") - 2, "1e39");
  std::ofstream(dir / "hr/f1.obj", std::ios::trunc) << obj;
  check_one_line_error(gdsr_run(dir, import_to(dir, dir / "ds")), "f1.obj");
  CHECK_FALSE(fs::exists(dir / "ds"));
  // Within float range before --scale, beyond it after: the scaled value is what is stored.
  obj.replace(obj.find("1e39"), 4, "1e37");
  std::ofstream(dir / "hr/f1.obj", std::ios::trunc) << obj;
  check_one_line_error(gdsr_run(dir, import_to(dir, dir / "ds") + " --scale 100"), "f1.obj");
  CHECK_FALSE(fs::exists(dir / "ds"));
}

TEST_CASE("cli writes: a dataset replace killed at each rename keeps the old dataset and the next run recovers") {
  if (kill_at_rename(1).empty()) {
    MESSAGE("SKIPPED: strace missing or not allowed to trace here");
    return;
  }
  TempDir dir("writes_kill");
  write_exports(dir, 3);
  const std::string cmd[2] = {import_to(dir, dir / "ds") + " --fps 30", import_to(dir, dir / "ds") + " --fps 25"};
  std::string bytes[2];
  for (int k = 0; k < 2; ++k) {
    REQUIRE(gdsr_run(dir, cmd[k]).status == 0);
    bytes[k] = folder_bytes(dir / "ds");
  }
  REQUIRE(bytes[0] != bytes[1]);
  int kills = 0;
  for (int n = 1, was = 1; n <= 40; ++n, was = 1 - was) {
    // The folder holds dataset `was`; the other one replaces it and is killed at rename n.
    const int now = 1 - was;
    INFO("killed at rename " << n);
    const Run r =
        gdsr_run(dir, cmd[now],
                 "strace -f -o /dev/null -e trace=rename -e inject=rename:signal=KILL:when=" + std::to_string(n) + " ");
    if (r.status == 0) break;  // the replace has fewer than n renames
    ++kills;
    if (fs::exists(dir / "ds/manifest.json"))
      CHECK(folder_bytes(dir / "ds") == bytes[was]);
    else  // killed between "old aside" and "new in": only DIR.old.<pid> holds it
      CHECK(count_prefixed(dir.path.string(), "ds.old.") == 1);
    const Run next = gdsr_run(dir, cmd[now]);  // restores, sweeps the dead temp, replaces
    CHECK(next.status == 0);
    CHECK(folder_bytes(dir / "ds") == bytes[now]);
    CHECK(count_prefixed(dir.path.string(), "ds.") == 0);
  }
  CHECK(kills == 16);  // one rename per file (14 without a body) and the two of the swap
  MESSAGE("killed at each of " << kills << " renames");
}

TEST_CASE(
    "cli writes: infer killed at each rename leaves the old prediction or a refused one and the next run recovers") {
  if (kill_at_rename(1).empty()) {
    MESSAGE("SKIPPED: strace missing or not allowed to trace here");
    return;
  }
  TempDir dir("writes_kill_infer");
  gdsr::write_dataset(dir / "ds", gdsr_test::wave_dataset(4));
  REQUIRE(gdsr_run(dir, "train --data '" + (dir / "ds") + "' --config '" + GDSR_SOURCE_DIR +
                            "/configs/tiny.json' --no-vgg --patches 1 --patch-size 16 --max-steps 1 --out '" +
                            (dir / "run") + "'")
              .status == 0);
  // Two predictions that differ: frames 0..3 and 1..3.
  const std::string infer =
      "infer --model '" + (dir / "run/model.ckpt") + "' --data '" + (dir / "ds") + "' --out '" + (dir / "pred") + "'";
  const std::string cmd[2] = {infer, infer + " --first 1"};
  const std::string eval = "eval --no-export --data '" + (dir / "ds") + "' --pred '" + (dir / "pred") + "'";
  // A prediction's content: its arrays and its first frame (prediction.json also records timings).
  auto content = [&] {
    const std::string meta = slurp(dir / "pred/prediction.json");
    return slurp(dir / "pred/pred_hr.bin") + slurp(dir / "pred/pred_lr.bin") +
           meta.substr(meta.find("\"first_frame\""), 20);
  };
  std::string bytes[2];
  for (int k = 0; k < 2; ++k) {
    REQUIRE(gdsr_run(dir, cmd[k]).status == 0);
    bytes[k] = content();
  }
  REQUIRE(bytes[0] != bytes[1]);
  int kills = 0;
  for (int n = 1, was = 1; n <= 40; ++n, was = 1 - was) {
    const int now = 1 - was;
    INFO("killed at rename " << n);
    const Run r = gdsr_run(dir, cmd[now], kill_at_rename(n));
    if (r.status == 0) break;
    ++kills;
    // The old prediction whole, or (killed while moving the new files in) one without
    // prediction.json that eval refuses naming it; never a mix that eval would score.
    const Run e = gdsr_run(dir, eval);
    if (fs::exists(dir / "pred/prediction.json"))
      CHECK(content() == bytes[was]);
    else
      CHECK(e.err.find("prediction.json") != std::string::npos);
    const Run next = gdsr_run(dir, cmd[now]);
    CHECK(next.status == 0);
    CHECK(content() == bytes[now]);
    CHECK(count_prefixed(dir.path.string(), "pred.") == 0);
  }
  CHECK(kills >= 6);  // the stage's files, then the moves into pred/
  MESSAGE("killed at each of " << kills << " renames");
}
