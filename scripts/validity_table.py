#!/usr/bin/env python3
"""Prints one markdown table of the validity figures stored by `gdsr data make` in each
dataset's manifest.json (docs/dataset-format.md, "Validity figures"), one row per dataset
and resolution, next to the simulator's seconds per frame.

    scripts/validity_table.py DATASET_DIR [DATASET_DIR ...]

Reads only what the manifests hold: run `gdsr data check --data DIR` to recompute them.
A folder without a manifest or without validity figures is reported on stderr and skipped;
the exit status is then 1.
"""
import json
import os
import sys


def row(name, res, v, stats):
    r = v[res]
    si = r["self_intersection"]
    s = r["strain"]
    body = r.get("body")
    pen = f'{1000 * body["max_penetration_m"]:.1f} ({body["frames_over_limit"]})' if body else "-"
    if body and "pinch_frames" in body:
        pen += (f' / {1000 * body["max_penetration_outside_pinches_m"]:.1f} '
                f'({body["frames_over_limit_outside_pinches"]}) / {body["pinch_frames"]}')
    if body and "pinch_frames_in_body_crossings" in body:
        pen += f' ({body["pinch_frames_in_body_crossings"]} where the body crosses itself, in {v["body_crossing_frames"]} frames)'
    cpu = stats.get(f"{res}_cpu_seconds_per_frame")
    wall = stats.get(f"{res}_seconds_per_frame")
    speed = f"{wall:.3f} / {cpu:.3f}" if wall is not None and cpu is not None else "-"
    substeps = stats.get(f"{res}_substeps_per_frame")  # manifests before solver revision 32 have none
    if substeps is not None:
        speed += f" ({substeps:.1f} substeps)"
    agree = v["agreement_m"]
    agreement = f'{1000 * agree["mean"]:.1f} / {1000 * agree["max_frame_mean"]:.1f}' if res == "hr" else ""
    if res == "hr" and "lr_scale_mean" in agree:  # manifests from before the split by scale have none
        agreement += f' (drape {1000 * agree["lr_scale_mean"]:.1f}, wrinkles {1000 * agree["finer_mean"]:.1f})'
    return (f'| {name} | {res.upper()} | {r["faces"]} | {100 * si["clean_fraction"]:.1f}% '
            f'({si["clean_frames"]}/{si["frames_checked"]}) | {si["median_pairs"]:g} / {si["max_pairs"]} '
            f'| {s["E_u"]:.5f} | {s["E_v"]:.5f} | {s["E_uv"]:.5f} | {pen} | {agreement} '
            f'| {r["mean_curvature_1_m"]:.1f} | {speed} |')


def main(dirs):
    print("| dataset | res | faces | clean frames (CGAL) | pairs median / max | E_u | E_v | E_uv "
          "| max penetration mm (frames > 5 mm): all / outside pinches / pinch frames | HR-LR agreement mm mean / worst frame (drape, wrinkles) "
          "| mean curvature 1/m | s/frame wall / CPU (substeps per frame) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    status = 0
    for d in dirs:
        path = os.path.join(d, "manifest.json")
        try:
            with open(path) as f:
                m = json.load(f)
            v = m["validity"]
        except (OSError, ValueError, KeyError) as e:
            print(f"validity_table: {path}: no validity figures ({e})", file=sys.stderr)
            status = 1
            continue
        name = os.path.basename(os.path.normpath(d))
        stats = m.get("stats", {})
        for res in ("lr", "hr"):
            print(row(name, res, v, stats))
        up = v.get("lr_upsampled_mean_curvature_1_m")
        if up is not None:
            print(f"| {name} | LR upsampled | | | | | | | | | {up:.1f} | |")
    return status


if __name__ == "__main__":
    if len(sys.argv) < 2:
        print(__doc__.strip(), file=sys.stderr)
        sys.exit(2)
    sys.exit(main(sys.argv[1:]))
