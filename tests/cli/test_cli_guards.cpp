// Issue #15 "nothing lost, nothing silently wrong": the built gdsr binary refuses bad output
// folders, bad numbers, mismatched predictions and bad files with one line, before any work,
// and leaves what was there untouched.
#include "gdsr/geometry/obj_io.hpp"
#include "tests/support/cli_fixtures.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <unistd.h>

using gdsr_test::check_one_line_error;
using gdsr_test::count_prefixed;
using gdsr_test::gdsr_run;
using gdsr_test::import_to;
using gdsr_test::make_to;
using gdsr_test::Run;
using gdsr_test::slurp;
using gdsr_test::TempDir;
using gdsr_test::write_exports;
using gdsr_test::write_pred;
namespace fs = std::filesystem;

TEST_CASE("cli guards: --out refuses a folder that is not a dataset and a regular file") {
  TempDir dir("guard_out");
  write_exports(dir, 3);
  fs::create_directories(dir / "mine");
  std::ofstream(dir / "mine/notes.txt") << "my notes\n";
  std::ofstream(dir / "file.txt") << "a file\n";
  for (const std::string& cmd : {make_to(dir / "mine"), import_to(dir, dir / "mine")}) {
    const Run r = gdsr_run(dir, cmd);
    check_one_line_error(r, "not a gdsr dataset");
    CHECK(r.out.find("body:") == std::string::npos);  // refused before loading the motion
  }
  for (const std::string& cmd : {make_to(dir / "file.txt"), import_to(dir, dir / "file.txt")})
    check_one_line_error(gdsr_run(dir, cmd), "is not a folder");
  CHECK(slurp(dir / "mine/notes.txt") == "my notes\n");
  CHECK(slurp(dir / "file.txt") == "a file\n");
  check_one_line_error(gdsr_run(dir, make_to("")), "--out");
  check_one_line_error(gdsr_run(dir, make_to(dir / "file.txt/ds")), "file.txt is not a folder");
}

TEST_CASE("cli guards: import-md --out equal to or inside an input folder is refused") {
  TempDir dir("guard_overlap");
  write_exports(dir, 3);
  // The export folder itself (it holds lr/ and hr/) is not a dataset.
  check_one_line_error(gdsr_run(dir, import_to(dir, dir.path.string())), "not a gdsr dataset");
  check_one_line_error(gdsr_run(dir, import_to(dir, dir / "lr/ds")), "overlaps the input");
  check_one_line_error(gdsr_run(dir, import_to(dir, dir / "hr/./ds")), "overlaps the input");
  CHECK(fs::exists(dir / "lr/f2.obj"));
  CHECK_FALSE(fs::exists(dir / "lr/ds"));
}

TEST_CASE("cli guards: replacing a dataset leaves no temp folders and a killed replace is restored") {
  TempDir dir("guard_replace");
  write_exports(dir, 3);
  REQUIRE(gdsr_run(dir, import_to(dir, dir / "ds")).status == 0);
  REQUIRE(gdsr_run(dir, import_to(dir, dir / "ds")).status == 0);  // replaces its own dataset
  CHECK(fs::exists(dir / "ds/manifest.json"));
  CHECK(count_prefixed(dir.path.string(), "ds.") == 0);

  // A replace killed between "move the old one aside" and "rename the new one in".
  fs::rename(dir / "ds", dir / "ds.old.4242");
  std::ofstream(dir / "hr/f1.obj", std::ios::trunc) << "v 0 0 0\nv 1 0 0\nf 1 2 x\n";  // this import fails
  const Run r = gdsr_run(dir, import_to(dir, dir / "ds"));
  check_one_line_error(r, "f1.obj");
  CHECK(r.err.find("restored") != std::string::npos);
  CHECK(fs::exists(dir / "ds/manifest.json"));
  CHECK(count_prefixed(dir.path.string(), "ds.") == 0);
  CHECK(gdsr_run(dir, "data check --data '" + (dir / "ds") + "'").status == 0);
}

TEST_CASE("cli guards: data make refuses bad numbers before simulating") {
  TempDir dir("guard_numbers");
  for (const std::string bad :
       {"--raster 0", "--raster 100000", "--seconds -1", "--seconds nan", "--substeps -3", "--fps 100000", "--fps 0",
        "--fps nan", "--hr-pd 1e-4", "--lr-pd inf", "--rest-blend -1", "--friction nan", "--substep-travel -1",
        "--substep-travel nan", "--max-substeps 0", "--max-substeps 10"}) {
    const Run r = gdsr_run(dir, "data make --out '" + (dir / "bad") + "' " + bad);
    check_one_line_error(r, bad.substr(0, bad.find(' ')));
    CHECK(r.out.find("body:") == std::string::npos);
    CHECK_FALSE(fs::exists(dir / "bad"));
  }
  const Run coarse = gdsr_run(dir, "data make --out '" + (dir / "bad") + "' --lr-pd 0.03 --hr-pd 0.05");
  check_one_line_error(coarse, "coarser than the LR one");
  CHECK(coarse.out.find("body:") == std::string::npos);
  check_one_line_error(gdsr_run(dir, import_to(dir, dir / "bad") + " --fps 1e9"), "--fps");
}

TEST_CASE("cli guards: infer and eval refuse --frames 0 and a folder as --model") {
  TempDir dir("guard_infer");
  gdsr::write_dataset(dir / "ds", gdsr_test::wave_dataset(4));
  for (const char* cmd : {"infer", "eval"})
    for (const char* bad : {"--frames 0", "--frames -5", "--first -1"}) {
      const Run r =
          gdsr_run(dir, std::string(cmd) + " --model '" + (dir / "ds") + "' --data '" + (dir / "ds") + "' " + bad);
      check_one_line_error(r, std::string(bad).substr(0, std::string(bad).find(' ')));
    }
  const Run r =
      gdsr_run(dir, "infer --model '" + (dir / "ds") + "' --data '" + (dir / "ds") + "' --out '" + (dir / "o") + "'");
  check_one_line_error(r, "is a folder");
  CHECK(r.err.find("bad_alloc") == std::string::npos);
  CHECK_FALSE(fs::exists(dir / "o"));
}

TEST_CASE("cli guards: a dataset with a huge layer id or a folder in place of a file is refused at load") {
  TempDir dir("guard_layer");
  const gdsr::Dataset d = gdsr_test::wave_dataset(3);
  gdsr::write_dataset(dir / "ds", d);
  std::vector<int32_t> layer(static_cast<size_t>(d.hr.V.rows()), 0);
  layer[3] = 1000000;
  gdsr::Array a;
  a.dtype = gdsr::DType::i32;
  a.dims = {layer.size()};
  a.bytes.assign(reinterpret_cast<const char*>(layer.data()), layer.size() * sizeof(int32_t));
  gdsr::write_array(dir / "ds/hr_layer.bin", a);
  check_one_line_error(gdsr_run(dir, "data check --data '" + (dir / "ds") + "'"), "hr_layer.bin: layer id 1000000");

  // Dimensions whose product wraps around 2^64 to 0 bytes (2^62 x 4 x 3 float32).
  gdsr::write_dataset(dir / "ds3", d);
  gdsr::Array wrap;
  wrap.dtype = gdsr::DType::f32;
  wrap.dims = {uint64_t(1) << 62, 4, 3};
  gdsr::write_array(dir / "ds3/lr_frames.bin", wrap);
  const Run rw = gdsr_run(dir, "data check --data '" + (dir / "ds3") + "'");
  check_one_line_error(rw, "lr_frames.bin: dimensions larger than the file");
  CHECK(rw.err.find("max_size") == std::string::npos);

  gdsr::write_dataset(dir / "ds2", d);
  fs::remove(dir / "ds2/lr_frames.bin");
  fs::create_directories(dir / "ds2/lr_frames.bin");
  check_one_line_error(gdsr_run(dir, "data check --data '" + (dir / "ds2") + "'"), "lr_frames.bin is a folder");
}

TEST_CASE("cli guards: an unreadable dataset file is reported as permission denied") {
  TempDir dir("guard_perm");
  gdsr::write_dataset(dir / "ds", gdsr_test::wave_dataset(3));
  fs::permissions(dir / "ds/hr_frames.bin", fs::perms::none);
  // root reads anything: run the binary as nobody then (setpriv, util-linux).
  const bool root = ::geteuid() == 0;
  if (root && std::system("command -v setpriv >/dev/null 2>&1") != 0) {
    MESSAGE("SKIPPED: running as root without setpriv to drop privileges");
    return;
  }
  if (root) fs::permissions(dir.path, fs::perms::others_read | fs::perms::others_exec, fs::perm_options::add);
  const Run r = gdsr_run(dir, "data check --data '" + (dir / "ds") + "'",
                         root ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : "");
  check_one_line_error(r, "hr_frames.bin: Permission denied");
  CHECK(r.err.find("missing file") == std::string::npos);
  fs::permissions(dir / "ds/hr_frames.bin", fs::perms::owner_read | fs::perms::others_read);
  fs::permissions(dir / "ds/lr.obj", fs::perms::none);
  check_one_line_error(gdsr_run(dir, "data check --data '" + (dir / "ds") + "'",
                                root ? "setpriv --reuid=65534 --regid=65534 --clear-groups " : ""),
                       "lr.obj: Permission denied");
}

TEST_CASE("cli guards: eval refuses a prediction that does not match the dataset") {
  TempDir dir("guard_eval");
  const gdsr::Dataset d = gdsr_test::wave_dataset(6);
  gdsr::write_dataset(dir / "ds", d);
  gdsr::write_dataset(dir / "other", gdsr_test::wave_dataset(6));
  const std::vector<gdsr::Points3> G(d.hr_frames.begin() + 2, d.hr_frames.end());
  const std::string eval = "eval --no-export --pred '" + (dir / "p") + "' --data '";

  write_pred(dir / "p", G, 2, dir / "ds", 4);
  const Run ok = gdsr_run(dir, eval + (dir / "ds") + "'");
  CHECK(ok.status == 0);
  CHECK(ok.out.find("evaluation over 4 frames") != std::string::npos);
  check_one_line_error(gdsr_run(dir, eval + (dir / "other") + "'"), "was made on");
  check_one_line_error(gdsr_run(dir, eval + (dir / "ds") + "' --first 0 --frames 2"), "--first / --frames");

  write_pred(dir / "p", G, 3, dir / "ds", 4);  // frames 3..6 of a 6-frame dataset
  check_one_line_error(gdsr_run(dir, eval + (dir / "ds") + "'"), "covers frames 3..6");

  write_pred(dir / "p", G, 2, dir / "ds", 5);  // arrays of another run than prediction.json
  check_one_line_error(gdsr_run(dir, eval + (dir / "ds") + "'"), "records 5");

  std::vector<gdsr::Points3> nan = G;
  nan[1](0, 0) = std::numeric_limits<double>::quiet_NaN();
  write_pred(dir / "p", nan, 2, dir / "ds", 4);
  const Run rn = gdsr_run(dir, eval + (dir / "ds") + "'");
  check_one_line_error(rn, "NaN");
  CHECK(rn.out.find("nan mm") == std::string::npos);

  write_pred(dir / "p", {}, 2, dir / "ds", 0);
  const Run r0 = gdsr_run(dir, eval + (dir / "ds") + "'");
  check_one_line_error(r0, "no frames");
  CHECK(r0.out.find("0.00 mm") == std::string::npos);

  std::ofstream(dir / "p/prediction.json", std::ios::trunc) << "{\"first_frame\": 2,";
  const Run rj = gdsr_run(dir, eval + (dir / "ds") + "'");
  check_one_line_error(rj, "prediction.json");
  CHECK(rj.err.find("[json.exception") == std::string::npos);
}
