// Two datasets of the same garment meshes and clip length compared frame by frame: a solver
// change against the old output, a run against its repeat (determinism), or a run against a
// twin with one parameter nudged (how far the motion's own sensitivity separates two
// simulations of one fabric: the floor under the HR-LR agreement, issue 10).
#pragma once

#include "gdsr/data/dataset.hpp"

#include <vector>

namespace gdsr {

struct FrameDifference {
  std::vector<double> mean;  // per frame: mean over vertices of |a - b|, metres
  double max = 0;            // metres: largest |a - b| of any vertex in any frame
  bool identical = true;     // every coordinate bit-identical
  double clip_mean() const;  // mean of `mean` over the frames (0 for none)
  int worst_frame() const;   // frame of the largest per-frame mean (-1 for none)
};

// Throws (naming `what`) when the sequences differ in frame or vertex count.
FrameDifference frame_difference(const std::vector<Points3>& a, const std::vector<Points3>& b, const std::string& what);

struct DatasetDifference {
  FrameDifference lr, hr;
};

// Throws when the datasets differ in frames or in LR / HR vertex counts.
DatasetDifference compare_datasets(const Dataset& a, const Dataset& b);

}  // namespace gdsr
