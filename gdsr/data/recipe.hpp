// Dataset recipes: one JSON file lists the paired LR/HR simulations of a training set
// (garments x motion clips, particle distances) and which clips are held out, so that
// `gdsr data make --recipe FILE --out DIR` builds all of them into DIR/<name>/.
//
//   {
//     "lr_pd": 0.03, "hr_pd": 0.01, "fps": 30, "rest_blend": 15,      (optional, these defaults)
//     "hr_track_rate": 10,  (optional, 1/s: HR follows LR, `data make --track-rate`; absent: the solver's)
//     "partner_subjects": [["60", "61"]],                             (optional)
//     "clips": [
//       {"garment": "skirt_short", "motion": "../../shared/motions/cmu-salsa/60_02.bvh",
//        "start": 2, "seconds": 4, "split": "train", "name": "..."},   (name optional)
//       ...
//     ]
//   }
//
// Motion paths are relative to the recipe file's folder (or absolute). Clips of partner
// subjects (CMU salsa couples: 60_NN and 61_NN were recorded together) must share a split:
// a held-out clip whose partner was trained on is not unseen. Units: metres, seconds.
#pragma once

#include <cmath>
#include <string>
#include <vector>

namespace gdsr {

struct RecipeClip {
  std::string name;     // dataset folder name: given, or <garment>_<motion stem>_<start>s
  std::string garment;  // a garment of the catalogue (checked by the caller, which knows it)
  std::string motion;   // resolved path of the motion file
  double start = 0, seconds = 0;
  bool heldout = false;  // "split": "heldout" (else "train")
};

struct Recipe {
  std::string path;  // the file it was read from
  double lr_pd = 0.03, hr_pd = 0.01, fps = 30;
  int rest_blend = 15;
  double hr_track_rate = NAN;  // 1/s (sim::SimParams::track_rate); NaN: absent, the solver's default
  std::vector<RecipeClip> clips;
};

// Reads and checks a recipe. Throws gdsr::Error with one line naming the file and the key
// (or clip index) for a missing file, malformed JSON, a missing or out-of-range value, an
// unknown garment (not in garments), a duplicate name, or partners on both sides of the split.
Recipe load_recipe(const std::string& path, const std::vector<std::string>& garments);

}  // namespace gdsr
