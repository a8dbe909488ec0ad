// Pinned garment vertices (a waistband, a bodice's top band) carried by the body.
//
// The pinned vertices form bands (connected through the garment's edges); each band moves
// rigidly with the best-fit rigid motion (Kabsch, weighted least squares) of the body
// surface under it: the body vertices within `radius` metres of any of its pins' closest
// body points, measured along the body's edges, weighted by a smooth falloff. A waistband
// then keeps its shape (as a fitted band does) while the body twists, bends and steps under
// it.
//
// Why not each pin on its own piece of skin: the skinned body deforms non-rigidly at the
// waist (its skin there is partly carried by the thigh bones), and a pin 4-5 cm off the
// body (a circular waistband around an elliptical waist) rides on a lever arm. On CMU salsa
// 60_03, pins on their closest triangle's frame stretched pinned waistband edges of the
// 30 mm skirt to 2.0x their length, pins on a rigid fit of the 6 cm of skin around each to
// 1.86x (0.2 m: 1.38x), and the free cloth beside them was pulled into spikes.
//
// Tried and not kept (solver revision 22, skirt_pleated on salsa 61_03, 2-6 s, 30 mm): a pin
// inside a body part other than the one it was dressed on put on that part's surface each
// substep (a hand resting on the hip sinks 34 mm into the band, which stands 49 mm off the
// hip there). Frames with cloth > 5 mm inside the body outside pinches fell 47 -> 24, but 16
// frames had an edge longer than 2x its pattern (none before), 23 had cloth threaded on the
// body (none), 96.3% were free of self-intersections (99.3%), and the picture still showed the
// hand through the yoke below the band. SimParams::pin_yield_rate (opt-in) presses a pin from its
// first contact with the part on, never from inside it.
//
// Units: metres. Deterministic (fixed orders, no threads).
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <vector>

namespace sim {

class PinBinding {
 public:
  PinBinding() = default;
  // pinned: cloth vertex ids (into the garment triangles F); placed: their positions (rows =
  // pinned.size()) on the body pose body_V0 of triangles body_F. radius > 0 metres. Throws
  // gdsr::Error when a pin has no body within 5 m, the body is empty or sizes differ.
  PinBinding(const std::vector<int>& pinned, const gdsr::Points3& placed, const gdsr::Faces& F,
             const gdsr::Faces& body_F, const gdsr::Points3& body_V0, double radius = 0.06);

  int size() const { return static_cast<int>(pins_.size()); }
  int vertex(int k) const { return pins_[k].v; }
  int num_bands() const { return static_cast<int>(bands_.size()); }
  // Writes every pin's position on body pose `body` (same vertex count as body_V0) into its
  // row of x (cloth vertices x 3); on body_V0 itself these are the placed positions to rounding.
  // rotations, if given: each band's rotation on `body` (on body_V0 the identity, to rounding), the
  // frame a pin's offset from its band turns with.
  void place(const gdsr::Points3& body, gdsr::Points3& x, std::vector<Eigen::Matrix3d>* rotations = nullptr) const;
  // Position of pin k alone (tests, diagnostics).
  gdsr::Vec3 position(int k, const gdsr::Points3& body) const;
  // Band of pin k and the body vertices that carry that band.
  int band(int k) const { return pins_[k].band; }
  const std::vector<int>& support(int band) const { return bands_[band].body; }

 private:
  struct Pin {
    int v, band;
    gdsr::Vec3 offset0;  // placed position minus the band's centre0
  };
  struct Band {
    std::vector<int> body;       // body vertex ids under the band
    std::vector<double> weight;  // falloff weights, summing to 1
    gdsr::Vec3 centre0;          // weighted centroid on body_V0
    gdsr::Points3 rel0;          // support on body_V0 minus centre0
  };
  // Rotation R and centre c of band b on pose `body`: a pin goes to c + R offset0.
  void fit(int b, const gdsr::Points3& body, Eigen::Matrix3d& R, gdsr::Vec3& c) const;
  std::vector<Pin> pins_;
  std::vector<Band> bands_;
};

}  // namespace sim
