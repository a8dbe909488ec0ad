// Landmarks of a standing body's rest pose (Y up, metres): heights of waist, hips, crotch,
// armpits, shoulders, neck and the trunk radii there, the legs' centre lines down to the
// ankles and the arms' centre lines (T- or A-pose), measured from the mesh so that every
// garment pattern fits any human-sized body.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace sim {

struct BodyLandmarks {
  double floor = 0, height = 0;          // lowest y, total height
  gdsr::Vec3 axis = gdsr::Vec3::Zero();  // x, z of the (vertical) trunk axis; y = 0
  double waist_y = 0, hip_y = 0, crotch_y = 0, armpit_y = 0, shoulder_y = 0, neck_y = 0;
  double waist_r = 0, hip_r = 0;  // max horizontal distance of the trunk from the axis
  double chest_r = 0, shoulder_halfwidth = 0, leg_x = 0, thigh_r = 0;
  double bust_r = 0;  // max horizontal distance of the trunk from the axis between waist and armpits
  // The trunk's section at waist_y seen from the axis: its distance from the axis in direction
  // psi = atan2(x - axis.x, z - axis.z) (0 = the body's front), at kWaistBins directions
  // psi_k = 2 pi k / kWaistBins. Never above waist_r.
  static constexpr int kWaistBins = 72;
  std::vector<double> waist_profile;
  // The trunk's section at bust_y (2 cm under the armpits) the same way, its nearest crossing
  // from the axis (arms beside the trunk left out); never above bust_r.
  double bust_y = 0;
  std::vector<double> bust_profile;
  // A t-shirt's hem height (40% of the way from hips to waist), and the bounding box of the trunk
  // between it and the armpits (points within 0.26 m x H / 1.75 of the axis, those of a found arm
  // beyond its shoulder joint left out): the section a shirt must clear, not the hips under it.
  double shirt_hem_y = 0;
  gdsr::Vec3 trunk_lo = gdsr::Vec3::Zero(), trunk_hi = gdsr::Vec3::Zero();
  // Top of the shoulders between neck and shoulder joints, and the bounding box of the neck
  // (and chin) from 0.5 cm to 6 cm above it.
  double shoulder_top_y = 0;
  gdsr::Vec3 neck_lo = gdsr::Vec3::Zero(), neck_hi = gdsr::Vec3::Zero();
  // Legs, index 0: the +x side, 1: the -x side. ankle_y: height where the foot ends and the
  // shin begins; leg_top / leg_bottom: centre of the leg's section just below the crotch and
  // just above the ankle (spread legs tilt the line).
  double ankle_y = 0;
  gdsr::Vec3 leg_top[2] = {gdsr::Vec3::Zero(), gdsr::Vec3::Zero()};
  gdsr::Vec3 leg_bottom[2] = {gdsr::Vec3::Zero(), gdsr::Vec3::Zero()};
  // Arms (index 0: +x side, 1: -x side), found when the arm stands clear of the trunk (T- or
  // A-pose): a centre line from the shoulder joint `arm_root` along the unit `arm_dir`
  // (outwards) to the wrist at arm_root + arm_len * arm_dir; arm_r: the largest distance of
  // the arm's surface from that line between shoulder and wrist (a sleeve about the line clears
  // it, a bent elbow included); wrist_r: that distance at the wrist, the narrowest section (about
  // its own centre) from 60% of the way to the fingertips to the hand's widest. Metres.
  bool arm_found[2] = {false, false};
  gdsr::Vec3 arm_root[2] = {gdsr::Vec3::Zero(), gdsr::Vec3::Zero()};
  gdsr::Vec3 arm_dir[2] = {gdsr::Vec3::UnitX(), -gdsr::Vec3::UnitX()};
  double arm_len[2] = {0, 0}, arm_r[2] = {0, 0}, wrist_r[2] = {0, 0};
};

// Distance of the trunk's waist section from the axis in direction psi (radians, see
// waist_profile), interpolated between the measured directions.
double waist_radius(const BodyLandmarks& lm, double psi);

// How far (metres) a garment placed on a circle of radius waist_r around the axis draws in at
// direction psi to follow the waist section instead, `below` metres under the waist: the full
// waist_r - waist_radius(psi) at the waist, fading out (smoothstep) within 10 cm (less on a short
// waist-to-hip drop), so the hips, which the garments clear with their ease, are untouched.
double waist_fit_shrink(const BodyLandmarks& lm, double psi, double below);

// A trunk section (a profile as waist_profile: radii from the axis at psi_k = 2 pi k / n)
// grown outwards by an ease, walked by arc length: a band laid along it neither stretches nor
// gathers. An empty profile stands for the circle of radius `fallback_r`.
class SectionCurve {
 public:
  SectionCurve() = default;
  SectionCurve(const std::vector<double>& profile, double fallback_r, double ease);
  double radius(double psi) const;  // metres from the axis in direction psi (see waist_profile)
  // Direction psi (radians, in [0, 2 pi)) of the point a fraction f of the perimeter round from
  // the front (psi = 0) towards increasing psi; f wraps.
  double psi_at(double f) const;
  double perimeter() const { return arc_.back(); }  // metres

 private:
  std::vector<double> r_;         // m, radius at psi_k (ease included)
  std::vector<double> arc_{0.0};  // m, arc length from psi_0 to psi_k, k = 0..n (arc_[n]: the perimeter)
};

// The waist section (waist_profile) grown outwards by an ease e until its perimeter is
// 2 pi a, the length of a cone skirt's waistband of radius a: laid along it by arc length, the
// waistband neither stretches nor gathers. Without a measured profile, the circle of radius a.
class WaistCurve : public SectionCurve {
 public:
  // drop: metres under the waist over which the fit fades out (weight); <= 0: the waist-to-hip drop.
  WaistCurve(const BodyLandmarks& lm, double a, double drop = 0);
  double ease() const { return ease_; }  // metres (0 when even the bare section is longer than 2 pi a)
  // How much of the fit applies `below` metres under the waist: 1 - t^2, t = below / drop
  // clamped to [0, 1]. Where the section is wider than the cone (the sides) the skirt
  // stays out at least as far as the straight cone through the widest point; the smoothstep over
  // 10 cm of the radial fit cut 8 mm into a salsa dancer's hips (4 mm with this).
  double weight(double below) const;

 private:
  double ease_ = 0, drop_ = 0;  // m
};

// Perimeter (metres) of the waist section grown outwards by `ease` metres.
double waist_perimeter(const BodyLandmarks& lm, double ease);

// Half extents of the trunk along x (|x - axis.x|) and z (|z - axis.z|) over the body's
// vertices with y0 <= y <= y1 and horizontal distance from the axis below max_r (metres).
// Returns (0, 0) when no vertex qualifies.
gdsr::Vec2 trunk_extent(const gdsr::TriMesh& body_rest, const BodyLandmarks& lm, double y0, double y1, double max_r);

// Throws for an empty or non-finite mesh, a body shorter than 0.3 m, or one without a trunk.
BodyLandmarks measure_body(const gdsr::TriMesh& body_rest);

}  // namespace sim
