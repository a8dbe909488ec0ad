// Double-layered strapless dress: each layer is a bodice (front and back panels from under the
// armpits to the waist) sewn at the waist to a flared cone skirt (front and back panels).
// Layer 0 is the fitted inner dress, layer 1 a looser, shorter outer layer 12 mm further out
// that flares more. The top band of both layers is pinned (elastic band) and fitted to the
// trunk's section there (BodyLandmarks::bust_profile) with a little ease; the bodice widens
// from it to the round waist seam of the skirt. A round band (radius bust_r) stood 6-15 cm
// off the chest of CMU 01_01's body, and the arms, hanging beside the trunk, went through it.
#include "gdsr/sim/garment_cone.hpp"
#include "gdsr/sim/garment_design.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

constexpr double kPi = 3.14159265358979323846;

struct DressLayer {
  SkirtLayout skirt{Cone(0.1, 0.2, 0.1), {}, 0, 0};
  double R = 0, Hb = 0;   // bodice radius at the waist, height (metres)
  SectionCurve top;       // the fitted top band
  double Wt = 0;          // width of each bodice panel at the top: half the band's perimeter (metres)
  Vec2 bodice_origin[2];  // flat position of each bodice panel's bottom centre
  // Each bodice panel is a frustum unrolled: an annular sector of angle theta between radii
  // rho1 (the waist, arc length W = pi R) and rho1 - Hb (the band, arc length Wt) around an
  // apex above the panel. rho1 = 0: a rectangle (the band as long as the waist).
  double rho1 = 0, theta = 0;

  // Flat position of the point a fraction frac (-0.5 .. 0.5) across bodice panel k, h (0 .. 1) up it.
  Vec2 bodice_uv(int k, double frac, double h) const {
    if (rho1 == 0) return bodice_origin[k] + Vec2(frac * kPi * R, h * Hb);
    const double rho = rho1 - h * Hb, phi = frac * theta;
    return bodice_origin[k] + Vec2(rho * std::sin(phi), rho1 - rho * std::cos(phi));
  }
  // uv lies on panel k's band: its chords of the arc of radius rho1 - Hb are the only points of
  // the panel that close to the apex (as a cone skirt's pinned waistband).
  bool on_band(int k, const Vec2& uv) const {
    if (rho1 == 0) return uv.y() - bodice_origin[k].y() > Hb - 1e-9;
    return (uv - bodice_origin[k] - Vec2(0, rho1)).norm() < rho1 - Hb + 1e-9;
  }
  // The inverse of bodice_uv.
  void bodice_coords(int k, const Vec2& uv, double& frac, double& h) const {
    const Vec2 q = uv - bodice_origin[k];
    if (rho1 == 0) {
      frac = q.x() / (kPi * R);
      h = q.y() / Hb;
      return;
    }
    const Vec2 a(q.x(), rho1 - q.y());  // from the apex, pointing down the panel
    frac = std::atan2(a.x(), a.y()) / theta;
    h = (rho1 - a.norm()) / Hb;
  }
};

// Panels: inner skirt front/back, outer skirt front/back, inner bodice front/back, outer bodice front/back.
int layer_of(int panel) { return (panel < 4 ? panel : panel - 4) / 2; }

}  // namespace

GarmentDesign design_dress_layered(const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  const double top_y = lm.bust_y;  // the band: 2 cm under the armpits, where bust_profile is measured
  const double drop = std::max(lm.waist_y - lm.hip_y, 0.02);
  GarmentDesign d;
  Pattern& p = d.pattern;
  auto layers = std::make_shared<std::vector<DressLayer>>(2);
  double slope = 0;
  for (int l = 0; l < 2; ++l) {
    DressLayer& L = (*layers)[l];
    L.R = lm.bust_r + (0.015 + 0.012 * l) * s;
    L.Hb = top_y - lm.waist_y;
    L.top = SectionCurve(lm.bust_profile, lm.bust_r, (0.012 + 0.012 * l) * s);
    L.Wt = std::min(L.top.perimeter() / 2, kPi * L.R);
    const double W = kPi * L.R;
    if (W - L.Wt > 1e-6 * W) {
      L.rho1 = W * L.Hb / (W - L.Wt);
      L.theta = W / L.rho1;
    }
    const double length = (l == 0 ? 0.55 : 0.48) * s;
    const double need = (lm.hip_r + 0.02 * s - L.R) / drop;  // clear the hips
    slope = std::max({need, l == 0 ? 0.15 : slope + 0.3, slope + 0.02});
    // Spread legs: the hem clears each leg's line (plus 6 cm for the leg) at the hem height.
    const double hem_y = lm.waist_y - length;
    for (int j = 0; j < 2; ++j) {
      const Vec3 dl = lm.leg_bottom[j] - lm.leg_top[j];
      const Vec3 at = lm.leg_top[j] + dl * ((hem_y - lm.leg_top[j].y()) / (dl.y() < -1e-6 ? dl.y() : -1.0));
      slope = std::max(slope, (std::hypot(at.x() - lm.axis.x(), at.z() - lm.axis.z()) + 0.06 * s - L.R) / length);
    }
    const Cone c(L.R, L.R + slope * length, length);
    const int n = std::max(8, static_cast<int>(std::ceil(kPi * L.R / (0.03 * s))));
    L.skirt = add_cone_skirt(p, c, l == 0 ? 0.0 : pattern_max_x(p) + 0.1, l == 0 ? "inner_skirt" : "outer_skirt", n);
  }
  // Bodices in a row above the skirts; bottom edge split like the skirt's waist arc.
  double y0 = 0;
  for (const auto& pan : p.panels)
    for (const auto& v : pan.outline) y0 = std::max(y0, v.y() + 0.1);
  double x0 = 0;
  for (int l = 0; l < 2; ++l) {
    DressLayer& L = (*layers)[l];
    const double W = kPi * L.R;
    const int n = L.skirt.n_inner;
    for (int k = 0; k < 2; ++k) {
      L.bodice_origin[k] = Vec2(x0 + W / 2, y0);
      x0 += W + 0.05;
      std::vector<Vec2> o;  // the waist arc left to right (edges 0 .. n-1), the band right to left
      for (int i = 0; i <= n; ++i) o.push_back(L.bodice_uv(k, -0.5 + static_cast<double>(i) / n, 0));
      for (int i = 0; i <= n; ++i) o.push_back(L.bodice_uv(k, 0.5 - static_cast<double>(i) / n, 1));
      p.panels.push_back({std::string(l == 0 ? "inner" : "outer") + (k == 0 ? "_bodice_front" : "_bodice_back"), o});
    }
    const int sf = 2 * l, bf = 4 + 2 * l;  // panels: skirts (inner, outer), then bodices
    // Side seams of the bodice (edge n: right side going up, 2n + 1: left side going down).
    p.seams.push_back({bf, n, bf + 1, 2 * n + 1, true});
    p.seams.push_back({bf + 1, n, bf, 2 * n + 1, true});
    // Waist seams: bodice bottom edge i (psi increasing) meets skirt waist edge n-1-i.
    for (int k = 0; k < 2; ++k)
      for (int i = 0; i < n; ++i) p.seams.push_back({bf + k, i, sf + k, L.skirt.n_outer + 1 + (n - 1 - i), true});
  }
  const Vec3 axis = lm.axis;
  const double waist_y = lm.waist_y;
  d.place = [layers, axis, waist_y](int panel, const Vec2& uv) {
    const DressLayer& L = (*layers)[layer_of(panel)];
    const int k = panel % 2;
    if (panel < 4) return place_cone(L.skirt, k, uv, axis, waist_y);
    // The sector's radial line at `frac` runs straight from the waist circle (by angle) to the
    // fitted band (by arc length), as long as in the pattern: the band dips where it is drawn
    // in most.
    double frac, h;
    L.bodice_coords(k, uv, frac, h);
    const double psi_b = frac * kPi + k * kPi, psi_t = L.top.psi_at(0.5 * k + 0.5 * frac);
    const double rt = L.top.radius(psi_t);
    const double dx = rt * std::sin(psi_t) - L.R * std::sin(psi_b), dz = rt * std::cos(psi_t) - L.R * std::cos(psi_b);
    const double rise = std::sqrt(std::max(L.Hb * L.Hb - dx * dx - dz * dz, 0.25 * L.Hb * L.Hb));
    return Vec3(axis.x() + L.R * std::sin(psi_b) + h * dx, waist_y + h * rise,
                axis.z() + L.R * std::cos(psi_b) + h * dz);
  };
  d.pinned = [layers](int panel, const Vec2& uv) {  // the bodices' top band
    const DressLayer& L = (*layers)[layer_of(panel)];
    return panel >= 4 && L.on_band(panel % 2, uv);
  };
  d.layer = layer_of;
  return d;
}

}  // namespace sim
