// Import of Marvelous Designer exports into a gdsr Dataset:
//   - lr_dir / hr_dir: one OBJ per frame of the 30 mm / 10 mm simulation (welded 3-D mesh;
//     the same faces in every frame), ordered by the last number in the file name;
//   - lr_uv / hr_uv: the flattened (UV, unwelded) OBJ of each mesh: its "v" lines hold the
//     2-D pattern (the axis with the smallest extent is dropped) and its faces correspond
//     one to one, in order, to the faces of the 3-D mesh;
//   - body_dir (optional): one body OBJ per frame, same faces in every frame.
// Coordinates are multiplied by `scale` to get metres (MD exports mm: scale 0.001).
// The first frame becomes the canonical mesh. Every mismatch throws a one-line error.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/geometry/obj_io.hpp"
#include "gdsr/io/progress.hpp"

#include <string>
#include <vector>

namespace gdsr {

struct MdImportOptions {
  std::string lr_dir, hr_dir, lr_uv, hr_uv, body_dir;  // body_dir may be empty
  std::string garment = "imported";
  double fps = 30;     // frames per second of the exports
  double scale = 1.0;  // file units -> metres
  double weld = 0;     // > 0: merge 3-D vertices of the first frame closer than this (metres),
                       // for exports written unwelded; 0 = the 3-D OBJs are already welded
  int raster_size = 1024;
  ProgressFn progress;  // (frames read, total frames)
};

Dataset import_md(const MdImportOptions& opt);

// *.obj files of a folder sorted by the last integer in the name (then by name); throws if
// the folder is missing or holds none.
std::vector<std::string> list_frame_objs(const std::string& dir);

// list_frame_objs, and the frame numbers must step evenly (0,1,2,... or 0,5,10,...): a gap
// (missing frames) or a repeated number throws naming the file.
std::vector<std::string> list_frame_sequence(const std::string& dir);

// Reads one OBJ per path; every frame must have the first frame's vertex count and faces
// (errors "<where>: <file>: ..."). Only the first frame keeps F (and FT); VT is dropped.
// progress(++done, total) after each file.
std::vector<ObjData> read_frame_sequence(const std::vector<std::string>& paths, const std::string& where,
                                         const std::string& what, int& done, int total, const ProgressFn& progress);

// Welding map of V: each vertex joins the first earlier kept vertex within eps (hash grid of
// cell eps), otherwise it is kept. Returns old vertex -> new compact index (kept vertices in
// their original order); count = number of kept vertices.
std::vector<int> weld_map(const Points3& V, double eps, int& count);

// A garment from its flattened OBJ (UV layout in "v") and one 3-D frame (welded V, F).
GarmentMesh garment_from_flat(const ObjData& flat, const ObjData& frame, const std::string& what);

}  // namespace gdsr
