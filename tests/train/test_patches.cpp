#include <doctest/doctest.h>

#include "autograd/autograd.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "train/patches.hpp"
#include "tests/support/loss_test_meshes.hpp"

#include <algorithm>
#include <set>

using namespace gdsr;

namespace {

std::vector<int> fake_lr_map(int nv) {
  std::vector<int> m(nv);
  for (int v = 0; v < nv; ++v) m[v] = (v * 7) % 23;
  return m;
}

PatchSampler make_sampler(const GarmentMesh& g, int raster_size, PatchConfig cfg) {
  UVRaster r = rasterize_uv(g.UV, g.FUV, raster_size, raster_size, 4);
  return PatchSampler(std::move(r), g, fake_lr_map(static_cast<int>(g.V.rows())), cfg);
}

}  // namespace

TEST_CASE("patches: sampled windows stay inside the 1024 raster and cover garment pixels") {
  const GarmentMesh g = gdsr_test::cut_garment(41, 0.01);
  for (bool random : {true, false}) {
    CAPTURE(random);
    PatchConfig cfg;  // 80 x 80, 8 patches, coverage >= 0.1
    cfg.random_position = random;
    const PatchSampler s = make_sampler(g, 1024, cfg);
    std::mt19937_64 rng(7);
    for (int it = 0; it < 10; ++it) {
      const PatchBatch b = s.sample(rng);
      CHECK(b.patches.size() == static_cast<size_t>(random ? 8 : std::min<size_t>(8, s.grid().size())));
      for (const Patch& p : b.patches) {
        CHECK(p.x0 >= 0);
        CHECK(p.y0 >= 0);
        CHECK(p.x0 + p.size <= 1024);
        CHECK(p.y0 + p.size <= 1024);
        CHECK(p.size == 80);
        CHECK(s.coverage(p.x0, p.y0) >= 0.1);
        CHECK(p.num_garment_pixels() == static_cast<int>(std::lround(s.coverage(p.x0, p.y0) * 6400)));
      }
    }
  }
  CHECK_THROWS(make_sampler(g, 1024, PatchConfig{}).make_patch(1000, 0));
}

TEST_CASE("patches: a patch lists exactly the HR vertices under its pixels, its halo and LR triangles") {
  const GarmentMesh g = gdsr_test::cut_garment(41, 0.01);
  PatchConfig cfg;
  cfg.size = 40;
  const PatchSampler s = make_sampler(g, 256, cfg);
  const UVRaster& r = s.raster();
  const Csr vf = vertex_faces(g.F, static_cast<int>(g.V.rows()));
  const std::vector<int> lr = fake_lr_map(static_cast<int>(g.V.rows()));
  std::mt19937_64 rng(3);
  const PatchBatch b = s.sample(rng);
  REQUIRE(!b.patches.empty());
  for (size_t pi = 0; pi < b.patches.size(); ++pi) {
    const Patch& p = b.patches[pi];
    std::set<int> inside, faces;
    for (int y = p.y0; y < p.y0 + p.size; ++y)
      for (int x = p.x0; x < p.x0 + p.size; ++x) {
        const int t = r.tri[y * r.width + x];
        if (t >= 0)
          for (int k = 0; k < 3; ++k) inside.insert(g.F(t, k));
      }
    for (int v : inside)
      for (int k = vf.offsets[v]; k < vf.offsets[v + 1]; ++k) faces.insert(vf.items[k]);
    const std::set<int> got_inside(p.vertices.begin(), p.vertices.begin() + p.num_inside);
    CHECK(got_inside == inside);
    CHECK(std::set<int>(p.faces.begin(), p.faces.end()) == faces);
    std::set<int> all;
    for (int f : faces)
      for (int k = 0; k < 3; ++k) all.insert(g.F(f, k));
    CHECK(std::set<int>(p.vertices.begin(), p.vertices.end()) == all);
    CHECK(p.vertices.size() == all.size());  // no duplicates
    for (size_t f = 0; f < p.faces.size(); ++f)
      for (int k = 0; k < 3; ++k) CHECK(p.vertices[p.local_faces(static_cast<int>(f), k)] == g.F(p.faces[f], k));
    std::set<int> lrt;
    for (int v : p.vertices) lrt.insert(lr[v]);
    CHECK(std::set<int>(p.lr_triangles.begin(), p.lr_triangles.end()) == lrt);
    for (size_t i = 0; i < p.vertices.size(); ++i) CHECK(b.vertices[b.rows[pi][i]] == p.vertices[i]);
    for (int t : p.lr_triangles) CHECK(std::binary_search(b.lr_triangles.begin(), b.lr_triangles.end(), t));
  }
}

TEST_CASE("patches: inside-vertex normals of a patch equal the whole mesh's (halo)") {
  const GarmentMesh g = gdsr_test::cut_garment(31, 0.01);
  PatchConfig cfg;
  cfg.size = 40;
  const PatchSampler s = make_sampler(g, 256, cfg);
  const Points3 X = gdsr_test::bumpy(g.V, 0.3, 1.0, 3);
  const Points3 N = vertex_normals(X, g.F);
  const Patch p = s.make_patch(60, 60);
  Points3 Xp(static_cast<int>(p.vertices.size()), 3);
  for (size_t i = 0; i < p.vertices.size(); ++i) Xp.row(static_cast<int>(i)) = X.row(p.vertices[i]);
  const ag::Tensord n = vertex_normals(to_tensor<double>(Xp), p.topo);
  double err = 0;
  for (int i = 0; i < p.num_inside; ++i) err = std::max(err, (n.mat().row(i) - N.row(p.vertices[i])).norm());
  CHECK(p.num_inside > 10);
  CHECK(err < 1e-12);
}

TEST_CASE("patches: the normal map of a flat patch is uniform (0.5, 0.5, 1) on the garment") {
  const GarmentMesh g = gdsr_test::cut_garment(41, 0.01);
  PatchConfig cfg;  // 80 x 80 of 1024
  const PatchSampler s = make_sampler(g, 1024, cfg);
  // A window across the diagonal edge of the cut: garment and background pixels.
  const Vec2 px = s.raster().uv_to_pixel(Vec2(0.15, 0.15));
  const Patch p = s.make_patch(static_cast<int>(px.x()) - 40, static_cast<int>(px.y()) - 40);
  REQUIRE(p.num_garment_pixels() > 100);
  REQUIRE(p.num_garment_pixels() < 6400);
  Points3 Xp(static_cast<int>(p.vertices.size()), 3);
  for (size_t i = 0; i < p.vertices.size(); ++i) Xp.row(static_cast<int>(i)) = g.V.row(p.vertices[i]);
  const ag::Tensorf n = vertex_normals(to_tensor<float>(Xp), p.topo);
  const double bg = 0.25;
  const ag::Tensorf img = draw_normal_map(n, p, bg);
  REQUIRE(img.shape() == ag::Shape{1, 3, 80, 80});
  const float* d = img.data();
  double err = 0, bg_err = 0;
  for (int i = 0; i < 6400; ++i) {
    const double c[3] = {d[i], d[6400 + i], d[2 * 6400 + i]};
    if (p.mask[i]) {
      err = std::max({err, std::abs(c[0] - 0.5), std::abs(c[1] - 0.5), std::abs(c[2] - 1.0)});
    } else {
      bg_err = std::max({bg_err, std::abs(c[0] - bg), std::abs(c[1] - bg), std::abs(c[2] - bg)});
    }
  }
  CHECK(err < 1e-5);  // float raster barycentrics sum to 1 within ~1e-7
  CHECK(bg_err == 0.0);
  const ag::Tensorf pix = normal_map_pixels(n, p);
  CHECK(pix.rows() == p.num_garment_pixels());
  CHECK(pix.at(0, 2) == doctest::Approx(1.0).epsilon(1e-5));
}

TEST_CASE("patches: float64 gradient check of the normal map w.r.t. the patch's positions") {
  const GarmentMesh g = gdsr_test::cut_garment(21, 0.01);
  PatchConfig cfg;
  cfg.size = 24;
  const PatchSampler s = make_sampler(g, 128, cfg);
  const Points3 X = gdsr_test::bumpy(g.V, 0.3, 1.0, 4);
  const Patch p = s.make_patch(30, 30);
  REQUIRE(p.num_garment_pixels() > 0);
  Points3 Xp(static_cast<int>(p.vertices.size()), 3);
  for (size_t i = 0; i < p.vertices.size(); ++i) Xp.row(static_cast<int>(i)) = X.row(p.vertices[i]);
  const ag::GradCheckResult r = ag::gradcheck(
      [&](const std::vector<ag::Tensord>& in) { return draw_normal_map(vertex_normals(in[0], p.topo), p); },
      {to_tensor<double>(Xp)});
  INFO(r.report());
  CHECK(r.max_rel_error < 1e-6);
}

TEST_CASE("patches: validation's normal-map SSIM of a tilted flat patch is the closed form") {
  // A flat garment against itself rotated by theta about x: the normal maps are uniform,
  // (0.5, 0.5, 1) and (0.5, 0.5 - 0.5 sin theta, 0.5 + 0.5 cos theta), so on a patch the garment
  // fills, every window is flat and SSIM = mean over channels of (2 a b + C1) / (a^2 + b^2 + C1),
  // C1 = (0.01 * 255)^2 (Wang et al. 2004; the structure term is 1 on flat windows).
  const GarmentMesh g = gdsr_test::cut_garment(31, 0.01);
  PatchConfig cfg;
  cfg.size = 40;
  const PatchSampler s = make_sampler(g, 256, cfg);
  std::vector<Patch> full;  // windows the garment fills
  for (int y = 0; y + cfg.size <= 256 && full.size() < 2; y += 10)
    for (int x = 0; x + cfg.size <= 256 && full.size() < 2; x += 10) {
      Patch p = s.make_patch(x, y);
      if (p.num_garment_pixels() == p.size * p.size) full.push_back(std::move(p));
    }
  REQUIRE(full.size() == 2);
  const PatchBatch b = make_batch(full);
  const double theta = 0.6;
  Points3 flat(static_cast<int>(b.vertices.size()), 3), tilted = flat;
  for (size_t i = 0; i < b.vertices.size(); ++i) {
    const Vec3 x = g.V.row(b.vertices[i]).transpose();
    flat.row(static_cast<int>(i)) = Vec3(x.x(), x.y(), 0).transpose();  // the sheet lies in z = 0
    tilted.row(static_cast<int>(i)) = Vec3(x.x(), std::cos(theta) * x.y(), std::sin(theta) * x.y()).transpose();
  }
  const auto term = [](double a, double c) {
    const double C1 = std::pow(0.01 * 255, 2);
    a *= 255, c *= 255;
    return (2 * a * c + C1) / (a * a + c * c + C1);
  };
  const double closed = (1 + term(0.5, 0.5 - 0.5 * std::sin(theta)) + term(1.0, 0.5 + 0.5 * std::cos(theta))) / 3;
  CHECK(patch_normal_map_ssim(b, tilted, flat) == doctest::Approx(closed).epsilon(1e-5));  // float images
  CHECK(patch_normal_map_ssim(b, flat, flat) == doctest::Approx(1).epsilon(1e-9));
  CHECK(closed < 0.99);
  CHECK_THROWS_AS(patch_normal_map_ssim(b, flat.topRows(3), flat), std::runtime_error);
}
