// The detail target of --detail-target (train/detail_target.hpp) against closed forms: it is
// the HR frame when the coarse shape is the coarse truth, and moves rigidly with a rigidly
// moved coarse shape.
#include <doctest/doctest.h>

#include "gdsr/geometry/correspondence.hpp"
#include "tests/support/data_fixtures.hpp"
#include "train/detail_target.hpp"

#include <Eigen/Geometry>

TEST_CASE("detail target: the HR frame on the coarse truth, rigidly moved with the coarse shape") {
  const gdsr::Dataset d = gdsr_test::wave_dataset();
  const int t = 3;
  const gdsr::Points3& hr = d.hr_frames[t];
  const gdsr::Points3 coarse = gdsr::downsample(d.corr, hr);
  std::vector<int> vertices;
  for (int v = 0; v < d.corr.hr_vertices; v += 3) vertices.push_back(v);

  const gdsr::Points3 same = gdsr::detail_target(d.corr, hr, coarse, coarse, vertices, 1e-2);
  CHECK((same - hr).cwiseAbs().maxCoeff() < 1e-12);

  // C^ = R C* + s: the target is R HR + s at the listed vertices, HR elsewhere.
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::RowVector3d shift(0.3, -0.1, 0.05);
  const gdsr::Points3 moved = (coarse * R.transpose()).rowwise() + shift;
  const gdsr::Points3 target = gdsr::detail_target(d.corr, hr, coarse, moved, vertices, 1e-2);
  const gdsr::Points3 expect = (hr * R.transpose()).rowwise() + shift;
  double worst = 0;
  for (int v : vertices) worst = std::max(worst, (target.row(v) - expect.row(v)).norm());
  CHECK(worst < 1e-10);
  CHECK((target.row(1) - hr.row(1)).norm() == 0.0);  // not listed: untouched
  // The detail is not zero on this sheet, so the rotation above was a real test.
  const gdsr::Points3 up = gdsr::upsample(d.corr, coarse);
  CHECK((hr - up).rowwise().norm().maxCoeff() > 1e-4);

  CHECK_THROWS_WITH_AS(gdsr::detail_target(d.corr, hr, coarse, coarse, {d.corr.hr_vertices}, 1e-2),
                       doctest::Contains("out of range"), std::runtime_error);
}
