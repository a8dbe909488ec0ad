// The prediction folder written by `gdsr infer` and read by `gdsr eval` / `gdsr export`:
//   pred_hr.bin       float32 T x N_hr x 3, the predicted HR frames G (metres)
//   pred_lr.bin       float32 T x N_lr x 3, the corrected LR frames C^ (metres)
//   prediction.json   {"first_frame", "frames", "dataset", "model", "seconds_per_frame",
//                      "model_seconds_per_frame"}
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <string>
#include <vector>

namespace gdsr {

struct Prediction {
  int first_frame = 0;                                        // dataset frame of G[0]
  std::vector<Points3> G;                                     // HR frames
  std::vector<Points3> C_hat;                                 // LR frames (may be empty when read with hr_only)
  std::string dataset, model;                                 // where it came from (free text)
  double seconds_per_frame = 0, model_seconds_per_frame = 0;  // wall time of the roll-out
};

// Writes the three files into dir (created if missing), each atomically; prediction.json is
// removed first and written last, so it marks a complete prediction.
void write_prediction(const std::string& dir, const Prediction& p);

// Throws gdsr::Error naming the file on a missing or malformed file, arrays whose frame count
// differs from the recorded one, or NaN / inf predicted positions.
Prediction read_prediction(const std::string& dir, bool hr_only = false);

}  // namespace gdsr
