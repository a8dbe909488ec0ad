// XPBD cloth solver (small steps: many substeps, one constraint pass each). Constraints:
// edge lengths from the flat pattern (stretch + shear against the UV rest shape), isometric
// bending (Bergou et al. 2006, flat rest state), body contact with thickness and Coulomb
// friction against the moving body (closest body triangle, refreshed every few substeps,
// body velocity from the frame blend), pinned vertices bound to the nearest body triangle,
// and inner/outer layer contact for multi-layer garments. Sequential Gauss-Seidel in a
// fixed order: the same inputs give bit-identical output. Units: metres, seconds, kg.
// The body is Y-up (gravity along -y by default).
#pragma once

#include "gdsr/mesh.hpp"
#include "sim/cloth_collision.hpp"
#include "sim/garments.hpp"

#include <functional>
#include <vector>

namespace sim {

struct SimParams {
  int substeps = 40;             // per body frame (HR at 10 mm needs ~40 to buckle into wrinkles)
  int iterations = 1;            // constraint passes per substep
  double thickness = 0.004;      // m, cloth kept this far outside the body
  double friction = 0.3;         // Coulomb coefficient against the body
  double density = 0.08;         // kg/m^2 (silk charmeuse ~0.06-0.09)
  double stretch_stiffness = 2000;  // N/m (2-D Young's modulus per edge-area share)
  double bend_stiffness = 2e-6;  // N m (isometric bending modulus; silk is very soft)
  double damping = 0.5;          // 1/s, velocity decay (air drag)
  gdsr::Vec3 gravity = gdsr::Vec3(0, -9.81, 0);  // m/s^2
  double layer_gap = 0.004;      // m, outer layer kept this far outside the inner layer
  double contact_radius = 0.03;  // m, body search radius beyond thickness
  int contact_every = 5;         // substeps between contact refreshes
  double max_push = 0.02;        // m, vertices deeper than this inside the body are not pushed out
  double max_speed = 15;         // m/s, velocity clamp (safety against fast body parts)
  int settle_frames = 15;        // frames simulated on the first body pose before frame 0
};

// Stateful solver for one garment on one body topology.
class ClothSolver {
 public:
  // body_F / body_V0: body triangles and the pose the garment's rest placement was made on.
  ClothSolver(const Garment& g, const gdsr::Faces& body_F, const gdsr::Points3& body_V0, const SimParams& p);
  // Advances one frame of length dt seconds while the body moves from body_from to body_to.
  void step(const gdsr::Points3& body_from, const gdsr::Points3& body_to, double dt);
  const gdsr::Points3& positions() const { return x_; }
  const gdsr::Points3& velocities() const { return v_; }  // m/s
  const std::vector<double>& masses() const { return mass_; }  // kg per vertex (pinned too)
  int num_edges() const { return static_cast<int>(edges_.size()); }
  int num_bends() const { return static_cast<int>(bends_.size()); }

 private:
  struct Edge { int i, j; double rest, compliance; };
  struct Bend { int v[4]; double K[4]; double compliance; };
  struct Pin { int v, face; gdsr::Vec3 bary, local; };
  struct Contact { int v, face; gdsr::Vec3 bary; };
  struct LayerPair { int outer, inner; gdsr::Vec3 normal; };

  void refresh_contacts(const gdsr::Points3& body_now);
  void place_pins(const gdsr::Points3& body);
  gdsr::Vec3 pin_position(const Pin& pin, const gdsr::Points3& body) const;

  SimParams p_;
  gdsr::Faces F_, bodyF_;
  std::vector<int> layer_;
  gdsr::Points3 x_, v_, xprev_;
  std::vector<double> mass_, winv_;
  std::vector<Edge> edges_;
  std::vector<Bend> bends_;
  std::vector<Pin> pins_;
  std::vector<Contact> contacts_;
  std::vector<LayerPair> layer_pairs_;
  SurfaceGrid grid_;
  double body_cell_ = 0.05;
};

// Simulates the garment on body frames (each frames[t] is a pose of body_F, metres) at
// fps frames per second; returns the garment positions per frame (welded vertices x 3).
// Frame 0 is the rest placement after settle_frames on frames[0]. progress(done, total).
std::vector<gdsr::Points3> simulate_frames(const Garment& g, const gdsr::Faces& body_F,
                                           const std::vector<gdsr::Points3>& frames, double fps,
                                           const SimParams& p,
                                           const std::function<void(int done, int total)>& progress = {});

}  // namespace sim

#if __has_include("gdsr/body.hpp")
#include "gdsr/body.hpp"
namespace sim {
// Simulates the garment on a body sequence (see simulate_frames).
inline std::vector<gdsr::Points3> simulate(const Garment& g, const gdsr::BodySequence& body, const SimParams& p,
                                           const std::function<void(int done, int total)>& progress = {}) {
  return simulate_frames(g, body.F, body.frames, body.fps, p, progress);
}
}  // namespace sim
#endif
