# Run by tests/infer/test_export_blender.cpp inside Blender:
#   blender -b --factory-startup --python blender_read_exports.py -- OUT.json FPS FRAMES SPEC...
# SPEC is gltf=PATH, obj=PATTERN (##### replaced by the 5-digit frame number) or
# pc2=REST_OBJ,PC2. Each spec is imported into an empty scene with Blender's own importers
# (glTF add-on, OBJ importer, Mesh Cache modifier); the mesh is evaluated at each of the
# comma-separated FRAMES (k = the k-th exported frame) and OUT.json gets, per spec,
# {"vertices": n, "frames": {"k": [[x, y, z], ...]}} in gdsr's axes (Y up).
import json
import sys

import bpy

argv = sys.argv[sys.argv.index("--") + 1:]
out_path, fps, frames, specs = argv[0], int(argv[1]), [int(f) for f in argv[2].split(",")], argv[3:]


def empty_scene():
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = fps  # glTF keyframe k at k / fps lands on frame k
    scene.render.fps_base = 1.0
    return scene


def import_obj(path):
    bpy.ops.wm.obj_import(filepath=path)  # Y-up data, object rotated to Blender's Z up
    return bpy.context.selected_objects[0]


def positions(o):
    ev = o.evaluated_get(bpy.context.evaluated_depsgraph_get())
    me = ev.to_mesh()
    mw = o.matrix_world
    pts = []
    for v in me.vertices:
        p = mw @ v.co
        pts.append([p.x, p.z, -p.y])  # Blender's Z up back to gdsr's Y up
    ev.to_mesh_clear()
    return pts


results = []
for spec in specs:
    kind, arg = spec.split("=", 1)
    scene = empty_scene()
    res = {"kind": kind, "frames": {}}
    obj = None
    if kind == "gltf":
        # import_shading: the default "NORMALS" path of Debian's Blender 3.4 add-on uses np.bool,
        # gone from numpy 1.24 (Debian 12); "SMOOTH" avoids it.
        bpy.ops.import_scene.gltf(filepath=arg, merge_vertices=False, import_shading="SMOOTH")
        obj = [o for o in scene.objects if o.type == "MESH"][0]
    elif kind == "pc2":
        rest, cache = arg.split(",")
        obj = import_obj(rest)
        mod = obj.modifiers.new("cache", "MESH_CACHE")
        mod.cache_format = "PC2"
        mod.filepath = cache
        mod.frame_start = 0.0
        # Default axes: the OBJ importer keeps the Y-up vertex data and turns the object (its
        # matrix) Z up, so the cache's Y-up positions apply as they are.
    elif kind != "obj":
        raise SystemExit("unknown spec " + spec)
    for k in frames:
        if kind == "obj":
            o = import_obj(arg.replace("#####", "%05d" % k))
            res["frames"][str(k)] = positions(o)
            res["vertices"] = len(o.data.vertices)
            bpy.data.objects.remove(o)
        else:
            scene.frame_set(k)
            res["frames"][str(k)] = positions(obj)
            res["vertices"] = len(obj.data.vertices)
    results.append(res)

with open(out_path, "w") as f:
    json.dump(results, f)
print("blender_read_exports: wrote", out_path)
