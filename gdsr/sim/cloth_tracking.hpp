// An HR simulation that follows its LR one at the LR scale and adds only what the LR mesh
// cannot hold (wrinkles finer than the LR particle distance): a soft form of TRACKS (Bergou,
// Mathur, Wardetzky and Grinspun 2007, "TRACKS: toward directable thin shells"), where a fine
// shell is constrained so that its low-pass filtered shape equals a coarse guide simulation.
//
// Why: the drape of a garment on a walk or a dance is chaotic. Two runs that differ by a
// friction of 0.30001 against 0.3 end 15-37 mm apart, and so do the 30 and 10 mm simulations
// run independently, so much of "HR minus upsampled LR" is a different drape that no model can
// read from the LR input. Tracked, HR differs from LR by what the finer mesh adds.
//
// The filter is the LR mesh itself. U (HR x LR) is the barycentric upsampling of the LR-HR
// correspondence (gdsr/geometry/correspondence.hpp: hr_from_lr); its transpose, normalised by
// each LR vertex's total weight W, averages HR vertices over each LR vertex's hat function:
//   D = W^-1 U^T.  P = U D smooths a field down to what the LR mesh can represent (a low-pass
//   filter, not an exact projection: P P != P). W^-1 U^T U is row-stochastic, so P's
//   eigenvalues lie in [0, 1]. Each substep moves the HR positions x
// and velocities v of free (unpinned) vertices by
//   x += beta * P (U g - x),   v += beta * P (U g' - v),   beta = 1 - exp(-rate * h),
// with g and g' the guide's LR positions and velocity at the start of the substep. A
// wrinkle finer than the LR mesh (hat-weighted mean zero) is not touched; a difference in drape
// decays with the time constant 1 / rate. The move comes before contacts are solved, so body
// and self-contact still have the last word: the self-contact detection counts the pull in each
// vertex's motion (ClothSolver::pull_step_), and cloth that went through itself is not pulled
// (untangled_pull_weights), or the pull pressed a fold the LR mesh does not have back into a knot.
#pragma once

#include "gdsr/geometry/correspondence.hpp"

#include <vector>

namespace sim {

class GuideTracker {
 public:
  // Throws gdsr::Error on a correspondence whose indices do not fit its meshes.
  explicit GuideTracker(const gdsr::Correspondence& c);
  int lr_vertices() const { return corr_.lr_vertices; }
  int hr_vertices() const { return corr_.hr_vertices; }
  // Pulls x and v (HR welded vertices x 3; metres, m/s) towards the guide g and g' (LR welded
  // vertices x 3) as above. Vertices with winv[i] == 0 (pinned) do not move.
  void pull(const gdsr::Points3& guide_x, const gdsr::Points3& guide_v, double beta, const std::vector<double>& winv,
            gdsr::Points3& x, gdsr::Points3& v) const;
  // D (U g - y) for HR values y: the hat-weighted mean of the HR-LR difference per LR vertex.
  gdsr::Points3 lr_residual(const gdsr::Points3& guide, const gdsr::Points3& y) const;

 private:
  gdsr::Correspondence corr_;
  std::vector<double> weight_;  // W: per LR vertex, the sum of its barycentric weights over HR vertices
};

// The weights for GuideTracker::pull that leave cloth which went through itself to untangling
// (SelfCollision::untangle): winv, with 0 at the tangled vertices (1 in `tangled`) and at every
// vertex within `rings` edges of one on the mesh F (faces x 3). Pulled, the layers of a fold
// the LR mesh does not have were pressed back together, and a small knot lasted 14 frames.
std::vector<double> untangled_pull_weights(const std::vector<double>& winv, const std::vector<char>& tangled,
                                           const gdsr::Faces& F, int rings);

}  // namespace sim
