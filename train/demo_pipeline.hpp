// Stages 3-4 of `gdsr demo`: data from our simulator, then GDSR training, roll-out and
// evaluation. Prints (it is command-line code).
#pragma once

#include <string>

struct DemoPipelineOptions {
  std::string out = "runs/demo";
  bool quick = false;
  bool skip = false;
};

void run_demo_pipeline(const DemoPipelineOptions& opt);
