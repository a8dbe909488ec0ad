// Exports of a roll-out for DCC tools and the browser viewer (docs/exports.md): the GDSR
// prediction, the LR input and the HR simulation of the same frames, each as glTF, PC2 +
// rest OBJ and OBJ per frame (gdsr/io/sequence_export.hpp), plus export.json listing them.
#pragma once

#include "gdsr/data/dataset.hpp"
#include "gdsr/io/sequence_export.hpp"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace gdsr {

struct RolloutExportOptions {
  bool gdsr = true, lr = true, hr = true;  // which sequences (hr: the dataset's HR simulation)
  SequenceExportOptions formats;           // first_frame and fps are set from the roll-out / dataset
};

// G: predicted HR frames for dataset frames first_frame, first_frame + 1, ...
// Writes into dir: gdsr.*, lr.*, hr.* and export.json {"dataset", "fps", "first_frame",
// "frames", "sequences": [export_sequence(...) results]}; returns export.json's content.
// The HR sequences' glTF texcoords match the dataset's UV raster (normal-map images).
nlohmann::json export_rollout(const std::string& dir, const Dataset& d, const std::vector<Points3>& G, int first_frame,
                              const RolloutExportOptions& opt = {});

// glTF texcoords (0..1, origin top-left) of the UV vertices that put each vertex where the
// raster draws it: pixel (col, row) / (width, height).
Points2 raster_texcoords(const UVRaster& raster, const Points2& UV);

}  // namespace gdsr
