// PC2 point cache (the Maya/3ds Max "POINTCACHE2" format that Blender's Mesh Cache modifier
// reads): a header, then numSamples x numPoints x 3 little-endian float32 positions.
//   char[12] "POINTCACHE2\0", int32 version 1, int32 numPoints, float32 startFrame,
//   float32 sampleRate (frames between samples), int32 numSamples.
// The cache plays on a mesh with the same vertices in the same order (the rest OBJ written
// beside it by gdsr export). Positions are written as given: Y up, metres.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <string>
#include <vector>

namespace gdsr {

// Writes path atomically. frames: T >= 1 frames of equal vertex count, finite. Throws
// gdsr::Error naming path otherwise or on an I/O failure.
void write_pc2(const std::string& path, const std::vector<Points3>& frames, float start_frame = 0,
               float sample_rate = 1);

}  // namespace gdsr
