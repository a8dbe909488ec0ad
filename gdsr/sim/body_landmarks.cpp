#include "gdsr/sim/body_landmarks.hpp"

#include "gdsr/error.hpp"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

namespace sim {

using gdsr::Vec3;

namespace {

// Max horizontal distance from the trunk axis of the body vertices within `slab` of height
// y0, ignoring vertices further than max_r (arms, hands). -1 if the slab is empty.
double radial_extent(const gdsr::TriMesh& b, const Vec3& axis, double y0, double slab, double max_r) {
  double r = -1;
  for (int v = 0; v < b.V.rows(); ++v) {
    if (std::abs(b.V(v, 1) - y0) > slab) continue;
    const double d = std::hypot(b.V(v, 0) - axis.x(), b.V(v, 2) - axis.z());
    if (d < max_r) r = std::max(r, d);
  }
  return r;
}

// Radial profile of the section of b at height y around the axis: for each direction
// psi_k = 2 pi k / bins, the farthest (nearest: the nearest) crossing below max_r of the ray
// from the axis with the triangles' intersection segments with the plane y; -1 where the ray
// meets nothing.
std::vector<double> section_profile(const gdsr::TriMesh& b, const Vec3& axis, double y, double max_r, int bins,
                                    bool nearest = false) {
  std::vector<double> r(bins, -1.0);
  constexpr double kTwoPi = 6.283185307179586;
  for (int f = 0; f < b.F.rows(); ++f) {
    Eigen::Vector2d pts[2];
    int n = 0;
    for (int k = 0; k < 3 && n < 2; ++k) {
      const Vec3 p = b.V.row(b.F(f, k)), q = b.V.row(b.F(f, (k + 1) % 3));
      if ((p.y() - y) * (q.y() - y) > 0 || p.y() == q.y()) continue;
      const Vec3 x = p + (q - p) * ((y - p.y()) / (q.y() - p.y()));
      pts[n++] = Eigen::Vector2d(x.z() - axis.z(), x.x() - axis.x());  // (front, side): psi = atan2(side, front)
    }
    if (n < 2) continue;
    for (int k = 0; k < bins; ++k) {
      const Eigen::Vector2d d(std::cos(kTwoPi * k / bins), std::sin(kTwoPi * k / bins));
      const Eigen::Vector2d e = pts[1] - pts[0];
      const double den = d.x() * e.y() - d.y() * e.x();
      if (std::abs(den) < 1e-15) continue;
      const double t = (pts[0].x() * e.y() - pts[0].y() * e.x()) / den;  // along the ray
      const double u = (pts[0].x() * d.y() - pts[0].y() * d.x()) / den;  // along the segment
      if (u >= 0 && u <= 1 && t > 0 && t < max_r) r[k] = r[k] < 0 ? t : nearest ? std::min(r[k], t) : std::max(r[k], t);
    }
  }
  return r;
}

// Centre (bounding-box middle in x and z) of the vertices on side `side` (+1: x > axis.x)
// within `slab` of height y and closer than max_dx to the axis in x; false if none.
bool leg_centre(const gdsr::TriMesh& b, const Vec3& axis, int side, double y, double slab, Vec3& c,
                double max_dx = 1e300) {
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (int v = 0; v < b.V.rows(); ++v) {
    const double dx = side * (b.V(v, 0) - axis.x());
    if (std::abs(b.V(v, 1) - y) > slab || dx <= 0 || dx > max_dx) continue;
    lo = lo.cwiseMin(Vec3(b.V.row(v)));
    hi = hi.cwiseMax(Vec3(b.V.row(v)));
  }
  if (lo.x() > hi.x()) return false;
  c = 0.5 * (lo + hi);
  c.y() = y;
  return true;
}

// Legs: centre lines and the ankle height (the lowest height above the foot where the leg's
// front-back extent is back to shin size).
void measure_legs(const gdsr::TriMesh& b, BodyLandmarks& lm) {
  const double H = lm.height, s = H / 1.75, slab = 0.01 * s;
  double ankle = lm.floor + 0.05 * H;
  int found = 0;
  for (int k = 0; k < 2; ++k) {
    const int side = k == 0 ? 1 : -1;
    Vec3 shin;
    if (!leg_centre(b, lm.axis, side, lm.floor + 0.25 * H, slab, shin)) continue;
    auto zext = [&](double y) {
      double lo = 1e300, hi = -1e300;
      for (int v = 0; v < b.V.rows(); ++v)
        if (std::abs(b.V(v, 1) - y) <= slab && side * (b.V(v, 0) - lm.axis.x()) > 0 &&
            std::abs(b.V(v, 0) - shin.x()) < 0.12 * s) {
          lo = std::min(lo, b.V(v, 2));
          hi = std::max(hi, b.V(v, 2));
        }
      return hi - lo;
    };
    const double e_shin = zext(lm.floor + 0.20 * H);
    double a = lm.floor + 0.12 * H;
    for (double y = lm.floor + 0.02 * H; y < lm.floor + 0.12 * H; y += 0.004 * s)
      if (zext(y) < 1.3 * e_shin) {
        a = y;
        break;
      }
    ankle = found == 0 ? a : std::max(ankle, a);
    ++found;
  }
  lm.ankle_y = ankle;
  for (int k = 0; k < 2; ++k) {
    const int side = k == 0 ? 1 : -1;
    const double ytop = lm.crotch_y - 0.06 * s, ybot = lm.ankle_y + 0.04 * s;
    if (!leg_centre(b, lm.axis, side, ytop, slab, lm.leg_top[k], 0.22 * s))
      lm.leg_top[k] = Vec3(lm.axis.x() + side * lm.leg_x, ytop, lm.axis.z());
    if (!leg_centre(b, lm.axis, side, ybot, slab, lm.leg_bottom[k]))
      lm.leg_bottom[k] = Vec3(lm.leg_top[k].x(), ybot, lm.leg_top[k].z());
  }
}

// Radius of the section of `pts` (an arm's surface points) around its own centre in each of n
// bins of width w along the unit line (start, d), from the points within 1.5 bins of the bin's
// middle; the centre is the middle of their extent across the line. Distances from the line
// itself grow and shrink where a bent elbow takes the arm off it (the CMU salsa skeleton's rest
// pose: 7.3 cm on a 5 cm upper arm, and one wrist found on the hand, 10 cm beyond the other),
// and a section of a ~3,000-vertex body holds only a few points, hence the wider window. 0 where
// no point lies.
std::vector<double> section_radii(const std::vector<Vec3>& pts, const Vec3& start, const Vec3& d, int n, double w) {
  const Vec3 u = d.cross(Vec3::UnitY()).normalized(), v = d.cross(u);
  std::vector<std::vector<Eigen::Vector2d>> bins(n);
  for (const auto& p : pts) {
    const Vec3 o = p - start;
    const double t = o.dot(d) / w - 0.5;  // in bins, from the middle of bin 0
    const Eigen::Vector2d q(o.dot(u), o.dot(v));
    for (int i = std::max(0, static_cast<int>(std::ceil(t - 1.5)));
         i <= std::min(n - 1, static_cast<int>(std::floor(t + 1.5))); ++i)
      bins[i].push_back(q);
  }
  std::vector<double> r(n, 0);
  for (int i = 0; i < n; ++i) {
    if (bins[i].empty()) continue;
    Eigen::Vector2d lo = bins[i][0], hi = bins[i][0];
    for (const auto& q : bins[i]) lo = lo.cwiseMin(q), hi = hi.cwiseMax(q);
    const Eigen::Vector2d c = 0.5 * (lo + hi);
    for (const auto& q : bins[i]) r[i] = std::max(r[i], (q - c).norm());
  }
  return r;
}

// Arms: the vertices clear of the trunk on each side above the lowest height an A-pose hand
// reaches, their principal line, the shoulder joint on it at the trunk's side and the wrist
// at the narrowest section before the hand.
void measure_arms(const gdsr::TriMesh& b, BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  for (int k = 0; k < 2; ++k) {
    const int side = k == 0 ? 1 : -1;
    std::vector<Vec3> pts;
    for (int v = 0; v < b.V.rows(); ++v)
      if (side * (b.V(v, 0) - lm.axis.x()) > 0.25 * s && b.V(v, 1) > lm.armpit_y - 0.45 * s) pts.push_back(b.V.row(v));
    if (pts.size() < 30) continue;
    Vec3 m = Vec3::Zero();
    for (const auto& p : pts) m += p;
    m /= static_cast<double>(pts.size());
    Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
    for (const auto& p : pts) C += (p - m) * (p - m).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(C);
    Vec3 d = es.eigenvectors().col(2);
    if (side * d.x() < 0) d = -d;
    if (side * d.x() < 0.5) continue;  // arm hanging down or forward: not a T/A-pose arm
    // Shoulder joint: the line's point at 0.17 s from the axis (sideways).
    const double t_root = (lm.axis.x() + side * 0.17 * s - m.x()) / d.x();
    double t_max = -1e300;
    for (const auto& p : pts) t_max = std::max(t_max, (p - m).dot(d));
    const double L = t_max - t_root;
    if (!(L > 0.3 * s)) continue;
    // Distance from the line in 1 cm bins along it: a sleeve about the line must clear it.
    const int nb = static_cast<int>(std::ceil(L / (0.01 * s))) + 1;
    std::vector<double> rad(nb, 0);
    for (const auto& p : pts) {
      const double t = (p - m).dot(d);
      const int i = static_cast<int>((t - t_root) / (0.01 * s));
      if (i >= 0 && i < nb) rad[i] = std::max(rad[i], ((p - m) - t * d).norm());
    }
    // The wrist: the narrowest section between 60% of the way to the fingertips and the hand's
    // widest section (the widest beyond 70%; further on the fingers narrow again), measured
    // about the sections' own centres.
    const std::vector<double> sec = section_radii(pts, m + t_root * d, d, nb, 0.01 * s);
    int hand = -1;
    for (int i = static_cast<int>(0.7 * nb); i < nb; ++i)
      if (hand < 0 || sec[i] > sec[hand]) hand = i;
    int wrist = -1;
    for (int i = static_cast<int>(0.6 * nb); i < hand; ++i)
      if (sec[i] > 0 && (wrist < 0 || sec[i] < sec[wrist])) wrist = i;
    if (wrist < 0) continue;
    double r = 0;
    for (int i = static_cast<int>(0.08 * s / (0.01 * s)); i <= wrist; ++i) r = std::max(r, rad[i]);
    lm.arm_found[k] = true;
    lm.arm_root[k] = m + t_root * d;
    lm.arm_dir[k] = d;
    lm.arm_len[k] = (wrist + 0.5) * 0.01 * s;
    lm.arm_r[k] = r;
    lm.wrist_r[k] = *std::max_element(rad.begin() + std::max(0, wrist - 1), rad.begin() + std::min(nb, wrist + 2));
  }
}

// Trunk box, shoulder top and neck section (see the header).
void measure_upper_trunk(const gdsr::TriMesh& b, BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  // An A-pose arm hangs within reach of the axis beside the upper trunk: its points (beyond
  // the shoulder joint, within the arm's radius of its line) are not trunk.
  auto on_arm = [&](const Vec3& p) {
    for (int k = 0; k < 2; ++k) {
      if (!lm.arm_found[k]) continue;
      const double t = (p - lm.arm_root[k]).dot(lm.arm_dir[k]);
      if (t > 0 && ((p - lm.arm_root[k]) - t * lm.arm_dir[k]).norm() < lm.arm_r[k] + 0.005 * s) return true;
    }
    return false;
  };
  auto box = [&](double y0, double y1, double rmin, double rmax, Vec3& lo, Vec3& hi) {
    lo = Vec3::Constant(1e300);
    hi = Vec3::Constant(-1e300);
    for (int v = 0; v < b.V.rows(); ++v) {
      const double y = b.V(v, 1), r = std::hypot(b.V(v, 0) - lm.axis.x(), b.V(v, 2) - lm.axis.z());
      if (y < y0 || y > y1 || r < rmin || r > rmax || on_arm(b.V.row(v).transpose())) continue;
      lo = lo.cwiseMin(Vec3(b.V.row(v)));
      hi = hi.cwiseMax(Vec3(b.V.row(v)));
    }
    if (lo.x() > hi.x()) lo = hi = Vec3(lm.axis.x(), y0, lm.axis.z());
  };
  lm.shirt_hem_y = lm.hip_y + 0.4 * (lm.waist_y - lm.hip_y);
  box(lm.shirt_hem_y, lm.armpit_y, 0, 0.26 * s, lm.trunk_lo, lm.trunk_hi);
  lm.shoulder_top_y = lm.shoulder_y;
  for (int v = 0; v < b.V.rows(); ++v) {
    const double dx = std::abs(b.V(v, 0) - lm.axis.x());
    if (dx > 0.09 * s && dx < 0.17 * s && b.V(v, 1) < lm.neck_y + 0.08 * s)
      lm.shoulder_top_y = std::max(lm.shoulder_top_y, b.V(v, 1));
  }
  // Neck (and a chin leaning forward) from just above the shoulder top to 6 cm above it.
  box(lm.shoulder_top_y + 0.005 * s, lm.shoulder_top_y + 0.06 * s, 0, 0.16 * s, lm.neck_lo, lm.neck_hi);
}

}  // namespace

gdsr::Vec2 trunk_extent(const gdsr::TriMesh& b, const BodyLandmarks& lm, double y0, double y1, double max_r) {
  gdsr::Vec2 e(0, 0);
  for (int v = 0; v < b.V.rows(); ++v) {
    if (b.V(v, 1) < y0 || b.V(v, 1) > y1) continue;
    const double dx = b.V(v, 0) - lm.axis.x(), dz = b.V(v, 2) - lm.axis.z();
    if (std::hypot(dx, dz) >= max_r) continue;
    e.x() = std::max(e.x(), std::abs(dx));
    e.y() = std::max(e.y(), std::abs(dz));
  }
  return e;
}

BodyLandmarks measure_body(const gdsr::TriMesh& b) {
  if (b.V.rows() < 4 || !b.V.allFinite()) gdsr::fail("sim/body_landmarks", "body rest mesh is empty or not finite");
  BodyLandmarks lm;
  lm.floor = b.V.col(1).minCoeff();
  lm.height = b.V.col(1).maxCoeff() - lm.floor;
  if (!(lm.height > 0.3)) gdsr::fail("sim/body_landmarks", "body is shorter than 0.3 m (expected metres, Y up)");
  const double H = lm.height, s = H / 1.75;
  lm.armpit_y = lm.floor + 0.73 * H;
  lm.shoulder_y = lm.floor + 0.81 * H;
  lm.neck_y = lm.floor + 0.85 * H;
  // Trunk axis: mean x, z of the vertices around mid-height of the trunk, without those farther
  // than kTrunkReach from the slab's median: an A-pose's hands and forearms reach down into the
  // slab (the t-shirt's rest, rest_arm_drop_degrees). Counted, they moved the axis 16-37 mm off
  // the one of the same body with its arms level (CMU 01_01, 131_02, salsa 60_02 / 61_03); on the
  // 131_02 walker the t-shirt sat 3 cm off one hip and 10 cm off the other.
  constexpr double kTrunkReach = 0.3;  // metres x H / 1.75
  std::vector<int> slab_v;
  for (int v = 0; v < b.V.rows(); ++v)
    if (std::abs(b.V(v, 1) - (lm.floor + 0.62 * H)) < 0.03 * s) slab_v.push_back(v);
  if (slab_v.empty()) gdsr::fail("sim/body_landmarks", "body has no trunk at 0.62 of its height");
  auto median = [&](int col) {
    std::vector<double> a;
    for (int v : slab_v) a.push_back(b.V(v, col));
    std::nth_element(a.begin(), a.begin() + a.size() / 2, a.end());
    return a[a.size() / 2];
  };
  const double mx = median(0), mz = median(2);
  Vec3 c = Vec3::Zero();
  int n = 0;
  for (int v : slab_v)
    if (std::hypot(b.V(v, 0) - mx, b.V(v, 2) - mz) < kTrunkReach * s) {
      c += b.V.row(v).transpose();
      ++n;
    }
  if (n == 0)
    gdsr::fail("sim/body_landmarks", "body has no trunk around the middle of its section at 0.62 of its height");
  lm.axis = c / n;
  lm.axis.y() = 0;  // the axis is vertical: only its x, z are meaningful
  const double slab = 0.015 * s, max_r = 0.28 * s;
  // Crotch: highest height below 0.56 H where no vertex lies near the mid-plane x = axis.
  lm.crotch_y = lm.floor + 0.47 * H;
  for (double y = lm.floor + 0.56 * H; y > lm.floor + 0.35 * H; y -= 0.005 * s) {
    bool mid = false;
    for (int v = 0; v < b.V.rows() && !mid; ++v)
      mid = std::abs(b.V(v, 1) - y) < 0.02 * s && std::abs(b.V(v, 0) - lm.axis.x()) < 0.03 * s;
    if (!mid) {
      lm.crotch_y = y;
      break;
    }
  }
  // Waist: narrowest trunk section between crotch + 0.17 H and 0.72 H; hips: widest below.
  lm.waist_y = lm.floor + 0.61 * H;
  lm.waist_r = 1e9;
  for (double y = lm.crotch_y + 0.17 * H; y <= lm.floor + 0.72 * H; y += 0.005 * s) {
    const double r = radial_extent(b, lm.axis, y, slab, max_r);
    if (r > 0 && r < lm.waist_r) {
      lm.waist_r = r;
      lm.waist_y = y;
    }
  }
  if (!(lm.waist_r < 1e9)) gdsr::fail("sim/body_landmarks", "body has no trunk at waist height");
  lm.hip_r = lm.waist_r;
  lm.hip_y = lm.waist_y;
  for (double y = lm.crotch_y + 0.03 * s; y <= lm.waist_y; y += 0.005 * s) {
    const double r = radial_extent(b, lm.axis, y, slab, max_r);
    if (r > lm.hip_r) {
      lm.hip_r = r;
      lm.hip_y = y;
    }
  }
  lm.chest_r = std::max(radial_extent(b, lm.axis, lm.floor + 0.70 * H, slab, 0.24 * s), lm.waist_r);
  // The waist section from the axis: directions that meet nothing (a hole in a scan) take the
  // widest extent, so a garment fitted to it never goes inside the body.
  lm.waist_profile = section_profile(b, lm.axis, lm.waist_y, max_r, BodyLandmarks::kWaistBins);
  for (double& r : lm.waist_profile) r = r > 0 ? std::min(r, lm.waist_r) : lm.waist_r;
  lm.shoulder_halfwidth = 0.19 * s;
  // Legs: vertices right of the axis at thigh height.
  double sx = 0;
  int nl = 0;
  const double thigh_y = lm.floor + 0.40 * H;
  for (int v = 0; v < b.V.rows(); ++v)
    if (std::abs(b.V(v, 1) - thigh_y) < slab && b.V(v, 0) > lm.axis.x() && b.V(v, 0) - lm.axis.x() < max_r) {
      sx += b.V(v, 0) - lm.axis.x();
      ++nl;
    }
  lm.leg_x = nl ? sx / nl : 0.09 * s;
  lm.thigh_r = 0.08 * s;
  lm.bust_r = lm.waist_r;
  for (double y = lm.waist_y; y <= lm.armpit_y; y += 0.005 * s)
    lm.bust_r = std::max(lm.bust_r, radial_extent(b, lm.axis, y, slab, 0.24 * s));
  // The trunk's own section under the armpits: the nearest crossing from the axis, so that arms
  // hanging beside the trunk (within max_r) are not taken for it.
  lm.bust_y = lm.armpit_y - 0.02 * s;
  lm.bust_profile = section_profile(b, lm.axis, lm.bust_y, 0.24 * s, BodyLandmarks::kWaistBins, /*nearest=*/true);
  for (double& r : lm.bust_profile) r = r > 0 ? std::min(r, lm.bust_r) : lm.bust_r;
  measure_legs(b, lm);
  measure_arms(b, lm);
  measure_upper_trunk(b, lm);
  return lm;
}

double waist_radius(const BodyLandmarks& lm, double psi) {
  if (lm.waist_profile.empty()) return lm.waist_r;
  const int n = static_cast<int>(lm.waist_profile.size());
  double t = psi / 6.283185307179586 * n;
  t -= n * std::floor(t / n);
  const int i = static_cast<int>(t) % n;
  const double a = t - std::floor(t);
  return (1 - a) * lm.waist_profile[i] + a * lm.waist_profile[(i + 1) % n];
}

double waist_fit_shrink(const BodyLandmarks& lm, double psi, double below) {
  const double drop = std::min(0.1 * lm.height / 1.75, 0.7 * std::max(lm.waist_y - lm.hip_y, 0.0));
  if (!(drop > 0)) return 0;
  const double t = std::clamp(below / drop, 0.0, 1.0);
  return (lm.waist_r - waist_radius(lm, psi)) * (1 - t * t * (3 - 2 * t));
}

namespace {
constexpr double kTwoPi = 6.283185307179586;
}  // namespace

SectionCurve::SectionCurve(const std::vector<double>& profile, double fallback_r, double ease) {
  const int n = profile.empty() ? BodyLandmarks::kWaistBins : static_cast<int>(profile.size());
  r_.resize(n);
  for (int k = 0; k < n; ++k) r_[k] = (profile.empty() ? fallback_r : profile[k]) + ease;
  arc_.assign(n + 1, 0.0);
  for (int k = 0; k < n; ++k) {
    const double p0 = kTwoPi * k / n, p1 = kTwoPi * (k + 1) / n;
    const double q = r_[(k + 1) % n];
    arc_[k + 1] =
        arc_[k] + std::hypot(q * std::sin(p1) - r_[k] * std::sin(p0), q * std::cos(p1) - r_[k] * std::cos(p0));
  }
}

double SectionCurve::radius(double psi) const {
  const int n = static_cast<int>(r_.size());
  double t = psi / kTwoPi * n;
  t -= n * std::floor(t / n);
  const int i = std::min(static_cast<int>(t), n - 1);
  const double w = t - i;
  return (1 - w) * r_[i] + w * r_[(i + 1) % n];
}

double SectionCurve::psi_at(double f) const {
  const int n = static_cast<int>(r_.size());
  const double s = (f - std::floor(f)) * arc_[n];
  const int i =
      std::clamp(static_cast<int>(std::upper_bound(arc_.begin(), arc_.end(), s) - arc_.begin()) - 1, 0, n - 1);
  const double len = arc_[i + 1] - arc_[i];
  const double w = len > 0 ? std::clamp((s - arc_[i]) / len, 0.0, 1.0) : 0.0;
  return kTwoPi * (i + w) / n;
}

double waist_perimeter(const BodyLandmarks& lm, double ease) {
  return SectionCurve(lm.waist_profile, lm.waist_r, ease).perimeter();
}

WaistCurve::WaistCurve(const BodyLandmarks& lm, double a, double drop) {
  // The perimeter grows with the ease (by 2 pi per metre on a convex section): bisection.
  const double target = kTwoPi * a;
  double lo = 0, hi = std::max(a, 0.0);
  if (waist_perimeter(lm, 0) < target) {
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      (waist_perimeter(lm, mid) < target ? lo : hi) = mid;
    }
    ease_ = 0.5 * (lo + hi);
  }
  static_cast<SectionCurve&>(*this) = SectionCurve(lm.waist_profile, lm.waist_r, ease_);
  drop_ = drop > 0 ? drop : std::max(lm.waist_y - lm.hip_y, 0.0);
}

double WaistCurve::weight(double below) const {
  if (!(drop_ > 0)) return below <= 0 ? 1.0 : 0.0;
  const double t = std::clamp(below / drop_, 0.0, 1.0);
  return 1 - t * t;
}

}  // namespace sim
