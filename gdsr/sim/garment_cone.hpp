// Cone pieces shared by the skirt-like designs (garment_skirts.cpp, garment_dress.cpp,
// garment_tiers.cpp): a cone frustum around the body's vertical axis (waist radius a, hem
// radius b, vertical length L, metres) is developable, so its two panels (front, back,
// each half of the developed annular sector) are placed isometrically.
#pragma once

#include "gdsr/sim/body_landmarks.hpp"
#include "gdsr/sim/garment_design.hpp"
#include "gdsr/sim/pattern.hpp"

#include <memory>
#include <string>
#include <vector>

namespace sim {

struct Cone {
  double a, b, L;                      // metres
  double sin_a, cos_a, R1, Ls, theta;  // developed: inner radius R1, slant Ls, total angle (radians)
  Cone(double a_, double b_, double L_);
};

struct SkirtLayout {
  Cone cone;
  gdsr::Vec2 apex[2];            // flat apex of the front (0) and back (1) panel
  int n_outer = 0, n_inner = 0;  // edges on the hem and on the waist arc of each panel
};

// Scalloped (lace) hem: the hem arc is cut into scallops of arc length `length` that reach
// `depth` metres up into the panel; depth = 0: a plain circular hem.
struct Scallops {
  double depth = 0, length = 0.1;
};

// Appends the two panels of a cone skirt (panel indices base, base + 1) at flat x >= x_offset
// and their two side seams. n_inner > 0 fixes the number of edges on each waist arc (to sew
// the waist to another panel), n_outer > 0 those on each hem arc; 0 picks ~3 cm edges. Panel
// edges: 0 .. n_outer-1 hem (psi increasing),
// n_outer radial (+angle end), n_outer+1 .. n_outer+n_inner waist arc (from the body's +x
// side towards -x for the front), last: radial (-angle end).
SkirtLayout add_cone_skirt(Pattern& p, const Cone& c, double x_offset, const std::string& name, int n_inner = 0,
                           const Scallops& hem = {}, int n_outer = 0);

// 3-D point (metres) of point uv of panel k (0 front, 1 back) of a cone whose waist circle is
// at height waist_y around the vertical axis through `axis`; psi = 0 is the body's front (+z).
// With a `waist` curve (the body's waist section grown to the cone's waist length 2 pi a), the
// waistband lies along that curve by arc length instead of on the circle, blending back to the
// cone within WaistCurve::weight's fade: a round waistband around an oval waist floats 4-5 cm
// off the belly and the back, where a hand resting on the hip then pushes the held cloth into
// the body (CMU salsa 61_02: 25 mm). Along the curve the waistband keeps its pattern length
// (drawing the circle in radially instead gathered it, and a 30 mm mesh took the excess up in
// one flap down the front).
gdsr::Vec3 place_cone(const SkirtLayout& s, int k, const gdsr::Vec2& uv, const gdsr::Vec3& axis, double waist_y,
                      const WaistCurve* waist = nullptr);

// Waist radius a such that the waist section grown by `ease` metres has perimeter 2 pi a, and
// the hem radius needed to clear the hips with `ease` metres (at least a + min_flare).
Cone skirt_cone(const BodyLandmarks& lm, double length, double min_flare, double ease);

// Places, pins and layers a design made only of nested cone skirts: panels 2k, 2k + 1 are
// skirt k (layer k when layered), placed by place_cone and pinned along their waist arcs.
void finish_cone_design(GarmentDesign& d, std::shared_ptr<const std::vector<SkirtLayout>> lays, const BodyLandmarks& lm,
                        bool layered);

// Largest flat x of a pattern's corners (to lay out further panels to the right).
double pattern_max_x(const Pattern& p);

}  // namespace sim
