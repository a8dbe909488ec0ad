// Wavefront OBJ reading and writing (v, vt, f; vn and everything else is ignored).
// Faces may be "v", "v/vt", "v/vt/vn" or "v//vn", with negative (relative) indices, and
// polygons are fan-triangulated (0,1,2), (0,2,3), ... Units are whatever the file holds
// (gdsr expects metres). Errors are gdsr::Error naming the file and the line.
#pragma once

#include "gdsr/geometry/mesh.hpp"

#include <string>
#include <vector>

namespace gdsr {

// The raw content of an OBJ after triangulation.
struct ObjData {
  Points3 V;   // positions x 3
  Points2 VT;  // texture coordinates x 2 (empty if the file has none)
  Faces F;     // triangles x 3, into V
  Faces FT;    // triangles x 3, into VT; rows of -1 where a face has no vt
  bool has_uv() const { return VT.rows() > 0 && FT.rows() == F.rows() && (FT.array() >= 0).all(); }
};

// Reads every v/vt/f line. Throws on a malformed number, an index out of range, a NaN or
// infinite coordinate, or a file without vertices or faces.
ObjData read_obj(const std::string& path);
// The same on the file's bytes; `path` names the file in errors.
ObjData parse_obj(const std::string& text, const std::string& path);

// Positions and faces only.
TriMesh read_obj_mesh(const std::string& path);

// V from "v", UV from "vt", F from the v indices and FUV from the vt indices. Every face
// needs vt indices and each vt must always pair with the same v (uv_to_vertex).
GarmentMesh read_obj_garment(const std::string& path);

// Converts parsed OBJ data into a garment (same rules as read_obj_garment); `what` names
// the source in error messages.
GarmentMesh garment_from_obj(const ObjData& obj, const std::string& what);

// Writes via a temporary file in the same folder, then renames. %.9g precision.
void write_obj(const std::string& path, const TriMesh& mesh);
void write_obj(const std::string& path, const GarmentMesh& mesh);  // v, vt, f v/vt
// The mesh as written and read back (coordinates and UVs at %.9g), to measure exactly what a
// reader of the file will see.
GarmentMesh as_written_obj(const GarmentMesh& mesh);

// Writes `bytes` to `path` via path + ".tmp.<pid>" and a rename. Throws on any I/O error.
void write_file_atomic(const std::string& path, const std::string& bytes);

// Removes what killed writers left in `dir`: entries "<name>.tmp.<pid>" (files, or folders
// holding only files) for each name in `names`, whose process <pid> no longer runs. A temp
// of a running process is left alone. Best effort: errors are ignored.
void remove_stale_temps(const std::string& dir, const std::vector<std::string>& names);

}  // namespace gdsr
