// A user's own LR simulation as a Dataset without HR frames, for `gdsr infer --lr-dir`:
//   - lr_dir: one OBJ per frame (welded 3-D mesh, the same faces in every frame), from
//     Marvelous Designer, Blender or anything else; natural order of the last number in the
//     file name, which must step evenly (a gap = missing frames is an error);
//   - lr_uv: the flattened LR pattern (as Marvelous Designer exports it): its "v" lines hold
//     the 2-D layout, its faces correspond one to one, in order, to the 3-D faces;
//   - hr_uv (optional): the HR garment, an OBJ with "v" (welded 3-D mesh, any pose) and "vt"
//     (its pattern, in the same units and placement as the LR pattern), faces "f v/vt";
//     without it the HR garment is the LR one after `subdivide` 1-to-4 midpoint subdivisions
//     (3-D and UV together, so welded seam vertices stay welded);
//   - body_dir (optional): one body OBJ per frame, as many as LR frames.
// Coordinates are multiplied by `scale` to get metres. Every problem throws a one-line error
// naming the file.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/io/progress.hpp"

#include <string>

namespace gdsr {

struct SequenceImportOptions {
  std::string lr_dir, lr_uv, hr_uv, body_dir;  // hr_uv and body_dir may be empty
  int subdivide = 1;                           // without hr_uv: 1 or 2 subdivisions
  double fps = 30;                             // frames per second of the exports
  double scale = 1.0;                          // file units -> metres
  ProgressFn progress;                         // (frames read, total frames)
};

// LR and HR garments, LR (and body) frames, correspondences; hr_frames and raster empty.
Dataset import_lr_sequence(const SequenceImportOptions& opt);

}  // namespace gdsr
