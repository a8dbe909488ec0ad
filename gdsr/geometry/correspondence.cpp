#include "gdsr/geometry/correspondence.hpp"

#include "gdsr/error.hpp"

#include "gdsr/geometry/uv_raster.hpp"

#include <nanoflann.hpp>

#include <stdexcept>
#include <string>

namespace gdsr {
namespace {

struct UVCloud {
  const Points2& pts;
  size_t kdtree_get_point_count() const { return static_cast<size_t>(pts.rows()); }
  double kdtree_get_pt(size_t i, size_t d) const { return pts(static_cast<long>(i), static_cast<long>(d)); }
  template <class B> bool kdtree_get_bbox(B&) const { return false; }
};
using UVTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, UVCloud>, UVCloud, 2>;

BaryMap locate_all(const UVLocator& loc, const Points2& UV, const std::vector<int>& which) {
  BaryMap m;
  const int n = static_cast<int>(which.size());
  m.tri.assign(which.size(), -1);
  m.bary.resize(n, 3);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < n; ++i) {
    const UVHit h = loc.locate(UV.row(which[i]).transpose());
    m.tri[i] = h.tri;
    m.bary.row(i) = h.bary.transpose();
  }
  return m;
}

void check_garment(const GarmentMesh& g, const char* what) {
  if (g.V.rows() == 0 || g.F.rows() == 0 || g.UV.rows() == 0)
    gdsr::fail("correspondence", std::string("empty ") + what + " mesh");
  if (g.FUV.rows() != g.F.rows())
    gdsr::fail("correspondence", std::string(what) + " mesh has " + std::to_string(g.F.rows()) + " faces but " +
                                     std::to_string(g.FUV.rows()) + " UV faces");
  if (static_cast<long>(g.uv_to_vertex.size()) != g.UV.rows())
    gdsr::fail("correspondence", std::string(what) + " mesh uv_to_vertex size does not match UV");
}

}  // namespace

std::vector<int> first_uv_copy(const std::vector<int>& uv_to_vertex, int num_vertices) {
  std::vector<int> first(static_cast<size_t>(num_vertices), -1);
  for (int u = static_cast<int>(uv_to_vertex.size()) - 1; u >= 0; --u) {
    const int v = uv_to_vertex[u];
    if (v < 0 || v >= num_vertices) gdsr::fail("correspondence", "uv_to_vertex index out of range");
    first[v] = u;
  }
  for (int v = 0; v < num_vertices; ++v)
    if (first[v] < 0) gdsr::fail("correspondence", "vertex " + std::to_string(v) + " has no UV copy");
  return first;
}

Correspondence compute_correspondence(const GarmentMesh& lr, const GarmentMesh& hr) {
  check_garment(lr, "LR");
  check_garment(hr, "HR");
  Correspondence c;
  c.lr_F = lr.F;
  c.hr_F = hr.F;
  c.lr_uv_to_vertex = lr.uv_to_vertex;
  c.lr_vertices = static_cast<int>(lr.V.rows());
  c.hr_vertices = static_cast<int>(hr.V.rows());

  const std::vector<int> hr_first = first_uv_copy(hr.uv_to_vertex, c.hr_vertices);
  const UVLocator lr_loc(lr.UV, lr.FUV);
  c.hr_from_lr = locate_all(lr_loc, hr.UV, hr_first);

  std::vector<int> lr_all(static_cast<size_t>(lr.UV.rows()));
  for (size_t u = 0; u < lr_all.size(); ++u) lr_all[u] = static_cast<int>(u);
  const UVLocator hr_loc(hr.UV, hr.FUV);
  c.lr_from_hr = locate_all(hr_loc, lr.UV, lr_all);

  const UVCloud cloud{lr.UV};
  UVTree tree(2, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  c.hr_nearest_lr.assign(static_cast<size_t>(c.hr_vertices), -1);
#pragma omp parallel for schedule(static)
  for (int i = 0; i < c.hr_vertices; ++i) {
    const double q[2] = {hr.UV(hr_first[i], 0), hr.UV(hr_first[i], 1)};
    unsigned idx = 0;
    double d2 = 0;
    tree.knnSearch(q, 1, &idx, &d2);
    c.hr_nearest_lr[i] = lr.uv_to_vertex[idx];
  }
  return c;
}

Points3 apply_bary(const BaryMap& map, const Faces& faces, const Points3& positions) {
  Points3 out(map.size(), 3);
  // Serial on purpose: ~1 ns per entry, an OpenMP team costs more than the loop.
  for (int i = 0; i < map.size(); ++i) {
    const int f = map.tri[i];
    out.row(i) = map.bary(i, 0) * positions.row(faces(f, 0)) + map.bary(i, 1) * positions.row(faces(f, 1)) +
                 map.bary(i, 2) * positions.row(faces(f, 2));
  }
  return out;
}

Points3 upsample(const Correspondence& c, const Points3& lr_positions) {
  if (lr_positions.rows() != c.lr_vertices)
    gdsr::fail("upsample", "got " + std::to_string(lr_positions.rows()) + " LR positions, expected " +
                               std::to_string(c.lr_vertices));
  return apply_bary(c.hr_from_lr, c.lr_F, lr_positions);
}

Points3 downsample(const Correspondence& c, const Points3& hr_positions) {
  if (hr_positions.rows() != c.hr_vertices)
    gdsr::fail("downsample", "got " + std::to_string(hr_positions.rows()) + " HR positions, expected " +
                                 std::to_string(c.hr_vertices));
  const Points3 per_uv = apply_bary(c.lr_from_hr, c.hr_F, hr_positions);
  Points3 sum = Points3::Zero(c.lr_vertices, 3);
  std::vector<int> count(static_cast<size_t>(c.lr_vertices), 0);
  for (int u = 0; u < per_uv.rows(); ++u) {
    sum.row(c.lr_uv_to_vertex[u]) += per_uv.row(u);
    ++count[c.lr_uv_to_vertex[u]];
  }
  for (int v = 0; v < c.lr_vertices; ++v) {
    if (count[v] == 0) gdsr::fail("downsample", "LR vertex " + std::to_string(v) + " has no UV copy");
    sum.row(v) /= count[v];
  }
  return sum;
}

Points3 at_lr_scale(const Correspondence& c, const Points3& hr_positions) {
  return upsample(c, downsample(c, hr_positions));
}

void validate_correspondence(const Correspondence& c) {
  auto check_map = [](const BaryMap& m, long expect, long faces, const char* name) {
    if (m.size() != expect || m.bary.rows() != expect)
      gdsr::fail("correspondence", std::string(name) + " has " + std::to_string(m.size()) + " entries, expected " +
                                       std::to_string(expect));
    for (int i = 0; i < m.size(); ++i) {
      if (m.tri[i] < 0 || m.tri[i] >= faces)
        gdsr::fail("correspondence", std::string(name) + " entry " + std::to_string(i) + " has triangle " +
                                         std::to_string(m.tri[i]) + " out of range");
      if (!m.bary.row(i).allFinite())
        gdsr::fail("correspondence", std::string(name) + " entry " + std::to_string(i) + " is NaN");
    }
  };
  check_map(c.hr_from_lr, c.hr_vertices, c.lr_F.rows(), "hr_from_lr");
  check_map(c.lr_from_hr, static_cast<long>(c.lr_uv_to_vertex.size()), c.hr_F.rows(), "lr_from_hr");
  if (static_cast<int>(c.hr_nearest_lr.size()) != c.hr_vertices)
    gdsr::fail("correspondence", "hr_nearest_lr has the wrong size");
  for (int v : c.hr_nearest_lr)
    if (v < 0 || v >= c.lr_vertices) gdsr::fail("correspondence", "hr_nearest_lr index out of range");
  for (int v : c.lr_uv_to_vertex)
    if (v < 0 || v >= c.lr_vertices) gdsr::fail("correspondence", "lr_uv_to_vertex index out of range");
  if (c.lr_F.size() && (c.lr_F.minCoeff() < 0 || c.lr_F.maxCoeff() >= c.lr_vertices))
    gdsr::fail("correspondence", "LR face index out of range");
  if (c.hr_F.size() && (c.hr_F.minCoeff() < 0 || c.hr_F.maxCoeff() >= c.hr_vertices))
    gdsr::fail("correspondence", "HR face index out of range");
}

}  // namespace gdsr
