#include "sim/garments.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace sim {

using gdsr::Vec2;
using gdsr::Vec3;

namespace {

[[noreturn]] void fail(const std::string& msg) { throw std::runtime_error("sim/garments: " + msg); }

constexpr double kPi = 3.14159265358979323846;

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

// ---- Cone skirts ---------------------------------------------------------------------
// A skirt is a cone (waist radius a, hem radius b, vertical length L) cut into two panels
// (front, back), each half of the developed annular sector.
struct Cone {
  double a, b, L;  // metres
  double sin_a, cos_a, R1, Ls, theta;  // developed: inner radius R1, slant Ls, total angle
  Cone(double a_, double b_, double L_) : a(a_), b(b_), L(L_) {
    Ls = std::hypot(L, b - a);
    sin_a = (b - a) / Ls;
    cos_a = L / Ls;
    R1 = a / sin_a;
    theta = 2 * kPi * sin_a;
  }
};

struct SkirtLayout {
  Cone cone;
  Vec2 apex[2];
};

// Appends the two panels of a cone skirt (panel indices base, base + 1) and their seams.
SkirtLayout add_cone_skirt(Pattern& p, const Cone& c, double x_offset, const std::string& name) {
  const double R2 = c.R1 + c.Ls;
  const double half = c.theta / 4;  // each panel spans theta / 2
  const int n_outer = std::max(8, static_cast<int>(std::ceil(R2 * 2 * half / 0.03)));
  const int n_inner = std::max(4, static_cast<int>(std::ceil(c.R1 * 2 * half / 0.03)));
  const double width = 2 * R2 * std::sin(std::min(half, kPi / 2)) + 0.05;
  SkirtLayout lay{c, {}};
  const int base = static_cast<int>(p.panels.size());
  for (int k = 0; k < 2; ++k) {
    const Vec2 apex(x_offset + width / 2 + k * (width + 0.05), R2 + 0.01);
    lay.apex[k] = apex;
    const double mid = -kPi / 2;
    auto outl = arc_points(apex, R2, mid - half, mid + half, n_outer);
    const auto in = arc_points(apex, c.R1, mid + half, mid - half, n_inner);
    outl.insert(outl.end(), in.begin(), in.end());
    p.panels.push_back({name + (k == 0 ? "_front" : "_back"), outl});
  }
  // Edge n_outer: radial at the panel's +angle end (outer -> inner); last edge: radial at
  // the -angle end (inner -> outer).
  const int e_plus = n_outer, e_minus = n_outer + n_inner + 1;
  p.seams.push_back({base, e_plus, base + 1, e_minus, true});
  p.seams.push_back({base + 1, e_plus, base, e_minus, true});
  return lay;
}

// 3-D point of a skirt panel point; psi = 0 is the body's front (+z).
Vec3 place_cone(const SkirtLayout& s, int k, const Vec2& uv, const Vec3& axis, double waist_y) {
  const Vec2 d = uv - s.apex[k];
  const double rho = d.norm();
  const double phi = std::atan2(d.y(), d.x()) + kPi / 2;  // 0 at the panel centre
  const double psi = phi / s.cone.sin_a + (k == 0 ? 0.0 : kPi);
  const double apex_y = waist_y + s.cone.R1 * s.cone.cos_a;
  const double r = rho * s.cone.sin_a;
  return Vec3(axis.x() + r * std::sin(psi), apex_y - rho * s.cone.cos_a, axis.z() + r * std::cos(psi));
}

// Waist radius and the hem radius needed to clear the hips with `ease` metres.
Cone skirt_cone(const BodyLandmarks& lm, double length, double min_flare, double ease) {
  const double a = lm.waist_r + ease;
  const double drop = std::max(lm.waist_y - lm.hip_y, 0.02);
  const double need = a + (lm.hip_r + 2 * ease - a) * length / drop;
  return Cone(a, std::max({need, a + min_flare, a + 0.02}), length);
}

// ---- Two-panel tube garments (top, shorts) ---------------------------------------------
// Front panel centred at x = 0 maps its flat x to the angle psi = x / R around the axis;
// the back panel continues the same sense of rotation (psi = pi + x / R), so both face out.

Panel mirror_copy(const Panel& pan, double dx, const std::string& name) {
  Panel q{name, pan.outline};
  for (auto& v : q.outline) v.x() += dx;
  return q;
}

}  // namespace

std::vector<std::string> garment_names() {
  return {"skirt_short", "skirt_long", "top", "shorts", "skirt_layered"};
}

BodyLandmarks measure_body(const gdsr::TriMesh& b) {
  if (b.V.rows() < 4 || !b.V.allFinite()) fail("body rest mesh is empty or not finite");
  BodyLandmarks lm;
  lm.floor = b.V.col(1).minCoeff();
  lm.height = b.V.col(1).maxCoeff() - lm.floor;
  if (!(lm.height > 0.3)) fail("body is shorter than 0.3 m (expected metres, Y up)");
  const double H = lm.height, s = H / 1.75;
  lm.armpit_y = lm.floor + 0.73 * H;
  lm.shoulder_y = lm.floor + 0.81 * H;
  lm.neck_y = lm.floor + 0.85 * H;
  // Trunk axis: mean x, z of the vertices around mid-height of the trunk.
  Vec3 c = Vec3::Zero();
  int n = 0;
  for (int v = 0; v < b.V.rows(); ++v)
    if (std::abs(b.V(v, 1) - (lm.floor + 0.62 * H)) < 0.03 * s) {
      c += b.V.row(v).transpose();
      ++n;
    }
  if (n == 0) fail("body has no trunk at 0.62 of its height");
  lm.axis = c / n;
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
  if (!(lm.waist_r < 1e9)) fail("body has no trunk at waist height");
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
  return lm;
}

Pattern garment_pattern(const std::string& name, const BodyLandmarks& lm) {
  const double s = lm.height / 1.75;
  Pattern p;
  if (name == "skirt_short") {
    add_cone_skirt(p, skirt_cone(lm, 0.42 * s, 0.22 * s, 0.015), 0, "skirt");
  } else if (name == "skirt_long") {
    const double len = lm.waist_y - lm.floor - 0.15 * s;
    add_cone_skirt(p, skirt_cone(lm, len, 0.20 * s, 0.015), 0, "skirt");
  } else if (name == "skirt_layered") {
    add_cone_skirt(p, skirt_cone(lm, 0.55 * s, 0.12 * s, 0.015), 0, "under");
    double xmax = 0;
    for (auto& pan : p.panels)
      for (auto& v : pan.outline) xmax = std::max(xmax, v.x());
    add_cone_skirt(p, skirt_cone(lm, 0.36 * s, 0.30 * s, 0.03), xmax + 0.1, "over");
  } else if (name == "top") {
    const double R = lm.chest_r + 0.035 * s;
    const double W = kPi * R;
    const double hem_y = lm.waist_y - 0.06 * s;
    const double Hs = lm.armpit_y - 0.02 * s - hem_y;             // side seam height
    const double psi_s = std::asin(std::min(0.9, 0.11 * s / R));  // strap centre angle
    const double xs = R * psi_s, sw = 0.035 * s;                   // strap centre, half width (flat)
    const double Hsh = lm.shoulder_y + 0.02 * s - hem_y;          // shoulder line height
    const double Htop = Hsh + R * std::cos(psi_s);                // plus the fold over the shoulder
    const double Hneck = Hsh - 0.10 * s;
    std::vector<Vec2> o{Vec2(-W / 2, 0), Vec2(W / 2, 0), Vec2(W / 2, Hs)};
    // Right armhole (quarter ellipse) up to the strap's outer edge.
    const int na = 8;
    for (int k = 1; k <= na; ++k) {
      const double t = kPi / 2 * k / na;
      o.push_back(Vec2(xs + sw + (W / 2 - xs - sw) * std::cos(t), Hs + (Htop - Hs) * std::sin(t)));
    }
    o.push_back(Vec2(xs - sw, Htop));  // shoulder seam (right)
    const int nn = 10;                 // neckline (half ellipse, down to Hneck)
    for (int k = 1; k < nn; ++k) {
      const double t = kPi * k / nn;
      o.push_back(Vec2((xs - sw) * std::cos(t), Htop - (Htop - Hneck) * std::sin(t)));
    }
    o.push_back(Vec2(-(xs - sw), Htop));
    o.push_back(Vec2(-(xs + sw), Htop));  // shoulder seam (left)
    for (int k = na - 1; k >= 0; --k) {
      const double t = kPi / 2 * k / na;
      o.push_back(Vec2(-(xs + sw) - (W / 2 - xs - sw) * std::cos(t), Hs + (Htop - Hs) * std::sin(t)));
    }
    const int n = static_cast<int>(o.size());  // last edge: (-W/2, Hs) -> (-W/2, 0)
    Panel front{"top_front", o};
    p.panels.push_back(front);
    p.panels.push_back(mirror_copy(front, W + 0.1, "top_back"));
    const int e_side_r = 1, e_side_l = n - 1;
    const int e_sh_r = 2 + na, e_sh_l = 2 + na + nn + 1;
    p.seams.push_back({0, e_side_r, 1, e_side_l, true});
    p.seams.push_back({1, e_side_r, 0, e_side_l, true});
    p.seams.push_back({0, e_sh_r, 1, e_sh_l, true});
    p.seams.push_back({1, e_sh_r, 0, e_sh_l, true});
  } else if (name == "shorts") {
    const double R = lm.hip_r + 0.03 * s;
    const double W = kPi * R;
    const double hem_y = lm.crotch_y - 0.16 * s;
    const double Htot = lm.waist_y - hem_y;
    const double Hc = lm.crotch_y - 0.03 * s - hem_y;
    const double g = 0.02 * s;
    std::vector<Vec2> o{Vec2(-W / 2, 0), Vec2(-g, 0), Vec2(0, Hc), Vec2(g, 0),
                        Vec2(W / 2, 0), Vec2(W / 2, Htot), Vec2(-W / 2, Htot)};
    Panel front{"shorts_front", o};
    p.panels.push_back(front);
    p.panels.push_back(mirror_copy(front, W + 0.1, "shorts_back"));
    p.seams.push_back({0, 4, 1, 6, true});  // side seams
    p.seams.push_back({1, 4, 0, 6, true});
    p.seams.push_back({0, 1, 1, 2, true});  // inseams
    p.seams.push_back({0, 2, 1, 1, true});
  } else {
    fail("unknown garment '" + name + "'");
  }
  return p;
}

Garment make_garment(const std::string& name, double h, const gdsr::TriMesh& body_rest) {
  const BodyLandmarks lm = measure_body(body_rest);
  const double s = lm.height / 1.75;
  const Pattern pat = garment_pattern(name, lm);
  PatternMesh pm = mesh_pattern(pat, h);
  Garment g;
  g.name = name;
  g.particle_distance = h;
  const Vec3 axis = lm.axis;
  std::vector<char> pin_uv(pm.mesh.UV.rows(), 0);

  if (name.rfind("skirt", 0) == 0) {
    // Rebuild the layouts to place points (same numbers as garment_pattern).
    std::vector<SkirtLayout> lays;
    Pattern tmp;
    if (name == "skirt_short") {
      lays.push_back(add_cone_skirt(tmp, skirt_cone(lm, 0.42 * s, 0.22 * s, 0.015), 0, "skirt"));
    } else if (name == "skirt_long") {
      lays.push_back(add_cone_skirt(tmp, skirt_cone(lm, lm.waist_y - lm.floor - 0.15 * s, 0.20 * s, 0.015), 0, "skirt"));
    } else {
      lays.push_back(add_cone_skirt(tmp, skirt_cone(lm, 0.55 * s, 0.12 * s, 0.015), 0, "under"));
      double xmax = 0;
      for (auto& pan : tmp.panels)
        for (auto& v : pan.outline) xmax = std::max(xmax, v.x());
      lays.push_back(add_cone_skirt(tmp, skirt_cone(lm, 0.36 * s, 0.30 * s, 0.03), xmax + 0.1, "over"));
    }
    place_pattern(pm, [&](int panel, const Vec2& uv) {
      return place_cone(lays[panel / 2], panel % 2, uv, axis, lm.waist_y);
    });
    for (int u = 0; u < pm.mesh.UV.rows(); ++u) {
      const auto& L = lays[pm.uv_panel[u] / 2];
      const double rho = (Vec2(pm.mesh.UV.row(u)) - L.apex[pm.uv_panel[u] % 2]).norm();
      pin_uv[u] = rho < L.cone.R1 + 1e-9;
    }
    if (name == "skirt_layered") {
      pm.mesh.layer.assign(pm.mesh.V.rows(), 0);
      for (int u = 0; u < pm.mesh.UV.rows(); ++u)
        if (pm.uv_panel[u] >= 2) pm.mesh.layer[pm.mesh.uv_to_vertex[u]] = 1;
    }
  } else if (name == "top") {
    const double R = lm.chest_r + 0.035 * s;
    const double W = kPi * R;
    const double hem_y = lm.waist_y - 0.06 * s;
    const double psi_s = std::asin(std::min(0.9, 0.11 * s / R));
    const double Hsh = lm.shoulder_y + 0.02 * s - hem_y;
    const double E = R * std::cos(psi_s);
    place_pattern(pm, [&](int panel, const Vec2& uv) {
      const double x = uv.x() - panel * (W + 0.1), y = uv.y();
      const double psi = x / R + panel * kPi;
      double X = R * std::sin(psi), Z = R * std::cos(psi), Y = hem_y + y;
      if (y > Hsh) {  // fold over the shoulder towards the side plane z = 0
        const double f = std::min(1.0, (y - Hsh) / E);
        Z *= 1 - f;
        Y = hem_y + Hsh;
      }
      return Vec3(axis.x() + X, Y, axis.z() + Z);
    });
  } else if (name == "shorts") {
    const double R = lm.hip_r + 0.03 * s;
    const double W = kPi * R;
    const double hem_y = lm.crotch_y - 0.16 * s;
    const double Htot = lm.waist_y - hem_y;
    const double Hc = lm.crotch_y - 0.03 * s - hem_y;
    const double g = 0.02 * s, blend = 0.10 * s;
    place_pattern(pm, [&](int panel, const Vec2& uv) {
      const double x = uv.x() - panel * (W + 0.1), y = uv.y();
      const double psi = x / R + panel * kPi;
      const Vec3 hip(R * std::sin(psi), hem_y + y, R * std::cos(psi));
      if (y >= Hc + blend) return Vec3(axis + hip);
      // Leg tube: side seam (t = 0) outside, inseam (t = 1) inside, front/back at t = 1/2.
      // Between the crotch and crotch + blend the tubes blend into the hip cylinder, so the
      // crotch point sits between the legs.
      const double gy = g * std::max(0.0, 1 - y / Hc);
      const double wleg = W / 2 - gy;
      const double t = std::clamp((W / 2 - std::abs(x)) / wleg, 0.0, 1.0);
      const double r = wleg / kPi;
      const double side = (x >= 0) == (panel == 0) ? 1.0 : -1.0;  // 3-D x side of this leg
      const double zs = panel == 0 ? 1.0 : -1.0;
      const Vec3 leg(side * (R / 2 + r * std::cos(kPi * t)), hem_y + y, zs * r * std::sin(kPi * t));
      const double u = std::clamp((y - Hc) / blend, 0.0, 1.0);
      const double b = u * u * (3 - 2 * u);
      return Vec3(axis + (1 - b) * leg + b * hip);
    });
    for (int u = 0; u < pm.mesh.UV.rows(); ++u) pin_uv[u] = pm.mesh.UV(u, 1) > Htot - 1e-9;
  }
  for (int u = 0; u < pm.mesh.UV.rows(); ++u)
    if (pin_uv[u]) g.pinned.push_back(pm.mesh.uv_to_vertex[u]);
  std::sort(g.pinned.begin(), g.pinned.end());
  g.pinned.erase(std::unique(g.pinned.begin(), g.pinned.end()), g.pinned.end());
  g.mesh = std::move(pm.mesh);
  return g;
}

}  // namespace sim
