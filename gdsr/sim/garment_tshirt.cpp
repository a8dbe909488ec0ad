// Long-sleeve t-shirt for a rest pose with the arms clear of the trunk (T- or A-pose). Torso:
// an elliptic cylinder (semi-axes A sideways, B front-back) around the trunk, cut into a front
// and a back panel (side seams at the ellipse's sides); above the shoulder line each panel
// folds horizontally inwards to the shoulder seam (the shoulder top is a horizontal plane with
// an elliptic neck opening). Sleeves: a circular cone around each arm's centre line from the
// torso to the forearm (radius rs at the shoulder joint, tapering to a cuff kCuffEase over the
// wrist's radius, kCuffAboveWrist up from the wrist), one panel per sleeve (a sector of a ring)
// with its seam under the arm. The armhole is the exact intersection curve of sleeve cone and
// torso cylinder, so both developments are isometric and the sleeve cap sews edge by edge to
// the armhole of the front and back panels. Only the shoulder fold is not isometric (shear
// where the ellipse turns sideways). No pins: it hangs on the shoulders. Cut for an A-pose rest
// (sim::rest_arm_drop_degrees): cut for a T-pose, the sleeves were short over the top of the
// arm once the arms came down and dragged the shoulders off a salsa dancer.
#include "gdsr/error.hpp"
#include "gdsr/sim/garment_design.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kHole = 10;           // armhole edges per torso panel (a sleeve cap has 2 kHole)
constexpr int kCuff = 8;            // edges of the cuff (an arc of the sleeve's flat ring)
constexpr double kCuffEase = 0.03;  // metres (x height / 1.75) of the cuff's radius over the wrist's
// Metres (x height / 1.75) from the cuff up to the wrist: the sleeve ends on the lower forearm.
// Down to the wrist, it slid onto the hand and bunched over it, and the cuff, caught by the hand
// and the forearm's turns, was pulled into the forearm and the arm came out of the sleeve (solver
// revision 28 has the figures).
constexpr double kCuffAboveWrist = 0.10;

struct Sleeve {
  Vec3 root, d, e1, e2;                       // centre line and frame: e1 down (perpendicular to d), e2 = e1 x d
  double rs = 0, slope = 0, t_cuff = 0;       // radius rs + slope t at distance t along d (slope <= 0)
  std::array<double, 2 * kHole + 1> theta{};  // theta[0]: bottom side-seam crossing, theta[kHole]: top
  Vec3 normal(double th) const { return std::cos(th) * e1 + std::sin(th) * e2; }
  Vec3 at(double t, double th) const { return root + t * d + (rs + slope * t) * normal(th); }
  // The cone's development: the generator theta = theta[0] + a runs along the flat x axis
  // from the shoulder joint (x = 0) with a the angle round the arm (0 to 2 pi), flat y > 0.
  // Exact for a cone (a sector of a ring around the apex beyond the wrist), the rectangle
  // (t, rs a) for a cylinder.
  bool cone() const { return slope < -1e-9; }
  double slant() const { return std::sqrt(1 + slope * slope); }
  double apex() const { return -rs / slope; }  // t of the apex (cone only)
  Vec2 flat(double t, double a) const {
    if (!cone()) return Vec2(t, rs * a);
    const double rho = (apex() - t) * slant(), phi = a * -slope / slant();
    return Vec2(apex() * slant() - rho * std::cos(phi), rho * std::sin(phi));
  }
  Vec3 unflat(const Vec2& q) const {
    if (!cone()) return at(q.x(), theta[0] + q.y() / rs);
    const double dx = apex() * slant() - q.x();
    const double t = apex() - std::hypot(dx, q.y()) / slant();
    return at(t, theta[0] + std::atan2(q.y(), dx) / (-slope / slant()));
  }
};

struct Shirt {
  double cx = 0, cz = 0, A = 0, B = 0;  // torso ellipse centre and semi-axes
  double hem_y = 0, Hsh = 0;            // hem height; flat height of the fold line
  double S = 0;                         // ellipse perimeter
  std::vector<double> psi, arc;         // arc length table over psi in [-pi/2, 3pi/2]
  Sleeve sl[2];
  Vec2 origin[4];  // flat origin of front, back, sleeve 0, sleeve 1
  double s_of(double p) const {
    const double t = (p + kPi / 2) / (2 * kPi) * (psi.size() - 1);
    const int i = std::clamp(static_cast<int>(t), 0, static_cast<int>(psi.size()) - 2);
    return arc[i] + (t - i) * (arc[i + 1] - arc[i]);
  }
  double psi_of(double s) const {
    const int i = std::clamp(static_cast<int>(std::upper_bound(arc.begin(), arc.end(), s) - arc.begin()) - 1, 0,
                             static_cast<int>(arc.size()) - 2);
    return psi[i] + (s - arc[i]) / (arc[i + 1] - arc[i]) * (psi[i + 1] - psi[i]);
  }
  // Exit parameter t of the sleeve's generator at angle th through the torso cylinder; NaN when
  // the line misses it.
  double exit_t(const Sleeve& q, double th) const {
    const Vec3 p0 = q.at(0, th), dir = q.d + q.slope * q.normal(th);  // t along d: n(th) is normal to d
    const double q0 = (p0.x() - cx) / A, q1 = dir.x() / A, w0 = (p0.z() - cz) / B, w1 = dir.z() / B;
    const double a = q1 * q1 + w1 * w1, b = q0 * q1 + w0 * w1, c = q0 * q0 + w0 * w0 - 1;
    const double disc = b * b - a * c;
    if (!(disc > 0) || a < 1e-12) return std::numeric_limits<double>::quiet_NaN();
    return (-b + std::sqrt(disc)) / a;
  }
  double hit(const Sleeve& q, double th) const {
    const double t = exit_t(q, th);
    if (std::isnan(t)) gdsr::fail("sim/garment_tshirt", "sleeve line misses the torso cylinder");
    return t;
  }
  bool sleeves_cross_torso() const {
    for (const Sleeve& q : sl)
      for (int j = 0; j < 64; ++j)
        if (std::isnan(exit_t(q, 2 * kPi * j / 64))) return false;
    return true;
  }
  // Flat point (relative to the torso panel's origin) of 3-D torso point P; back: panel 1.
  Vec2 torso_flat(const Vec3& P, int panel) const {
    double p = std::atan2((P.x() - cx) / A, (P.z() - cz) / B);
    if (panel == 1 && p < 0) p += 2 * kPi;
    return Vec2(s_of(p) - panel * S / 2, P.y() - hem_y);
  }
  Vec3 torso_place(int panel, const Vec2& q) const {
    const double p = psi_of(q.x() + panel * S / 2);
    const double X = A * std::sin(p), Z = B * std::cos(p);
    if (q.y() <= Hsh) return Vec3(cx + X, hem_y + q.y(), cz + Z);
    const double in = std::min(q.y() - Hsh, std::abs(Z));  // fold inwards towards the side plane
    return Vec3(cx + X, hem_y + Hsh, cz + Z - std::copysign(in, Z));
  }
};

}  // namespace

GarmentDesign design_tshirt(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  for (int k = 0; k < 2; ++k)
    if (!lm.arm_found[k] || std::abs(lm.arm_dir[k].y()) > 0.77)
      gdsr::fail("sim/garment_tshirt", "the body's rest pose needs both arms raised clear of the trunk (T- or A-pose)");
  auto sh = std::make_shared<Shirt>();
  Shirt& T = *sh;
  const double ease = 0.035 * s;  // over the trunk's bounding box (a rounded pelvis bulges diagonally)
  T.hem_y = lm.shirt_hem_y;
  T.cx = lm.axis.x();
  double rs = 0, rw = 0;  // sleeve radius at the shoulder joint and at the cuff
  for (int k = 0; k < 2; ++k) {
    rs = std::max(rs, lm.arm_r[k] + 0.02 * s);
    rw = std::max(rw, lm.wrist_r[k] + kCuffEase * s);
  }
  rw = std::min(rw, rs);
  // Side seams through the trunk's centre, moved towards the arms' plane only as far as the
  // sleeves need to cross them: in the arms' plane (4-8 cm behind the trunk's centre on the CMU
  // bodies) the ellipse had to reach that much further forward, a shirt 40-48 cm deep on a 25 cm trunk.
  const double arms_z = 0.5 * (lm.arm_root[0].z() + lm.arm_root[1].z());
  T.cz = std::clamp(0.5 * (lm.trunk_lo.z() + lm.trunk_hi.z()), arms_z - 0.5 * rs, arms_z + 0.5 * rs);
  T.A = std::max({lm.trunk_hi.x() - T.cx, T.cx - lm.trunk_lo.x()}) + ease;
  T.A = std::max({T.A, std::abs(lm.arm_root[0].x() - T.cx) + 0.05 * s, std::abs(lm.arm_root[1].x() - T.cx) + 0.05 * s});
  T.B = std::max({lm.trunk_hi.z() - T.cz, T.cz - lm.trunk_lo.z(), rs + 0.03 * s}) + ease;
  for (int k = 0; k < 2; ++k) T.B = std::max(T.B, std::abs(lm.arm_root[k].z() - T.cz) + rs + 0.03 * s);
  for (int k = 0; k < 2; ++k) {
    Sleeve& q = T.sl[k];
    q.root = lm.arm_root[k];
    q.d = lm.arm_dir[k];
    q.rs = rs;
    q.t_cuff = lm.arm_len[k] - kCuffAboveWrist * s;
    q.slope = (rw - rs) / q.t_cuff;
    q.e1 = (-Vec3::UnitY() + q.d * q.d.y()).normalized();
    q.e2 = q.e1.cross(q.d);
  }
  // Deeper where a sleeve's generators, on arms held forward, would pass in front of the torso.
  for (int grow = 0; grow < 60 && !T.sleeves_cross_torso(); ++grow) T.B *= 1.03;
  // Ellipse arc length table.
  const int M = 20000;
  T.psi.resize(M + 1);
  T.arc.resize(M + 1);
  for (int i = 0; i <= M; ++i) {
    T.psi[i] = -kPi / 2 + 2 * kPi * i / M;
    T.arc[i] = i == 0 ? 0
                      : T.arc[i - 1] + std::hypot(T.A * (std::sin(T.psi[i]) - std::sin(T.psi[i - 1])),
                                                  T.B * (std::cos(T.psi[i]) - std::cos(T.psi[i - 1])));
  }
  const double s0 = T.s_of(0);
  for (double& a : T.arc) a -= s0;  // s = 0 at the front centre
  T.S = T.arc.back() - T.arc.front();
  // Sleeves: frame, side-seam crossings (z = cz) by bisection, wrist.
  double y_hole_top = -1e300, y_hole_bot = 1e300;
  for (int k = 0; k < 2; ++k) {
    Sleeve& q = T.sl[k];
    auto f = [&](double th) { return q.at(T.hit(q, th), th).z() - T.cz; };
    const double sgn = f(kPi / 2) > 0 ? 1.0 : -1.0;  // sign of f on the first half
    if (!(sgn * f(-kPi / 2) < 0 && sgn * f(3 * kPi / 2) < 0))
      gdsr::fail("sim/garment_tshirt", "armhole does not cross the side seam");
    auto root = [&](double lo, double hi) {  // sgn f(lo) < 0 < sgn f(hi) or the reverse
      const bool up = sgn * f(lo) < 0;
      for (int it = 0; it < 60; ++it) {
        const double m = 0.5 * (lo + hi);
        ((sgn * f(m) < 0) == up ? lo : hi) = m;
      }
      return 0.5 * (lo + hi);
    };
    const double tb = root(-kPi / 2, kPi / 2), tt = root(kPi / 2, 3 * kPi / 2);
    for (int j = 0; j <= kHole; ++j) {
      q.theta[j] = tb + (tt - tb) * j / kHole;
      q.theta[kHole + j] = tt + (tb + 2 * kPi - tt) * j / kHole;
    }
    double t_max = 0;
    for (int j = 0; j <= 2 * kHole; ++j) {
      const double t = T.hit(q, q.theta[j]);
      t_max = std::max(t_max, t);
      y_hole_top = std::max(y_hole_top, q.at(t, q.theta[j]).y());
      y_hole_bot = std::min(y_hole_bot, q.at(t, q.theta[j]).y());
    }
    if (q.t_cuff < t_max + 0.15 * s) gdsr::fail("sim/garment_tshirt", "arm too short for a sleeve");
  }
  const double y_top = std::max(lm.shoulder_top_y, y_hole_top + 0.01 * s) + 0.02 * s;
  T.Hsh = y_top - T.hem_y;
  if (y_hole_bot - T.hem_y < 0.1 * s) gdsr::fail("sim/garment_tshirt", "armholes too close to the hem");
  // Neck opening in the shoulder plane: two half ellipses (front, back) around the neck section.
  const double wn = std::min(0.6 * T.A, std::max(lm.neck_hi.x() - T.cx, T.cx - lm.neck_lo.x()) + 0.03 * s);
  // Front and back depth of the opening (the neck or a forward-leaning chin need not be centred on cz).
  const double dmax = 0.92 * T.B * std::sqrt(1 - (wn / T.A) * (wn / T.A));
  const double dn[2] = {std::clamp(lm.neck_hi.z() - T.cz + 0.03 * s, 0.04 * s, dmax),
                        std::clamp(T.cz - lm.neck_lo.z() + 0.03 * s, 0.04 * s, dmax)};
  const double s_n = T.s_of(std::asin(wn / T.A));

  // Torso panels: front (0) and back (1), the same outline shape but different armholes.
  GarmentDesign d;
  Pattern& p = d.pattern;
  const int m_sh = 8, m_neck = 12;
  struct Edges {
    int lower_r, hole_r, upper_r, sh_r, sh_l, upper_l, hole_l, lower_l;
  };
  Edges E[2];
  const double gap = 0.1;
  T.origin[0] = Vec2(T.S / 4 + gap, 0);
  T.origin[1] = Vec2(3 * T.S / 4 + 3 * gap, 0);
  for (int panel = 0; panel < 2; ++panel) {
    const int arm_r = panel == 0 ? 0 : 1, arm_l = 1 - arm_r;  // arm on the flat right / left edge
    auto hole = [&](int arm, int j) {                         // flat point of armhole sample j of an arm on this panel
      const Sleeve& q = T.sl[arm];
      Vec2 f = T.torso_flat(q.at(T.hit(q, q.theta[j]), q.theta[j]), panel);
      if (j % kHole == 0) f.x() = arm == arm_r ? T.S / 4 : -T.S / 4;  // on the side seam
      return f;
    };
    auto top_edge = [&](double x) {  // flat y of the shoulder seam at flat x
      const double ps = T.psi_of(x + panel * T.S / 2);
      return T.Hsh + std::abs(T.B * std::cos(ps));
    };
    std::vector<Vec2> o;
    Edges& e = E[panel];
    o.push_back(Vec2(-T.S / 4, 0));
    o.push_back(Vec2(T.S / 4, 0));  // edge 0: hem
    e.lower_r = static_cast<int>(o.size()) - 1;
    e.hole_r = e.lower_r + 1;
    for (int j = 0; j <= kHole; ++j) o.push_back(hole(arm_r, j));
    e.upper_r = static_cast<int>(o.size()) - 1;
    e.sh_r = e.upper_r + 1;
    for (int j = 0; j <= m_sh; ++j) {
      const double x = T.S / 4 + (s_n - T.S / 4) * j / m_sh;
      o.push_back(Vec2(x, top_edge(x)));
    }
    for (int j = 1; j < m_neck; ++j) {  // neckline: the neck ellipse seen through the fold
      const double x = s_n - 2 * s_n * j / m_neck;
      const double X = T.A * std::sin(T.psi_of(x + panel * T.S / 2));
      const double zn = dn[panel] * std::sqrt(std::max(0.0, 1 - (X / wn) * (X / wn)));
      o.push_back(Vec2(x, top_edge(x) - zn));
    }
    e.sh_l = static_cast<int>(o.size());
    for (int j = 0; j <= m_sh; ++j) {
      const double x = -s_n + (s_n - T.S / 4) * j / m_sh;
      o.push_back(Vec2(x, top_edge(x)));
    }
    e.upper_l = static_cast<int>(o.size()) - 1;
    e.hole_l = e.upper_l + 1;
    for (int j = kHole; j <= 2 * kHole; ++j) o.push_back(hole(arm_l, j));
    e.lower_l = static_cast<int>(o.size()) - 1;
    for (auto& v : o) v += T.origin[panel];
    p.panels.push_back({panel == 0 ? "tshirt_front" : "tshirt_back", o});
  }
  // Sleeves (Sleeve::flat): edge 0 and edge kCuff + 1 are the underarm seam's two sides,
  // edges 1..kCuff the cuff, then the cap from theta[2 kHole] back to theta[0].
  const int cap0 = kCuff + 2;
  double x_off = T.origin[1].x() + T.S / 4 + gap;
  for (int k = 0; k < 2; ++k) {
    const Sleeve& q = T.sl[k];
    std::vector<Vec2> o{q.flat(T.hit(q, q.theta[0]), 0)};
    for (int j = 0; j <= kCuff; ++j) o.push_back(q.flat(q.t_cuff, 2 * kPi * j / kCuff));
    for (int j = 2 * kHole; j >= 1; --j) o.push_back(q.flat(T.hit(q, q.theta[j]), q.theta[j] - q.theta[0]));
    double xmin = 1e300;
    for (const auto& v : o) xmin = std::min(xmin, v.x());
    T.origin[2 + k] = Vec2(x_off - xmin, 0);
    double xmax = -1e300;
    for (auto& v : o) xmax = std::max(xmax, (v += T.origin[2 + k]).x());
    x_off = xmax + gap;
    p.panels.push_back({k == 0 ? "sleeve_right" : "sleeve_left", o});
    p.seams.push_back({2 + k, 0, 2 + k, kCuff + 1, true});  // underarm seam
  }
  // Torso seams: side seams below and above the armholes, shoulder seams, armholes.
  for (int a = 0; a < 2; ++a) {
    const int b = 1 - a;
    p.seams.push_back({a, E[a].lower_r, b, E[b].lower_l, true});
    p.seams.push_back({a, E[a].upper_r, b, E[b].upper_l, true});
    for (int j = 0; j < m_sh; ++j) p.seams.push_back({a, E[a].sh_r + j, b, E[b].sh_l + (m_sh - 1 - j), true});
  }
  for (int panel = 0; panel < 2; ++panel) {
    const int arm_r = panel == 0 ? 0 : 1, arm_l = 1 - arm_r;
    // Cap edge for [theta_j, theta_j+1] is sleeve edge cap0 + (2 kHole - 1 - j).
    for (int j = 0; j < kHole; ++j) {
      p.seams.push_back({panel, E[panel].hole_r + j, 2 + arm_r, cap0 + (2 * kHole - 1 - j), true});
      p.seams.push_back({panel, E[panel].hole_l + j, 2 + arm_l, cap0 + (2 * kHole - 1 - (kHole + j)), true});
    }
  }
  d.place = [sh](int panel, const Vec2& uv) {
    const Shirt& T = *sh;
    const Vec2 q = uv - T.origin[panel];
    if (panel < 2) return T.torso_place(panel, q);
    return T.sl[panel - 2].unflat(q);
  };
  return d;
}

}  // namespace sim
