// Internal to gdsr/body.cpp: a smooth closed body around a bare skeleton (rest pose),
// skinned to the skeleton's nodes.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <string>
#include <vector>

namespace gdsr::detail {

struct SkelNode {
  std::string name;
  int parent = -1;  // parent node index, -1 for the root; parents come before children
  Vec3 pos;         // rest-pose world position, file units, y up
};

struct SkinnedBody {
  Points3 V;  // rest pose, file units
  Faces F;    // closed, outward
  // Skin: vertex i is influenced by nodes skin_node[skin_start[i] .. skin_start[i+1]).
  std::vector<int> skin_start, skin_node;
  std::vector<double> skin_weight;
  // Landmarks, file units: heights and torso-axis centre (x, z) at that height.
  double waist_y = 0, hip_y = 0, chest_y = 0, shoulder_y = 0;
  Vec3 waist_c, hip_c, chest_c;
  // How much taller the body stands with straight vertical legs than at the rest pose
  // (rest poses with spread legs), file units.
  double leg_extra = 0;
  // Two thighs and two upper arms were recognised by their joint names, so the torso was built
  // through hips and shoulders. false: the landmarks are height fractions and the torso bones
  // are round capsules: a column without shoulders, neck or waist.
  bool torso_found = false;
};

// The nodes that start the upper arms, recognised by name as build_skeleton_body does.
std::vector<int> upper_arm_starts(const std::vector<SkelNode>& nodes);

// Per node, the limb segment it moves with: the first node of its run of upper-arm, forearm,
// thigh or shin nodes (hands follow their forearm, feet and toes their shin), or -1 for the
// trunk, neck, head and clavicles.
std::vector<int> limb_segments(const std::vector<SkelNode>& nodes);

// metres_per_unit: scale of the file units (radii are in metres); edge: target triangle
// circumradius, metres. Throws if the skeleton has no recognisable body (fewer than 2 nodes).
SkinnedBody build_skeleton_body(const std::vector<SkelNode>& nodes, double metres_per_unit, double edge);

}  // namespace gdsr::detail
