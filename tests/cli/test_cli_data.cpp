// Runs the built gdsr binary on bad input: every failure is one line "gdsr: error: ..." on
// stderr and a non-zero exit status.
#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/geometry/self_intersections.hpp"
#include "gdsr/geometry/strain.hpp"
#include "tests/support/cli_run.hpp"
#include "tests/support/data_fixtures.hpp"

#include <doctest/doctest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "gdsr/sim/cloth_solver.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <sys/wait.h>
#include <utility>

using gdsr_test::check_one_line_error;
using gdsr_test::gdsr_run;
using gdsr_test::Run;
using gdsr_test::TempDir;
namespace fs = std::filesystem;

namespace {

// MD-style exports of a small tube: LR/HR frame folders and flattened OBJs.
void write_md_exports(const TempDir& dir, int lr_frames, int hr_frames) {
  const gdsr::GarmentMesh lr = gdsr_test::grid_garment(gdsr_test::GridSpec(6, 3, 0.6, 0.3).tube());
  const gdsr::GarmentMesh hr = gdsr::subdivide_midpoint(lr);
  fs::create_directories(dir / "lr");
  fs::create_directories(dir / "hr");
  gdsr::write_obj(dir / "lr_flat.obj", gdsr_test::flat_uv_mesh(lr));
  gdsr::write_obj(dir / "hr_flat.obj", gdsr_test::flat_uv_mesh(hr));
  for (int t = 0; t < lr_frames; ++t)
    gdsr::write_obj(dir / ("lr/f" + std::to_string(t) + ".obj"), gdsr::TriMesh{lr.V, lr.F});
  for (int t = 0; t < hr_frames; ++t)
    gdsr::write_obj(dir / ("hr/f" + std::to_string(t) + ".obj"), gdsr::TriMesh{hr.V, hr.F});
}

std::string import_args(const TempDir& dir) {
  return "data import-md --lr-dir '" + (dir / "lr") + "' --hr-dir '" + (dir / "hr") + "' --lr-uv '" +
         (dir / "lr_flat.obj") + "' --hr-uv '" + (dir / "hr_flat.obj") + "' --out '" + (dir / "out") + "'";
}

}  // namespace

TEST_CASE("cli data: import-md then check succeeds") {
  TempDir dir("cli_ok");
  write_md_exports(dir, 3, 3);
  const Run imp = gdsr_run(dir, import_args(dir));
  CHECK(imp.status == 0);
  CHECK(imp.out.find("3 frames") != std::string::npos);
  const Run chk = gdsr_run(dir, "data check --data '" + (dir / "out") + "'");
  CHECK(chk.status == 0);
  CHECK(chk.out.find("ok") != std::string::npos);
  // The validity figures of the (static, clean) import: no body to measure penetration against.
  CHECK(chk.out.find("validity over 3 frames") != std::string::npos);
  CHECK(chk.out.find("self-intersection: frames with 0 pairs") != std::string::npos);
  CHECK(chk.out.find("100.0%") != std::string::npos);
  CHECK(chk.out.find("strain: mean E_u") != std::string::npos);
  CHECK(chk.out.find("not measured") != std::string::npos);
  CHECK(chk.out.find("agreement") != std::string::npos);
  CHECK(chk.out.find("no validity figures stored") != std::string::npos);
  if (chk.out.find("validity over") == std::string::npos) MESSAGE("stdout: " << chk.out);
  const Run strided = gdsr_run(dir, "data check --intersection-stride 2 --data '" + (dir / "out") + "'");
  CHECK(strided.status == 0);
  CHECK(strided.out.find("1 frame in 2: 2 checked") != std::string::npos);
}

TEST_CASE("cli data: bad input gives a one-line error and exit 1") {
  TempDir dir("cli_bad");
  write_md_exports(dir, 3, 2);
  check_one_line_error(gdsr_run(dir, import_args(dir)), "mismatched frame counts");

  write_md_exports(dir, 3, 3);
  std::ofstream(dir / "hr/f1.obj") << "v 0 0 0\nv 1 0 0\nf 1 2 x\n";
  check_one_line_error(gdsr_run(dir, import_args(dir)), "f1.obj:3");

  std::ofstream(dir / "hr/f1.obj", std::ios::trunc) << "";
  check_one_line_error(gdsr_run(dir, import_args(dir)), "empty mesh");

  std::ofstream(dir / "hr/f1.obj", std::ios::trunc) << "v 0 NaN 0\n";
  check_one_line_error(gdsr_run(dir, import_args(dir)), "non-finite");

  check_one_line_error(gdsr_run(dir, "data check --data '" + (dir / "missing") + "'"), "no dataset folder");
  check_one_line_error(gdsr_run(dir, "data frobnicate"), "");
  CHECK_FALSE(fs::exists(dir / "out"));
}

TEST_CASE("cli data: make a tiny dataset, check it and preview a frame") {
  // Coarse particle distances and 0.2 s of motion keep this to a few seconds.
  TempDir dir("cli_make");
  const std::string out = dir / "ds";
  const Run mk = gdsr_run(dir, "data make --garment skirt_short --out '" + out +
                                   "' --seconds 0.2 --lr-pd 0.06 --hr-pd 0.03 --rest-blend 3 --raster 128");
  REQUIRE(mk.status == 0);
  CHECK(mk.err.find("warning") == std::string::npos);  // CMU 01_01's skeleton is recognised
  CHECK(mk.out.find("vertices: LR") != std::string::npos);
  CHECK(mk.out.find("seconds per frame") != std::string::npos);
  CHECK(mk.out.find("penetration") != std::string::npos);
  CHECK(mk.out.find("self-intersection: median pairs") != std::string::npos);
  CHECK(fs::exists(out + "/manifest.json"));
  CHECK_FALSE(fs::exists(out + ".tmp"));
  const Run chk = gdsr_run(dir, "data check --data '" + out + "'");
  CHECK(chk.status == 0);
  CHECK(chk.out.find("garment skirt_short") != std::string::npos);
  // `data check` recomputes the figures `data make` stored: the same numbers.
  CHECK(chk.out.find("body: max penetration") != std::string::npos);
  CHECK(chk.out.find("strain: longest edge / pattern") != std::string::npos);
  CHECK(chk.out.find("stored validity figures agree with the recomputed ones") != std::string::npos);
  if (chk.out.find("agree with the") == std::string::npos) MESSAGE("stdout: " << chk.out);
  // Another crease rule (here off) measures other figures: they are not compared with the stored ones.
  const Run off = gdsr_run(dir, "data check --data '" + out + "' --pinch-gap 0");
  CHECK(off.status == 0);
  CHECK(off.out.find("stored with a pinch gap of 8.0 mm") != std::string::npos);
  CHECK(off.out.find("not compared") != std::string::npos);
  CHECK(gdsr_run(dir, "data check --data '" + out + "' --pinch-gap -1").status != 0);
  // Each frame's figures as CSV: a header and one line per frame.
  const std::string csv = dir / "frames.csv";
  CHECK(gdsr_run(dir, "data check --data '" + out + "' --per-frame '" + csv + "'").status == 0);
  const std::string rows = gdsr_test::slurp(csv);
  CHECK(rows.rfind("frame,lr_pairs,hr_pairs,", 0) == 0);
  CHECK(std::count(rows.begin(), rows.end(), '\n') == 1 + gdsr::load_dataset(out).manifest.frames);
  CHECK_FALSE(fs::exists(csv + ".tmp"));
  // The strain of each pattern piece: per resolution, the pieces' faces add up to the mesh's
  // and their shares of E_u to 100%.
  const Run byp = gdsr_run(dir, "data check --data '" + out + "' --strain-by-piece");
  CHECK(byp.status == 0);
  CHECK(byp.out.find("strain by pattern piece") != std::string::npos);
  const gdsr::DatasetManifest mf = gdsr::load_dataset(out).manifest;
  for (const std::string res : {"LR", "HR"}) {
    std::istringstream lines(byp.out);
    std::string line;
    int pieces = 0, faces = 0;
    double share = 0;
    while (std::getline(lines, line)) {
      std::istringstream row(line);
      std::string r, xrange, pct;
      int k = 0, nf = 0;
      double eu = 0, eus = 0, ev = 0, evs = 0, euv = 0;
      if (!(row >> r >> k >> nf >> xrange >> eu >> eus >> ev >> evs >> euv >> pct) || r != res) continue;
      CHECK(k == pieces);
      CHECK(eus <= eu + 1e-12);
      ++pieces, faces += nf, share += std::stod(pct);
    }
    CHECK(pieces >= 2);  // skirt_short: front and back
    CHECK(faces == (res == "LR" ? mf.lr_faces : mf.hr_faces));
    CHECK(share == doctest::Approx(100).epsilon(0.01));
  }
  const Run pv =
      gdsr_run(dir, "data preview --data '" + out + "' --frame 5 --size 128 --out '" + (dir / "p.png") + "'");
  CHECK(pv.status == 0);
  CHECK(fs::file_size(dir / "p.png") > 1000);
  // Strain painted on the cloth: the counts printed per resolution, and another picture.
  const Run pvs =
      gdsr_run(dir, "data preview --data '" + out + "' --frame 5 --size 128 --strain --out '" + (dir / "ps.png") + "'");
  CHECK(pvs.status == 0);
  CHECK(pvs.out.find("LR: ") != std::string::npos);
  CHECK(pvs.out.find("faces with a fibre more than 2% shorter than in the pattern") != std::string::npos);
  {  // the LR counts, from each face's fibre strained most (|w| - 1 beyond 2%)
    const gdsr::Dataset ds = gdsr::load_dataset(out);
    int shorter = 0, longer = 0;
    for (const gdsr::Vec2& w : gdsr::fibre_stretch(ds.lr, ds.lr_frames[5])) {
      const double e = std::abs(w.x() - 1) >= std::abs(w.y() - 1) ? w.x() - 1 : w.y() - 1;
      shorter += e<-0.02, longer += e> 0.02;
    }
    CHECK(shorter + longer > 0);
    CHECK(pvs.out.find("LR: " + std::to_string(shorter) +
                       " faces with a fibre more than 2% shorter than in the "
                       "pattern, " +
                       std::to_string(longer) + " more than 2% longer") != std::string::npos);
  }
  REQUIRE(fs::exists(dir / "ps.png"));
  CHECK(gdsr_test::slurp(dir / "ps.png") != gdsr_test::slurp(dir / "p.png"));
  const Run pvi =
      gdsr_run(dir, "data preview --data '" + out + "' --intersections --size 128 --out '" + (dir / "pi.png") + "'");
  CHECK(pvi.status == 0);
  CHECK(fs::file_size(dir / "pi.png") > 1000);
  // Other views: the same frame seen from the side and from above is another picture.
  for (const std::string view : {"left", "top"}) {
    const fs::path png = dir / ("p_" + view + ".png");
    const Run pvv = gdsr_run(
        dir, "data preview --data '" + out + "' --frame 5 --size 128 --view " + view + " --out '" + png.string() + "'");
    CHECK(pvv.status == 0);
    REQUIRE(fs::exists(png));
    CHECK(gdsr_test::slurp(png.string()) != gdsr_test::slurp(dir / "p.png"));
  }
  check_one_line_error(gdsr_run(dir, "data preview --data '" + out + "' --frame 999 --out '" + (dir / "q.png") + "'"),
                       "out of range");
  // The stored figures in a table: the dataset by name, or every dataset in a folder (here the
  // test's folder, which holds this one dataset among other files).
  const Run tab = gdsr_run(dir, "data table --data '" + out + "' --out '" + (dir / "t.md") + "'");
  CHECK(tab.status == 0);
  CHECK(tab.out.find("| ds | skirt_short | " + std::to_string(gdsr::load_dataset(out).manifest.frames) + " | ") !=
        std::string::npos);
  CHECK(tab.out.find("of 1 datasets pass every limit") != std::string::npos);
  const std::string md = gdsr_test::slurp(dir / "t.md");
  CHECK(md.rfind("| dataset | garment |", 0) == 0);
  CHECK(tab.out.find(md) == 0);  // the file holds the table printed
  const Run folder = gdsr_run(dir, "data table --data '" + dir.path.string() + "/'");  // a trailing slash too
  CHECK(folder.status == 0);
  CHECK(folder.out.find("| ds | skirt_short |") != std::string::npos);
  CHECK(gdsr_run(dir, "data table --data '" + out + "/'").out.find("| ds | skirt_short |") != std::string::npos);
  check_one_line_error(gdsr_run(dir, "data table --data '" + (dir / "none") + "'"), "none");
  check_one_line_error(gdsr_run(dir, "data make --garment skirt_short --motion '" + (dir / "none.bvh") + "' --out '" +
                                         (dir / "x") + "'"),
                       "none.bvh");
  check_one_line_error(gdsr_run(dir, "data make --garment no_such_garment --out '" + (dir / "x") + "'"), "garment");
}

TEST_CASE("cli data: preview --penetration paints and counts the faces in the body") {
  // The validity tests' sheet over a box body whose top rises 1, 8, 8, 3 mm through it: LR
  // vertex (0.165, 0.15, 0) and the six HR ones over the box top are that deep (HR 2 mm less).
  // In frame 2 a second box hovers 1 cm above them: pinched.
  TempDir dir("cli_preview_depth");
  gdsr::Dataset d = gdsr_test::stretched_dataset({0.001, 0.008, 0.008, 0.003});
  gdsr_test::add_second_part(d, gdsr_test::box(0.6, 0.65, 0.13, 0.17, 0.01, 0.05),
                             gdsr_test::box(0.14, 0.19, 0.13, 0.17, 0.01, 0.05));
  gdsr::write_dataset(dir / "ds", d);
  // Expected, from the geometry alone: faces with a corner over the box top, deeper than 5 mm.
  auto faces_over_box = [](const gdsr::GarmentMesh& g, const gdsr::Points3& X, double depth) {
    int n = 0;
    for (int f = 0; f < g.F.rows(); ++f) {
      bool in = false;
      for (int k = 0; k < 3; ++k) {
        const Eigen::RowVector3d x = X.row(g.F(f, k));
        in |= x.x() > 0.1 && x.x() < 0.2 && x.y() > 0.1 && x.y() < 0.2 && depth - x.z() > 0.005;
      }
      n += in;
    }
    return n;
  };
  const int lr_faces = faces_over_box(d.lr, d.lr_frames[1], 0.008),
            hr_faces = faces_over_box(d.hr, d.hr_frames[1], 0.008);
  REQUIRE(lr_faces > 0);
  REQUIRE(hr_faces > lr_faces);
  // Pixels of a colour: magenta (in the body) and cyan (pinched), BGR with shading and blending.
  auto pixels = [](const std::string& png, bool magenta) {
    const cv::Mat img = cv::imread(png, cv::IMREAD_COLOR);
    REQUIRE_FALSE(img.empty());
    int n = 0;
    for (int y = 0; y < img.rows; ++y)
      for (int x = 0; x < img.cols; ++x) {
        const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
        n += magenta ? c[2] > 140 && c[0] > 140 && c[1] < 110 : c[2] < 90 && c[1] > 120 && c[0] > 150;
      }
    return n;
  };
  auto preview = [&](int frame) {
    const std::string png = dir / ("f" + std::to_string(frame) + ".png");
    const Run r = gdsr_run(dir, "data preview --data '" + (dir / "ds") + "' --frame " + std::to_string(frame) +
                                    " --penetration --size 160 --out '" + png + "'");
    CHECK(r.status == 0);
    return std::make_pair(r.out, png);
  };
  const auto [out0, png0] = preview(0);  // 1 mm: under the limit
  CHECK(out0.find("LR: 0 faces with a corner > 5 mm in the body outside pinches (deepest 0.0 mm), 0 pinched") !=
        std::string::npos);
  CHECK(pixels(png0, true) == 0);
  CHECK(pixels(png0, false) == 0);
  const auto [out1, png1] = preview(1);  // 8 mm (HR 6 mm), nothing above: outside pinches
  CHECK(out1.find("LR: " + std::to_string(lr_faces) + " faces with a corner > 5 mm in the body outside pinches " +
                  "(deepest 8.0 mm), 0 pinched") != std::string::npos);
  CHECK(out1.find("HR: " + std::to_string(hr_faces) + " faces with a corner > 5 mm in the body outside pinches " +
                  "(deepest 6.0 mm), 0 pinched") != std::string::npos);
  CHECK(pixels(png1, true) > 0);  // drawn through the box that hides them from the front
  CHECK(pixels(png1, false) == 0);
  const auto [out2, png2] = preview(2);  // the same depths under the second box: pinched
  CHECK(out2.find("LR: 0 faces with a corner > 5 mm in the body outside pinches (deepest 0.0 mm), " +
                  std::to_string(lr_faces) + " pinched") != std::string::npos);
  CHECK(pixels(png2, true) == 0);
  CHECK(pixels(png2, false) > 0);
  if (out1.find("LR: ") == std::string::npos) MESSAGE("stdout: " << out1);
  // A closed crease of one part: the second box stays 1 cm above the sheet in every frame, the same
  // part as the body box, so in frame 1 the 8 mm-deep cloth lies in a 2 mm gap: pinched, as in
  // `data check`, and outside pinches with --pinch-gap 0.
  gdsr::Dataset crease = gdsr_test::stretched_dataset({0.001, 0.008, 0.008, 0.003});
  const gdsr::TriMesh forearm = gdsr_test::box(0.14, 0.19, 0.13, 0.17, 0.01, 0.05);
  gdsr_test::add_second_part(crease, forearm, forearm);
  gdsr::write_dataset(dir / "crease", crease);
  auto crease_preview = [&](const std::string& flags) {
    return gdsr_run(dir, "data preview --data '" + (dir / "crease") + "' --frame 1 --penetration --size 96 --out '" +
                             (dir / "c.png") + "'" + flags);
  };
  const Run pinched = crease_preview(""), off = crease_preview(" --pinch-gap 0");
  CHECK(pinched.out.find("LR: 0 faces with a corner > 5 mm in the body outside pinches (deepest 0.0 mm), " +
                         std::to_string(lr_faces) + " pinched") != std::string::npos);
  CHECK(off.out.find("LR: " + std::to_string(lr_faces) + " faces with a corner > 5 mm in the body outside pinches " +
                     "(deepest 8.0 mm), 0 pinched") != std::string::npos);
  CHECK(crease_preview(" --pinch-gap nan").status != 0);
  // A dataset without a body: one line naming the flag, no picture.
  gdsr::Dataset bodiless = gdsr_test::wave_dataset(2);
  gdsr::write_dataset(dir / "nobody", bodiless);
  check_one_line_error(
      gdsr_run(dir, "data preview --data '" + (dir / "nobody") + "' --penetration --out '" + (dir / "nb.png") + "'"),
      "--penetration");
  CHECK_FALSE(fs::exists(dir / "nb.png"));
}

// Three vertical sheets (0.3 m, n x n vertices, facing the front camera +z) as one garment,
// layer k at z = z[k]; the middle one dented back through the innermost at its centre, behind
// the outer sheet that hides both from the front. No body.
static gdsr::GarmentMesh three_layers(int n, const double z[3]) {
  gdsr::GarmentMesh g;
  for (int k = 0; k < 3; ++k) {
    gdsr::GarmentMesh s = gdsr_test::grid_garment(gdsr_test::GridSpec(n - 1, n - 1, 0.3, 0.3).layer(k));
    s.V.col(2).array() += z[k];
    const int nv = static_cast<int>(g.V.rows()), nuv = static_cast<int>(g.UV.rows());
    auto stack = [](auto& a, const auto& b) {
      auto top = a;
      a.resize(top.rows() + b.rows(), b.cols());
      a << top, b;
    };
    stack(g.V, s.V);
    stack(g.UV, gdsr::Points2(s.UV.rowwise() + Eigen::RowVector2d(0.5 * k, 0)));
    stack(g.F, gdsr::Faces(s.F.array() + nv));
    stack(g.FUV, gdsr::Faces(s.FUV.array() + nuv));
    for (int u : s.uv_to_vertex) g.uv_to_vertex.push_back(u + nv);
    g.layer.insert(g.layer.end(), s.layer.begin(), s.layer.end());
  }
  const int per = n * n;
  for (int v = per; v < 2 * per; ++v)
    if ((g.V.row(v).head<2>() - Eigen::RowVector2d(0.15, 0.15)).norm() < 0.06) g.V(v, 2) = -0.01;
  return g;
}

TEST_CASE("cli data: preview draws the faces of a knot hidden under an outer layer, and one layer alone") {
  TempDir dir("cli_preview_layers");
  const double z[3] = {0.0, 0.01, 0.03};
  gdsr::Dataset d;
  d.lr = three_layers(7, z);
  d.hr = three_layers(13, z);
  d.lr_frames.assign(2, d.lr.V);
  d.hr_frames.assign(2, d.hr.V);
  d.corr = gdsr::compute_correspondence(d.lr, d.hr);
  d.raster = gdsr::rasterize_uv(d.hr.UV, d.hr.FUV, 64, 64, 2);
  d.manifest.garment = "three sheets";
  gdsr::update_manifest_counts(d);
  gdsr::write_dataset(dir / "ds", d);
  auto preview = [&](const std::string& flags, const std::string& png) {
    const Run r =
        gdsr_run(dir, "data preview --data '" + (dir / "ds") + "' --size 160 --out '" + (dir / png) + "' " + flags);
    CHECK(r.status == 0);
    return r.out + r.err;
  };
  // Pixels under the caption bar (28 px) turned red from `plain` to `marked`: green falls, red
  // does not (both cloth colours, shaded, and the x-ray's blend).
  auto reddened = [&](const std::string& plain, const std::string& marked) {
    const cv::Mat a = cv::imread(dir / plain, cv::IMREAD_COLOR), b = cv::imread(dir / marked, cv::IMREAD_COLOR);
    REQUIRE_FALSE(a.empty());
    REQUIRE(a.size() == b.size());
    int n = 0;
    for (int y = 28; y < a.rows; ++y)
      for (int x = 0; x < a.cols; ++x) {
        const cv::Vec3b p = a.at<cv::Vec3b>(y, x), q = b.at<cv::Vec3b>(y, x);
        n += q[1] + 25 < p[1] && q[2] + 25 >= p[2];
      }
    return n;
  };
  // The dent crosses layer 0: counted by the yardstick itself, not by the preview.
  REQUIRE(gdsr::self_intersections(d.lr.V, d.lr.F).pairs > 0);
  preview("", "plain.png");
  // The outer sheet hides the knot from the front; it is drawn through it.
  // The yardstick's faces in intersecting pairs, all and per layer (of their first corner).
  std::set<int> crossing;
  for (const auto& [f, g] : gdsr::self_intersections(d.lr.V, d.lr.F, true).list) crossing.insert({f, g});
  int on_layer[3] = {0, 0, 0};
  for (int f : crossing) ++on_layer[d.lr.layer[d.lr.F(f, 0)]];
  CHECK(preview("--intersections", "all.png")
            .find("LR: " + std::to_string(crossing.size()) + " faces in intersecting pairs\n") != std::string::npos);
  CHECK(reddened("plain.png", "all.png") > 0);
  // Layer 2 alone crosses nothing: no red (drawn through, the other layers' faces would show);
  // layers 0 and 1 alone show their faces of the knot.
  preview("--layer 2", "l2.png");
  preview("--intersections --layer 2", "l2i.png");
  CHECK(reddened("l2.png", "l2i.png") == 0);
  CHECK(on_layer[2] == 0);
  CHECK(on_layer[0] > 0);
  CHECK(on_layer[1] > 0);
  for (const std::string layer : {"0", "1"}) {
    preview("--layer " + layer, "l" + layer + ".png");
    CHECK(preview("--intersections --layer " + layer, "l" + layer + "i.png")
              .find("LR: " + std::to_string(crossing.size()) + " faces in intersecting pairs, " +
                    std::to_string(on_layer[std::stoi(layer)]) + " of them on layer " + layer) != std::string::npos);
    CHECK(reddened("l" + layer + ".png", "l" + layer + "i.png") > 0);
  }
  check_one_line_error(
      gdsr_run(dir, "data preview --data '" + (dir / "ds") + "' --layer 3 --out '" + (dir / "bad.png") + "'"),
      "has 3 layers: 0-2");
  CHECK_FALSE(fs::exists(dir / "bad.png"));
  // A one-layer dataset has layer 0 only: with --layer 0 its penetration count is the whole
  // garment's, and says which layer it is of.
  gdsr::write_dataset(dir / "box", gdsr_test::stretched_dataset({0.001, 0.008}));
  auto in_body = [&](const std::string& flags) {
    const std::string out = gdsr_run(dir, "data preview --data '" + (dir / "box") + "' --frame 1 --penetration " +
                                              flags + " --size 64 --out '" + (dir / "b.png") + "'")
                                .out;
    const size_t at = out.find("LR: ");
    REQUIRE(at != std::string::npos);
    return out.substr(at, out.find(" with a corner", at) - at);
  };
  const std::string whole = in_body(""), layer0 = in_body("--layer 0");
  CHECK(whole.find(" faces") != std::string::npos);
  CHECK(whole != "LR: 0 faces");
  CHECK(layer0 == whole + " on layer 0");
  gdsr::write_dataset(dir / "wave", gdsr_test::wave_dataset(2));
  CHECK(
      gdsr_run(dir, "data preview --data '" + (dir / "wave") + "' --layer 0 --size 64 --out '" + (dir / "w.png") + "'")
          .status == 0);
  check_one_line_error(
      gdsr_run(dir, "data preview --data '" + (dir / "wave") + "' --layer 1 --out '" + (dir / "w1.png") + "'"),
      "one layer: 0");
}

TEST_CASE("cli data: make warns when a skeleton's hips and shoulders are not recognised") {
  // CMU 01_01 with its thighs renamed: the body is a column of capsules; data make says so on
  // stderr before anything else (here the skirt then finds no waist on it: a one-line error).
  TempDir dir("cli_make_names");
  const std::string renamed = gdsr_test::bvh_without_thighs(dir, "/usr/share/assimp/models/BVH/01_01.bvh");
  REQUIRE_MESSAGE(!renamed.empty(), "assimp-testmodels is not installed (scripts/setup.sh)");
  const Run mk = gdsr_run(dir, "data make --garment skirt_short --motion '" + renamed + "' --out '" + (dir / "ds") +
                                   "' --seconds 0.05 --lr-pd 0.1 --hr-pd 0.1 --settle-frames 0 --rest-blend 1 --raster 32");
  CHECK(mk.err.rfind("warning: ", 0) == 0);
  CHECK(mk.err.find("warning: " + renamed + ": no hips and shoulders found") != std::string::npos);
}

TEST_CASE("cli data: --skip-built keeps a clip built by this solver revision and rebuilds an older one") {
  TempDir dir("cli_skip_built");
  const std::string out = dir / "ds";
  const std::string cmd = "data make --skip-built --garment skirt_short --out '" + out +
                          "' --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --rest-blend 2 --raster 64 --settle-frames 3";
  const Run first = gdsr_run(dir, cmd);
  REQUIRE(first.status == 0);
  CHECK(first.out.find("building") != std::string::npos);
  const std::string manifest = gdsr_test::slurp(out + "/manifest.json");
  const std::string rev = "\"solver_revision\": " + std::to_string(sim::kSolverRevision);
  REQUIRE(manifest.find(rev) != std::string::npos);
  const Run again = gdsr_run(dir, cmd);
  REQUIRE(again.status == 0);
  CHECK(again.out.find("kept") != std::string::npos);
  // Another clip length, or a dataset an older solver made: rebuilt.
  const Run longer = gdsr_run(dir, cmd + " --start 0.1");
  CHECK(longer.out.find("built from other settings") != std::string::npos);
  std::string old = gdsr_test::slurp(out + "/manifest.json");
  old.replace(old.find(rev), rev.size(), "\"solver_revision\": 1");
  std::ofstream(out + "/manifest.json") << old;
  const Run stale = gdsr_run(dir, cmd + " --start 0.1");
  REQUIRE(stale.status == 0);
  CHECK(stale.out.find("built by an older solver") != std::string::npos);
  // The HR start is part of what was built: an HR settled from its own placement is not kept.
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"hr_start\": \"settled_lr\"") != std::string::npos);
  const Run independent = gdsr_run(dir, cmd + " --start 0.1 --independent-hr");
  REQUIRE(independent.status == 0);
  CHECK(independent.out.find("built with another HR start") != std::string::npos);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"hr_start\": \"placement\"") != std::string::npos);
  // So is the arm clearance the motion was fixed up with.
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"arm_clearance_m\": 0.01") != std::string::npos);
  const Run as_file = gdsr_run(dir, cmd + " --start 0.1 --independent-hr --arm-clearance 0");
  REQUIRE(as_file.status == 0);
  CHECK(as_file.out.find("built with another arm clearance") != std::string::npos);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"arm_clearance_m\": 0.0") != std::string::npos);
  CHECK(gdsr_run(dir, cmd + " --arm-clearance -1").status != 0);
  // And the body contact refresh: the skirt's is the solver's, 5, unless asked otherwise.
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"contact_every\": 5") != std::string::npos);
  const Run refresh = gdsr_run(dir, cmd + " --start 0.1 --independent-hr --arm-clearance 0 --contact-every 3");
  REQUIRE(refresh.status == 0);
  CHECK(refresh.out.find("built with another body contact refresh") != std::string::npos);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"contact_every\": 3") != std::string::npos);
  // And when cloth through itself is looked for (SimParams::self_tangle_retest).
  const std::string as_before = cmd + " --start 0.1 --independent-hr --arm-clearance 0 --contact-every 3";
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"self_tangle_retest\": false") != std::string::npos);
  const Run once = gdsr_run(dir, as_before + " --tangle-retest");
  REQUIRE(once.status == 0);
  CHECK(once.out.find("built with another tangle test cue") != std::string::npos);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"self_tangle_retest\": true") != std::string::npos);
  CHECK(gdsr_run(dir, as_before + " --tangle-retest").out.find("kept") != std::string::npos);
  // And how self-contact pushes pairs back across (SimParams::self_refuse_crossing_push).
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"self_refuse_crossing_push\": false") != std::string::npos);
  const Run refusing = gdsr_run(dir, as_before + " --tangle-retest --refuse-crossing-push");
  REQUIRE(refusing.status == 0);
  CHECK(refusing.out.find("built with another rule for pushes back across") != std::string::npos);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"self_refuse_crossing_push\": true") != std::string::npos);
  // And the adaptive substeps (SimParams::substep_travel), whose mean per frame is in the stats.
  const std::string refusing_cmd = as_before + " --tangle-retest --refuse-crossing-push";
  const Run adaptive = gdsr_run(dir, refusing_cmd + " --substep-travel 0.0001 --max-substeps 35");
  REQUIRE(adaptive.status == 0);
  CHECK(adaptive.out.find("built with other adaptive substeps") != std::string::npos);
  const nlohmann::json m = nlohmann::json::parse(gdsr_test::slurp(out + "/manifest.json"));
  CHECK(m["sim_params"]["substep_travel_m"].get<double>() == 0.0001);
  CHECK(m["sim_params"]["max_substeps"].get<int>() == 35);
  const double lr_substeps = m["stats"]["lr_substeps_per_frame"].get<double>();
  // The hem of a settling skirt falls faster than 0.1 mm in 1/600 s relative to the waist.
  CHECK(lr_substeps > m["sim_params"]["substeps"].get<int>());
  CHECK(lr_substeps <= 35);
  CHECK(gdsr_run(dir, refusing_cmd + " --substep-travel 0.0001 --max-substeps 35").out.find("kept") !=
        std::string::npos);
  CHECK(gdsr_run(dir, refusing_cmd + " --substep-travel 0.0001 --max-substeps 40")
            .out.find("built with other adaptive") != std::string::npos);
  check_one_line_error(gdsr_run(dir, refusing_cmd + " --substep-travel 0.003 --max-substeps 10"),
                       "--max-substeps: 10 is fewer than --substeps 20");
}

TEST_CASE("cli data: the t-shirt is simulated with its own body contact refresh, every 3rd substep") {
  // sim::body_contact_every: the sleeve in a bending elbow's crook needs fresher contacts.
  TempDir dir("cli_tshirt_refresh");
  const std::string out = dir / "ds";
  const Run mk =
      gdsr_run(dir, "data make --garment tshirt --motion '" + std::string(GDSR_SHARED_DIR) +
                        "/motions/cmu-salsa/61_03.bvh' --start 2 --out '" + out +
                        "' --seconds 0.1 --lr-pd 0.06 --hr-pd 0.05 --rest-blend 2 --raster 64 --settle-frames 3");
  REQUIRE(mk.status == 0);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"contact_every\": 3") != std::string::npos);
}

TEST_CASE(
    "cli data: a salsa skeleton's narrow shoulders are moved out, said, recorded, and rebuilt when the limit changes") {
  // gdsr::BodyOptions::min_shoulder_half_width (tests/gdsr/body/test_body_shoulders.cpp measures the body).
  TempDir dir("cli_shoulders");
  const std::string out = dir / "ds";
  const std::string cmd = "data make --skip-built --garment skirt_short --motion '" + std::string(GDSR_SHARED_DIR) +
                          "/motions/cmu-salsa/61_03.bvh' --start 2 --out '" + out +
                          "' --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --rest-blend 2 --raster 64 --settle-frames 3";
  const Run mk = gdsr_run(dir, cmd);
  REQUIRE(mk.status == 0);
  CHECK(mk.out.find("body: shoulder joints 0.126 m from the middle in the file, moved out to 0.200 m") !=
        std::string::npos);
  std::string manifest = gdsr_test::slurp(out + "/manifest.json");
  CHECK(manifest.find("\"shoulders_widened\": true") != std::string::npos);
  CHECK(manifest.find("\"min_shoulder_half_width_m\": 0.2") != std::string::npos);
  CHECK(gdsr_run(dir, cmd).out.find("kept") != std::string::npos);
  // A wider limit moves them again: rebuilt. A limit under the file's 0.126 m leaves them as the
  // file has them, like 0: the second of those is kept.
  const Run wider = gdsr_run(dir, cmd + " --min-shoulder-half-width 0.22");
  REQUIRE(wider.status == 0);
  CHECK(wider.out.find("built with another shoulder width limit") != std::string::npos);
  CHECK(wider.out.find("moved out to 0.220 m") != std::string::npos);
  const Run as_filed = gdsr_run(dir, cmd + " --min-shoulder-half-width 0");
  REQUIRE(as_filed.status == 0);
  CHECK(as_filed.out.find("built with another shoulder width limit") != std::string::npos);
  CHECK(as_filed.out.find("body: shoulder joints") == std::string::npos);
  manifest = gdsr_test::slurp(out + "/manifest.json");
  CHECK(manifest.find("\"shoulders_widened\": false") != std::string::npos);
  CHECK(gdsr_run(dir, cmd + " --min-shoulder-half-width 0.1").out.find("kept") != std::string::npos);
  check_one_line_error(gdsr_run(dir, cmd + " --min-shoulder-half-width 0.5"), "--min-shoulder-half-width");
}

TEST_CASE(
    "cli data: --body-yield-gap gives way where the kneel drives the thigh into the belly, said, recorded and "
    "previewed") {
  // gdsr::BodyOptions::yield_gap (tests/gdsr/body/test_body_yield.cpp measures the body with CGAL).
  TempDir dir("cli_body_yield");
  const std::string out = dir / "ds";
  const std::string cmd = "data make --skip-built --garment skirt_short --motion '" + std::string(GDSR_SHARED_DIR) +
                          "/motions/cmu-walk/131_01.bvh' --start 3.1 --out '" + out +
                          "' --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --rest-blend 2 --raster 64 --settle-frames 3";
  // `data preview --intersections` counts the body's faces where one part passes into another.
  auto body_crossing_faces = [&]() {
    const Run pv = gdsr_run(
        dir, "data preview --intersections --size 64 --frame 3 --data '" + out + "' --out '" + (dir / "p.png") + "'");
    REQUIRE(pv.status == 0);
    const size_t at = pv.out.find("body: ");
    REQUIRE(at != std::string::npos);
    CHECK(pv.out.find(" faces where one part passes into another (CGAL", at) != std::string::npos);
    return std::stoi(pv.out.substr(at + 6));
  };
  const Run plain = gdsr_run(dir, cmd);
  REQUIRE(plain.status == 0);
  CHECK(plain.out.find("gave way") == std::string::npos);
  CHECK(gdsr_test::slurp(out + "/manifest.json").find("\"body_yield_gap_m\": 0.0") != std::string::npos);
  CHECK(body_crossing_faces() > 50);  // the raised thigh in the belly: 81 faces
  const Run yielded = gdsr_run(dir, cmd + " --body-yield-gap 0.004");
  REQUIRE(yielded.status == 0);
  CHECK(yielded.out.find("built with another body yield gap") != std::string::npos);
  CHECK(yielded.out.find("body: one part passed into another in") != std::string::npos);
  const std::string manifest = gdsr_test::slurp(out + "/manifest.json");
  CHECK(manifest.find("\"body_yield_gap_m\": 0.004") != std::string::npos);
  CHECK(manifest.find("\"body_yielded_frames\": 0,") == std::string::npos);
  CHECK(body_crossing_faces() == 0);
  CHECK(gdsr_run(dir, cmd + " --body-yield-gap 0.004").out.find("kept") != std::string::npos);
  check_one_line_error(gdsr_run(dir, cmd + " --body-yield-gap 0.05"), "--body-yield-gap");
}

TEST_CASE("cli data: compare finds a repeat bit-identical, a nudged twin apart, and refuses other meshes") {
  TempDir dir("cli_compare");
  const std::string clip = " --garment skirt_short --seconds 0.2 --hr-pd 0.06 --rest-blend 2 --raster 64"
                           " --settle-frames 3 --lr-pd ";
  REQUIRE(gdsr_run(dir, "data make --out '" + (dir / "a") + "'" + clip + "0.08").status == 0);
  REQUIRE(gdsr_run(dir, "data make --out '" + (dir / "b") + "'" + clip + "0.08").status == 0);
  REQUIRE(gdsr_run(dir, "data make --out '" + (dir / "c") + "'" + clip + "0.08 --friction 0.2").status == 0);
  const Run same = gdsr_run(dir, "data compare --a '" + (dir / "a") + "' --b '" + (dir / "b") + "'");
  REQUIRE(same.status == 0);
  CHECK(same.out.find("LR: bit-identical over") != std::string::npos);
  CHECK(same.out.find("HR: bit-identical over") != std::string::npos);
  const Run twin = gdsr_run(dir, "data compare --a '" + (dir / "a") + "' --b '" + (dir / "c") + "' --every 1");
  REQUIRE(twin.status == 0);
  CHECK(twin.out.find("LR: mean") != std::string::npos);
  CHECK(twin.out.find("HR: mean") != std::string::npos);
  CHECK(twin.out.find("bit-identical") == std::string::npos);
  REQUIRE(gdsr_run(dir, "data make --out '" + (dir / "d") + "'" + clip + "0.07").status == 0);
  check_one_line_error(gdsr_run(dir, "data compare --a '" + (dir / "a") + "' --b '" + (dir / "d") + "'"), "LR frames");
  check_one_line_error(gdsr_run(dir, "data compare --a '" + (dir / "a") + "' --b '" + (dir / "none") + "'"), "none");
}

TEST_CASE("cli data: solver knobs reach the solver and the manifest / values out of range are refused") {
  TempDir dir("cli_knobs");
  const std::string out = dir / "ds";
  const Run mk =
      gdsr_run(dir, "data make --garment skirt_short --out '" + out +
                        "' --seconds 0.1 --lr-pd 0.08 --hr-pd 0.06 --rest-blend 2 --raster 64"
                        " --iterations 3 --friction 0.1 --self-thickness 0.002 --no-self-collision"
                        " --compression-ratio 0.5 --compression-exponent 1.5 --settle-frames 3 --contact-every 2"
                        " --self-slack 0.002 --self-detect-every 3 --self-slack-per-pd 0.25 --self-passes 2"
                        " --no-limbs-pass-through --no-limbs-pass-until-clear --untangle-step 0.25 --no-self-redetect"
                        " --tangle-retest --refuse-crossing-push"
                        " --track-rate 4 --max-push-step 0.01 --pinch-separation 0.08 --contact-travel 0"
                        " --pin-yield-rate 2.5 --dressed-radius 0.02");
  REQUIRE(mk.status == 0);
  const std::string manifest = gdsr_test::slurp(out + "/manifest.json");
  CHECK(manifest.find("\"iterations\": 3") != std::string::npos);
  CHECK(manifest.find("\"friction\": 0.1") != std::string::npos);
  CHECK(manifest.find("\"self_collision\": false") != std::string::npos);
  CHECK(manifest.find("\"self_thickness_m\": 0.002") != std::string::npos);
  CHECK(manifest.find("\"compression_ratio\": 0.5") != std::string::npos);
  CHECK(manifest.find("\"compression_pd_exponent\": 1.5") != std::string::npos);
  CHECK(manifest.find("\"settle_frames\": 3") != std::string::npos);
  CHECK(manifest.find("\"contact_every\": 2") != std::string::npos);
  CHECK(manifest.find("\"contact_travel\": 0") != std::string::npos);
  CHECK(manifest.find("\"pin_yield_rate_1_s\": 2.5") != std::string::npos);
  CHECK(manifest.find("\"self_slack_m\": 0.002") != std::string::npos);
  CHECK(manifest.find("\"self_detect_every\": 3") != std::string::npos);
  CHECK(manifest.find("\"self_passes\": 2") != std::string::npos);
  CHECK(manifest.find("\"self_slack_per_pd\": 0.25") != std::string::npos);
  CHECK(manifest.find("\"limbs_pass_through\": false") != std::string::npos);
  CHECK(manifest.find("\"limbs_pass_until_clear\": false") != std::string::npos);
  CHECK(manifest.find("\"self_redetect\": false") != std::string::npos);
  CHECK(manifest.find("\"self_tangle_retest\": true") != std::string::npos);
  CHECK(manifest.find("\"self_refuse_crossing_push\": true") != std::string::npos);
  CHECK(manifest.find("\"untangle_step\": 0.25") != std::string::npos);
  CHECK(manifest.find("\"hr_track_rate_1_s\": 4") != std::string::npos);
  CHECK(manifest.find("\"max_push_step_m\": 0.01") != std::string::npos);
  CHECK(manifest.find("\"pinch_separation_m\": 0.08") != std::string::npos);
  CHECK(manifest.find("\"dressed_radius_m\": 0.02") != std::string::npos);
  CHECK(manifest.find("\"layer_gap_m\": 0.004") != std::string::npos);  // the infer layer offset's default
  for (const std::string bad : {"--iterations 0",           "--friction -1",         "--self-thickness 1",
                                "--bend-stiffness -2",      "--compression-ratio 0", "--compression-exponent -1",
                                "--compression-exponent 5", "--settle-frames -1",    "--contact-every 0",
                                "--self-slack 0",           "--self-detect-every 0", "--self-passes 0",
                                "--self-slack-per-pd 0",    "--untangle-step -0.1",  "--track-rate -1",
                                "--track-rate nan",         "--max-push-step 0",     "--pinch-separation 0",
                                "--contact-travel -1",      "--pin-yield-rate -1",   "--dressed-radius -0.01",
                                "--dressed-radius nan"}) {
    const Run r = gdsr_run(dir, "data make --out '" + (dir / "bad") + "' " + bad);
    CHECK(r.status == 1);  // a refusal, not a crash (a sanitizer report exits 99)
    CHECK(r.err.find(bad.substr(0, bad.find(' '))) != std::string::npos);
    CHECK_FALSE(fs::exists(dir / "bad"));
  }
}

TEST_CASE("cli data: a recipe builds every clip once, skips what is built and valid, rebuilds what is not") {
  const std::string bvh = "/usr/share/assimp/models/BVH/";
  REQUIRE_MESSAGE(fs::exists(bvh + "01_03.bvh"), "assimp-testmodels is not installed (scripts/setup.sh)");
  TempDir dir("cli_recipe");
  std::ofstream(dir / "r.json") << R"({"lr_pd": 0.08, "hr_pd": 0.06, "rest_blend": 2, "clips": [
    {"garment": "skirt_short", "motion": ")" + bvh + R"(01_01.bvh", "start": 1, "seconds": 0.1, "split": "train"},
    {"garment": "skirt_short", "motion": ")" + bvh + R"(01_03.bvh", "start": 1, "seconds": 0.1, "split": "heldout",
     "name": "unseen"}]})";
  const std::string out = dir / "sets";
  const std::string make = "data make --recipe '" + (dir / "r.json") + "' --settle-frames 2 --raster 64 --out '" + out + "'";
  const Run first = gdsr_run(dir, make);
  REQUIRE(first.status == 0);
  CHECK(first.out.find("2 built, 0 already built") != std::string::npos);
  CHECK(fs::exists(out + "/skirt_short_01_01_1s/manifest.json"));
  CHECK(fs::exists(out + "/unseen/manifest.json"));
  const std::string splits = gdsr_test::slurp(out + "/splits.json");
  CHECK(splits.find("\"heldout\": [\n    \"unseen\"") != std::string::npos);
  CHECK(first.out.find("--val-data " + out + "/unseen") != std::string::npos);

  const auto stamp = fs::last_write_time(out + "/unseen/hr_frames.bin");
  const Run again = gdsr_run(dir, make);
  REQUIRE(again.status == 0);
  CHECK(again.out.find("0 built, 2 already built") != std::string::npos);
  CHECK(fs::last_write_time(out + "/unseen/hr_frames.bin") == stamp);

  // A damaged dataset (a truncated array) is rebuilt; the intact one is kept.
  fs::resize_file(out + "/unseen/hr_frames.bin", 100);
  const Run repair = gdsr_run(dir, make);
  REQUIRE(repair.status == 0);
  CHECK(repair.out.find("unseen (invalid") != std::string::npos);
  CHECK(repair.out.find("1 built, 1 already built") != std::string::npos);
  CHECK(gdsr_run(dir, "data check --data '" + out + "/unseen'").status == 0);

  // Another HR tracking rate is another dataset: both are rebuilt, with the rate in the manifest.
  std::string tracked = gdsr_test::slurp(dir / "r.json");
  tracked.insert(1, R"("hr_track_rate": 3, )");
  std::ofstream(dir / "r.json") << tracked;
  const Run retrack = gdsr_run(dir, make);
  REQUIRE(retrack.status == 0);
  CHECK(retrack.out.find("built with another HR tracking rate") != std::string::npos);
  CHECK(retrack.out.find("2 built, 0 already built") != std::string::npos);
  CHECK(gdsr_test::slurp(out + "/unseen/manifest.json").find("\"hr_track_rate_1_s\": 3") != std::string::npos);

  check_one_line_error(gdsr_run(dir, make + " --garment pants"), "--recipe");
  check_one_line_error(gdsr_run(dir, "data make --recipe '" + (dir / "none.json") + "' --out '" + out + "'"),
                       "none.json");
}
