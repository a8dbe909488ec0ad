// XPBD cloth solver (substeps with a few constraint passes each). Constraints:
// edge lengths from the flat pattern (stretch + shear against the UV rest shape; a shortened
// edge is compression_ratio times softer, as woven fabric buckles below the particle
// distance), isometric
// bending (Bergou et al. 2006, flat rest state; by default solved implicitly, see
// sim/cloth_bending_solve.hpp), body contact with thickness and Coulomb
// friction against the moving body (closest body triangle, refreshed every few substeps and
// searched as far as the cloth travels until the next refresh,
// body velocity from the frame blend; where a second body part is within reach, both, the
// part the vertex was dressed on last, see pinch_separation), pinned bands (a waistband) moving
// rigidly with the body under them (sim/cloth_pins.hpp),
// inner/outer layer contact for multi-layer garments, long-range attachments to the pins
// (sim/cloth_tethers.hpp), cloth self-contact (see sim/cloth_self_collision.hpp), and for an HR
// simulation given its LR one, a pull towards it at the LR scale (sim/cloth_tracking.hpp).
// Without a body, pinned vertices stay fixed in space. Sequential Gauss-Seidel in a fixed
// order: the same inputs give bit-identical output. Units: metres, seconds, kg.
// The body is Y-up (gravity along -y by default).
#pragma once

#include "gdsr/body/body.hpp"
#include "gdsr/geometry/mesh.hpp"
#include "gdsr/geometry/mesh_ops.hpp"
#include "gdsr/io/progress.hpp"
#include "gdsr/sim/cloth_bending_solve.hpp"
#include "gdsr/sim/cloth_collision.hpp"
#include "gdsr/sim/cloth_pins.hpp"
#include "gdsr/sim/cloth_self_collision.hpp"
#include "gdsr/sim/cloth_tethers.hpp"
#include "gdsr/sim/cloth_tracking.hpp"
#include "gdsr/sim/gauss_seidel_schedule.hpp"
#include "gdsr/sim/garments.hpp"

#include <array>
#include <functional>
#include <memory>
#include <vector>

namespace sim {

// Bumped whenever a change alters simulated output (solver, garment patterns or placement), so
// that `gdsr data make --skip-built` and recipes rebuild datasets an older solver made.
// 2: waist curve, pants yoke, self-contact gap and compression scaled with the particle distance.
// 3: body contacts give way rather than overstretch the cloth (contact_release_stretch).
// 4: `data make` starts the HR settle from the settled LR garment (simulate_frames' start).
// 5: skeleton bodies read Poser and cgspeed joint names (CMU salsa "rShldr", the 131 walks'
//    "LeftHip": before, a column with no shoulders, neck or waist) and keep the head upright
//    (the bodies of 01_01 and 01_03 are unchanged, bit for bit).
// 6: skeleton bodies whose rest pose has the arms hanging down (the 131 walks) are built with
//    the arms level, a T-pose (01_01, 01_03 and the salsa bodies are unchanged, bit for bit);
//    body contacts give way (contact_release_stretch) only on cloth that hangs from a pin, so
//    garments with pins (every skirt, pants, the dress) are unchanged, bit for bit.
// 7: the t-shirt is put on an A-pose rest (gdsr::BodyOptions::rest_arm_drop_degrees 45, from
//    the garment catalogue) and its sleeves taper to the wrist: its T-pose sleeves dragged the
//    shoulders down off a salsa dancer once the arms came down. Every other garment is
//    unchanged, bit for bit.
// 8: on meshes finer than 20 mm the self-contact slack is capped at 0.15 of the particle distance
//    and the detection interval lengthened in proportion (SimParams::self_slack_per_pd): the
//    10 mm skirt is 1.4-1.7x faster with the same validity figures. 20 and 30 mm meshes are
//    unchanged, bit for bit.
// 9: with self-contact on, the layer_gap constraint pairs an outer vertex with its nearest inner
//    one only where the layers lie flat on each other (normals within 60 degrees, the outer
//    vertex outside), and never pushes a pair that has crossed: it pushed outer cloth along an
//    inner normal across folds, so the 10 mm layered dress on CMU 01_01 tangled at the hip from
//    frame 50 and blew up. One-layer garments, and any garment with self-contact off, are
//    unchanged, bit for bit.
// 10: the layered dress's pinned top band is fitted to the trunk's section under the armpits
//    (BodyLandmarks::bust_profile): a round band stood 6-15 cm off the chest of CMU 01_01's body
//    and the arms, hanging beside the trunk, went through it. Every other garment is unchanged,
//    bit for bit.
// 11: a hand that went through cloth hanging from a pin passes on (SimParams::limbs_pass_through)
//    instead of wrapping the cloth around itself and carrying it: skirt_short on the CMU 131
//    walks had a hand inside the skirt for most of the clip. Clips where no cloth vertex ever
//    lies deeper than max_push inside a body part it was not dressed on, and garments without
//    pins, are unchanged, bit for bit.
// 12: cloth that went through itself is pulled back actively (SimParams::untangle_step):
//    each edge found crossing a face at a frame's tangle test is moved against it, every
//    substep while it still crosses, down the gradient of the intersection contour's length.
//    Freeing the tangled pairs alone left knots for the rest of the clip. Clips whose frames
//    never have an edge crossing a face are unchanged, bit for bit.
// 13: `data make` simulates HR following its LR simulation at the LR scale (SimParams::track_rate,
//     sim/cloth_tracking.hpp): run independently, the chaotic drape of a dance or a walk kept
//     the two 21-38 mm apart on average, so "HR minus upsampled LR" was mostly a different drape,
//     not wrinkles. LR frames, and everything simulated without a guide, are unchanged, bit for bit.
// 14: the HR pull respects self-contact: the detection counts it in each vertex's motion (a pair
//     pushed across by the pull looked like an intersection that had slipped through, and was
//     freed), and cloth that went through itself, with a few edges around it, is left to
//     untangling. At 30/s skirt_short on salsa 61_02 (2-6 s) had a knot for 14 frames (89.0% of
//     HR frames clean); 100% now. `data make`'s default rate is 30/s, not 10
//     (SimParams::track_rate). LR frames, and anything simulated without a guide, are unchanged,
//     bit for bit.
// 15: a body contact moves cloth that hangs from no pin (the t-shirt, the top) with the body's
//     surface along its normal plus at most max_push_step per contact pass (the part that wins a pinch
//     may also undo the other part's push). Pushed out in one go, a hem vertex that a forearm had
//     overtaken within a contact refresh was thrown through to the forearm's far side: the 30 mm
//     t-shirt on CMU 131_03 (2-3.5 s) had cloth threaded on a forearm in 49 of 61 frames and an
//     edge longer than 2x its pattern in 50; 4 and 0 now (mean E_u 0.0027 -> 0.0017). The cost: a
//     few vertices stay inside a forearm pressed into the shirt across the body, in 36 frames (1
//     before). Garments with pins are unchanged, bit for bit.
// 16: without self-contact too, the layer_gap constraint pairs an outer vertex with its nearest
//     inner one only where their normals are within 60 degrees (revision 9's rule with
//     self-contact on): across folds it pushed the overskirt along an inner normal through the
//     underskirt, and at compression_pd_exponent 1 the 40 mm layered skirt at rest wound its
//     overskirt inside the underskirt (168 of 748 outer vertices after 10 frames). Anything
//     simulated with self-contact on (the default), and one-layer garments, are unchanged, bit
//     for bit.
// 17: cloth a hand went through stays in passing contact with that hand until it is clear of it
//     (SimParams::limbs_pass_until_clear): pushed out only where the hand's surface stands still
//     or moves away, without friction. Let back into full contact as soon as it was less than
//     max_push inside, the cloth on the hand's far side was pushed on ahead of it: on CMU 131_02 a
//     hand that had gone through the first tier of the 30 mm skirt_tiered lifted the skirt to the
//     chest (24.3% of LR frames free of self-intersections, cloth more than 5 mm inside the body
//     outside pinches in 115 frames; 100% and 18 now). Clips where no cloth vertex ever lies
//     deeper than max_push inside a body part it was not dressed on, and garments without pins,
//     are unchanged, bit for bit.
// 18: cloth is 5 mm thick to self-contact at every particle distance finer than 30 mm
//     (SimParams::self_thickness), as at 30 mm: at 10 mm it was 3 mm, so HR folds could close
//     tighter than LR ones, and a fold collapsed over one face row behind a bent knee or in a
//     salsa turn went through itself. HR frames free of self-intersections (CGAL), revision 17
//     -> 18, 4 s clips: pants on walk 131_02 84.6 -> 100%, on salsa 60_02 95.6 -> 100%, on salsa
//     61_03 63.2 -> 100%; skirt_short on salsa 61_03 91.9 -> 100%, on CMU 01_01 98.5 -> 100%;
//     skirt_pleated on salsa 61_03 94.1 -> 100%. The HR solver takes ~20% more CPU time (skirt_short,
//     bench_cloth). Meshes of 30 mm and coarser are unchanged, bit for bit.
// 19: the t-shirt fits the trunk (sim/garment_tshirt.cpp): side seams through the trunk's centre,
//     not in the arms' plane 4-8 cm behind it, and its width measured from the hem up, not from
//     the hips (it was 40-48 cm deep on a 25 cm trunk); and cloth that hangs from no pin, inside
//     two body parts at once, is held rather than pushed onto either (SimParams::
//     hold_unpinned_pinches). The 10 mm t-shirt on salsa 60_02 (2-3.5 s): HR frames free of
//     self-intersections 44.3% -> 100% (42.6% with the fit alone: sleeve and shirt swapped sides in
//     the armpit), median intersecting pairs 824 -> 0, HR mean E_u 0.0035 -> 0.0011, cloth
//     vertices on an edge longer than 2x its pattern 1124 -> 52. Garments with pins are unchanged,
//     bit for bit.
// 20: a self-contact pair found crossed is pushed back by at most one self_thickness per pass
//     (SimParams::self_crossed_push), not all the way: on salsa 61_03 (2-3.5 s) an upper arm swept
//     across the chest pushed the 10 mm t-shirt's layers one way and self-contact pushed them back
//     by up to 36 mm, tearing the shirt at frame 36 (770 edges longer than 2x their pattern) and
//     knotting it. HR frames free of self-intersections 57.4% -> 100%, HR mean E_u 0.0034 ->
//     0.0018, longest HR edge 7.4x -> 3.2x its pattern.
// 21: the self-contact broad phase keeps only pairs whose path boxes overlap, as its header
//     states (Embree also reported some pairs of a BVH leaf whose boxes did not, and those within
//     reach were kept: which ones depended on the BVH), and collides the edges as two scenes, so
//     that its two threads share the work. Datasets byte-identical to revision 20's on
//     skirt_pleated, salsa 61_03 (2-3 s), skirt_short, CMU 01_01 (1-2 s) and the t-shirt on CMU
//     01_03 (1-3 s); HR 1.28-1.38 -> 1.11-1.25, 0.67 -> 0.60 and 2.10 -> 1.77 s per frame.
// 22: a vertex that leaves its slack mid-interval gets a new predicted path, and only the pairs
//     of the vertices, edges and faces it is on are found again (SimParams::self_redetect,
//     SelfCollision::redetect); the other pairs keep their sides and reaches, where before every
//     pair was found again. Datasets byte-identical to revision 21's on pants and skirt_pleated,
//     salsa 61_03 (2-3 s); LR 0.13 -> 0.08 s per frame (pants), HR 0.90 -> 0.80 (skirt_pleated).
// 23: the body contact search reaches as far as the cloth travels until the next refresh
//     (SimParams::contact_travel): fast cloth makes its contacts before it enters the body.
//     skirt_tiered on salsa 61_03 (2-6 s, 30 mm), friction 0.3 / 0.30001 (and 0.29999 / 0.30002
//     before): frames with cloth > 5 mm inside the body outside pinches 56 / 26 / 24 / 29 -> 25 /
//     26, deepest 55.6 / 31.7 / 28.9 / 30.6 -> 27.4 / 31.1 mm; LR frames free of self-intersections
//     100 / 86.0 / 94.9 / 98.5 -> 100 / 86.0% (the clip is chaotic). Byte-identical on 1 s of
//     skirt_short (CMU 01_01), skirt_pleated and pants (salsa 61_03), and the t-shirt's LR (CMU
//     01_03; its HR curvature 20.448 -> 20.447, every other figure the same); CPU time the same.
// 24: pins a hand may press in are the default (SimParams::pin_yield_rate 5/s; garments of one
//     layer), pressed towards their home only. 30 mm LR / 10 mm HR, 2-6 s, rigid -> 5/s: frames with
//     cloth > 5 mm inside the body outside pinches, skirt_pleated on salsa 61_03 (friction 0.3 /
//     0.30001) LR 46 / 47 -> 40 / 31, HR 51 / 49 -> 46 / 39; on salsa 60_03 LR 34 -> 19, HR 51 ->
//     37 (deepest 27.0 -> 25.5 mm); frames free of self-intersections 100% at both resolutions in
//     every run (revision 23's press along the hand's normal: HR 97.8 / 96.3% on 61_03). The
//     deepest frame left on 61_03 (35.8 mm, frame 86) is a forearm sweeping along the band, which
//     no press towards the hip undoes. Pants on salsa 61_03: LR frames free of self-intersections
//     97.8 -> 100%, frames inside the body LR 1 -> 0, HR 4 -> 5 (deepest 44.3 -> 38.3 mm), HR frames
//     with an edge > 2x its pattern 52 -> 48 (the crotch). skirt_short on CMU 01_01 (1-6 s) and 01_03
//     (1-3 s), the demo's clips: byte-identical (no hand reaches the band).
// 25: the pants' notch between the legs ends in a half-circle of radius 3 cm (a crotch seam between
//     the legs, garment_legs.hpp) instead of a point that gathered 673 degrees of pattern angle
//     (450 now at each of the arc's corners). Pants, 30 mm LR / 10 mm HR, 4 s, HR frames with an
//     edge > 2x its pattern: salsa 61_03 48 -> 4 (longest 3.38 -> 2.05x), 60_02 33 -> 0, walk
//     131_02 5 -> 0, CMU 01_01 1 -> 0; LR 0 -> 3 and 0 -> 1 on the salsas (2.17x, 2.02x: the arc's
//     short LR edges). 100% of frames free of self-intersections at both resolutions on all four;
//     frames > 5 mm inside the body outside pinches LR / HR 10 / 0 -> 8 / 0, 24 / 1 -> 16 / 2,
//     0 / 0 -> 0 / 0, 0 / 5 -> 2 / 5; LR E_u 0.0012-0.0020 -> 0.0013-0.0021. A straight 6 cm seam
//     (523 degrees at its ends) left 29 torn HR frames on 61_03 and 97.8% clean. Other garments
//     unchanged (the shorts keep the pointed notch).
// 26: the trunk's axis (measure_body) leaves out the A-pose's hands and forearms, which hang into
//     the slab it is measured on: the t-shirt (the one garment put on an A-pose) is centred on
//     the trunk instead of 16-37 mm off it (3.2 cm off one hip and 9.6 cm off the other on the
//     131_02 walker). T-shirt, 30 mm LR / 10 mm HR, 4 s, frames free of self-intersections LR / HR:
//     CMU 01_01 100 / 100 -> 100 / 100%, walk 131_02 100 / 100 -> 100 / 27.9%, salsa 60_02 100 /
//     100 -> 100 / 69.1%, 61_03 92.6 / 94.1 -> 100 / 100% (the shirt still comes off the dancer's
//     arms there); HR frames with an edge > 2x its pattern 2 / 120 / 107 / 97 -> 1 / 121 / 106 /
//     99; frames > 5 mm inside the body outside pinches (HR) 0 / 119 / 108 / 92 -> 1 / 119 / 105 /
//     103. The HR's knots are a chaotic draw on this garment (60_02 at revision 18: 19.9% with the
//     defaults, 96.3% with the friction nudged by 1e-5). Other garments: byte-identical (their
//     rest pose has the arms level, out of the slab).
// 27: self-contact boxes are taken in a frame moving with the cloth's mean motion, and the
//     detection interval shortens for the cloth's motion less that mean (the cloth moving along
//     with the body no longer cuts it): pairs found are the same, detections fewer on fast
//     motions. T-shirt on salsa 60_02 (2-6 s, 30 / 10 mm, friction 0.3 / 0.30001, same runs
//     side by side): HR CPU s per frame 2.21 / 2.27 -> 2.06 / 2.02; HR frames free of
//     self-intersections 100 / 99.3 -> 100 / 100%; LR frames > 5 mm inside the body outside
//     pinches 7 / 18 -> 7 / 41 (at 0.3 the LR is byte-identical: its interval never shortened;
//     at 0.30001 the chaotic spread). skirt_short on CMU 01_01 (1-6 s, the demo's): byte-identical.
// 28: the t-shirt's sleeves end on the lower forearm, 10 cm (x height / 1.75) short of the wrist
//     (garment_tshirt.cpp, kCuffAboveWrist). Down to the wrist, the sleeve slid onto the hand, and
//     the cuff, caught by the hand's and the forearm's turns, was pulled into the forearm until the
//     arm came out through the sleeve (`data preview --penetration` shows it). T-shirt at 30 mm,
//     4 s from 2 s (from 1 s on 01_01 / 01_03), LR frames with cloth more than 5 mm inside the body
//     outside pinches, friction 0.3 / 0.30001 / 0.29999 / 0.30002 on salsa 61_03: 103 / ~100 /
//     95 / 113 -> 31 / 14 / 19 / 12 (5 cm short: 26 / 88 / 94 / 22; 15 cm: 36 / 22 / 36 / 17);
//     at 0.3, 61_02 66 -> 17, 60_03 68 -> 57 (frames free of self-intersections 41 -> 100%),
//     60_02 7 -> 14, 01_01 4 -> 5, 01_03 4 -> 7, walk 131_02 23 -> 24 (frames with cloth threaded
//     on the body 59 -> 5). At 30 / 10 mm (friction 0.3): 61_03 LR / HR 103 / 99 -> 31 / 20 frames,
//     HR frames with an edge > 2x its pattern 81 -> 2, 100% / 100% free of self-intersections
//     before and after; 60_02 7 / 11 -> 14 / 10, 100% / 100%. What is left on 61_03 is mostly the
//     crook of a sharply bent elbow, where the skinned arm's two sides overlap. Other garments:
//     byte-identical (pants on salsa 60_02, 0.3 s, LR and HR frames).
// 29: a body part that some cloth was dressed on (SimParams::dressed_radius) no longer passes
//     through pinned cloth as a hand does (limbs_pass_through): in the kneel of CMU 131_01 (2-6 s)
//     the thigh, closed onto the calf with the trouser in the crook, went through the cloth there,
//     and the leg left the trouser leg and stayed out of it, 47-61 mm inside the cloth, to the end
//     of the clip. Pants, 30 mm LR / 10 mm HR: frames with cloth > 5 mm inside the body outside
//     pinches LR / HR 102 / 83 -> 18 / 5 (deepest 52.6 / 61.1 -> 21.1 / 32.9 mm, HR only in frames
//     15-19, a forearm in the hip), frames free of self-intersections 72.8 / 100 -> 89.7 / 100% (LR
//     frames 122-135: a fold at the crotch). With the friction nudged to 0.30001 and 0.30002 the leg
//     stayed in before as well (LR byte-identical with and without the rule): one run in three lost
//     it. LR byte-identical on the other 9 clips measured (pants on salsa 61_03, 60_02, walk 131_02
//     and CMU 01_01; skirt_short on 131_01, whose hand still passes, and 61_03; skirt_tiered and
//     skirt_pleated on 131_02; skirt_pleated on 61_03; dress_layered on 131_01), HR too where
//     measured (skirt_short and skirt_pleated on 131_01). Garments without pins: byte-identical.
// 30: the t-shirt's sleeves end 10 cm short of the wrist as found from the arm's sections about
//     their own centres (sim::BodyLandmarks::arm_len). The CMU salsa rest pose bends the elbows,
//     taking the arm up to 4 cm off its principal line; from distances to the line one wrist fell
//     on the hand, 10 cm beyond the other, and that sleeve slid down over the forward hand. T-shirt
//     at 30 / 30 mm, frames with cloth > 5 mm inside the body outside pinches LR / HR, friction 0.3
//     and 0.30001: salsa 61_03 9 / 10 and 15 / 15 -> 2 / 0 and 3 / 0; 60_02 1 / 0 and 2 / 0 -> 1 / 0
//     and 0 / 0; CMU 01_01 (0-5.5 s) 5 / 5 -> 4 / 5; walk 131_01 95 / 92 -> 92 / 92; all 100% free
//     of self-intersections before and after. Other garments: unchanged.
// 31: a self-contact pair is left free where an intersection slipped through only when both its
//     sides have a tangled vertex (SelfCollision, "Untangling"); one side was enough before, and a
//     tier lying on two that had crossed was let through them too. On the kneel of walk 131_01
//     (2-6 s, 30 / 30 mm), frames free of self-intersections LR / HR, friction 0.3 / 0.30001 /
//     0.30002: skirt_tiered 76.5 / 75.7, 62.5 / 75.0, 75.7 / 76.5 -> 83.1 / 84.6, 94.1 / 84.6,
//     77.9 / 86.8 (the knot still begins at frame 47, and lasts 7-30 frames, not 32-37, at most
//     131-308 pairs, not 400-578); skirt_pleated 80.1 -> 89.7% (LR, 0.3). The other 22 clips of the
//     30 mm matrix (6 garments on CMU 01_01 1-5 s, walk 131_01, salsa 60_02 and 61_03 2-6 s) as
//     before: pants on 131_01 89.7 / 100% either way (its knot at frames 122-135 at most 16 pairs,
//     not 120), the rest 100 / 100%. At 30 / 10 mm (0.3): skirt_tiered 76.5 / 71.3 -> 83.1 / 94.9%;
//     skirt_pleated HR 86.0 / 91.2 / 89.7 -> 86.0 / 90.4 / 96.3%. The cost: the tiered skirt's LR
//     outer tier, now kept out of the middle one, is caught in the left hand at the hip instead
//     (frames 95-99, up to 31 mm): frames with cloth > 5 mm inside the body outside pinches LR /
//     HR 21 / 20 -> 29 / 22 at 30 mm, 21 / 18 -> 29 / 23 at 30 / 10 mm.
//     Where the kneel's knot begins (2026-12-07, revision 31, 30 mm): CMU 131_01 is a slide into
//     the kneel. From frame 36 to 50 the body's centre travels 60 mm a frame (1.8 m/s) forwards
//     and 35 cm down, and it stops by frame 50. The tiers overtake the body: at frames 47-48
//     the fastest cloth moves 145-154 mm a frame while the body moves 72-87, and the tiers are
//     thrown forwards over the raised thigh. At frame 48, free vertices of every layer are 7-14
//     mm inside the body where the thigh meets the belly under the front of the waistband, and
//     a pin of the outer tier is 3 mm inside. The first crossing is a pinned edge of the outer
//     tier through the middle tier.
//     More substeps help, so cloth that outruns its thickness within one substep is the likely
//     cause. --substeps 40 (1.6x the time) gives 96.3 / 76.5, 92.6 / 96.3 and 97.1 / 96.3%, with
//     knots of 4-10 frames and at most 16-44 pairs, except the HR at 0.3, frames 47-78. Frames
//     with cloth > 5 mm inside the body outside pinches: 12-14. On the whole 30 mm matrix
//     (friction 0.3): 23 of 24 clips 100 / 100% free of self-intersections (pants and
//     skirt_pleated on 131_01 were 89.7% LR); frames with cloth > 5 mm inside the body outside
//     pinches LR / HR, summed over the 24 clips, 195 / 196 -> 66 / 72 (the t-shirt on 131_01 92 / 92
//     -> 2 / 1, its sleeve no longer in the elbow's crook; worse: dress_layered on 131_01 12 / 12
//     -> 18 / 18, skirt_pleated on 131_01 12 / 11 -> 13 / 16), at 1.7x the CPU time.
//     Substeps set per frame from the cloth's speed at the frame's start, relative to the
//     cloth's mean (up to 4x): with the 99th percentile kept within 4 mm a substep (21.8
//     substeps a frame on average), 96.3 / 93.4, 78.7 / 77.9 and 93.4 / 92.6%. With the fastest
//     vertex kept within 3 mm (37 substeps a frame on average, about --substeps 40's cost),
//     97.1 / 90.4, 90.4 / 96.3 and 97.8 / 100%. The next step: substeps (or a continuous test)
//     where the cloth outruns its thickness, measured on the whole matrix for its cost.
//     Also tried on the kneel, none kept (LR / HR % of frames free of self-intersections at
//     friction 0.3 / 0.30001 / 0.30002; the onset stayed at frame 46-48 in every run):
//     - rolling back, at the end of a substep, the free vertices of every edge-face crossing that
//       was not there at its start (all free vertices after 6 rounds; a knot's own contour may
//       move on): 64.0 / 63.2% at 0.3. The pinned edge cannot be rolled back, the first crossing
//       stays, and the cloth rolled back around it is left behind by the body;
//     - the outer tiers' pins pushed outward by self-contact (up to 15 mm, back at
//       pin_yield_rate): 77.2 / 77.9, 90.4 / 88.2, 77.2 / 80.1; up to 40 mm at twice the weight
//       72.8 / 75.0% at 0.3;
//     - pin_yield_rate for the layered skirt with each pin sharing the press of the innermost
//       tier's pin beside it (the band pressed as one, so no tier's pin passes another's):
//       88.2 / 94.9, 80.1 / 79.4, 86.8 / 86.8 (frames with cloth > 5 mm inside the body outside
//       pinches 15 / 13, 20 / 22, 17 / 16 against 29 / 22, 15 / 15, 21 / 19);
//     - the tiers 20 mm apart at the waist instead of 12: 72.1 / 75.7% at 0.3;
//     - the body given way where it crosses itself (data make --body-yield-gap 0.004: the body
//       crosses itself in 1 frame, not 31): 80.9 / 77.2, 75.0 / 94.9, 79.4 / 78.7%. So the
//       thigh inside the belly is not what starts the knot.
// 32: adaptive substeps (SimParams::substep_travel, 3 mm): a frame takes more substeps, in
//     quarters of `substeps` up to 80, when its fastest vertex, at the velocity it enters the
//     frame with relative to the cloth's mean, would move more than 3 mm in one (the 5 mm self
//     thickness is outrun otherwise: the kneel above). The 30 mm matrix (friction 0.3; 20
//     fixed substeps -> adaptive, and 40 fixed for comparison):
//     - frames free of self-intersections: 22 of 24 clips 100 / 100% (pants and skirt_pleated
//       on 131_01 were 89.7% LR); skirt_tiered on 131_01 83.1 / 84.6 -> 87.5 / 86.0% (40: 96.3 /
//       76.5); dress_layered on 131_01 100 / 100 -> 100 / 96.3% (40: 100 / 100; 100 / 100% with
//       the friction nudged to 0.30001, so within the spread);
//     - the tiered kneel at friction 0.3 / 0.30001 / 0.30002 (the spread): 83.1 / 84.6, 94.1 /
//       84.6, 77.9 / 86.8 -> 87.5 / 86.0, 81.6 / 88.2, 96.3 / 91.9% (40: 96.3 / 76.5, 92.6 /
//       96.3, 97.1 / 96.3); frames with cloth > 5 mm inside the body outside pinches 29 / 22,
//       15 / 15, 21 / 19 -> 14 / 11, 12 / 15, 13 / 12. Its knot still begins at frames 47-49, at
//       the front of the waistband, but lasts 5-24 frames with at most 43-87 pairs (7-30 frames
//       and 131-308 pairs at 20 fixed): smaller, not gone. At 2 mm (about 50 substeps a frame,
//       more than 40 fixed) 93.4 / 88.2, 94.9 / 96.3, 86.8 / 84.6%: no better, so what is left
//       of the knot is not only cloth outrunning its thickness;
//     - frames with cloth > 5 mm inside the body outside pinches, summed over the 24 clips, LR /
//       HR 195 / 196 -> 84 / 75 (40: 66 / 72); t-shirt on 131_01 92 / 92 -> 18 / 17, pants on
//       131_01 17 / 27 -> 5 / 4, skirt_tiered on 131_01 29 / 22 -> 14 / 11;
//     - substeps per frame 22-47 (skirt_short on 01_01 23.4 / 22.2, skirt_tiered on salsa 61_03
//       47.5 / 40.9): CPU time 1.34x (LR) and 1.22x (HR) of 20 substeps on 20 of the clips,
//       against 1.65x and 1.69x at 40.
//     At 30 / 10 mm on 131_01: skirt_pleated 89.7 / 86.0 -> 100 / 100% free of
//     self-intersections (body frames 12 / 16 -> 15 / 17; HR 29.7 substeps a frame, CPU 0.99 ->
//     1.17 s a frame, measured beside a test run); skirt_tiered 83.1 / 94.9 -> 87.5 / 95.6% (body
//     29 / 23 -> 14 / 12; HR 36.4 substeps, 32,962 vertices). The demo's skirt_short on CMU 01_01
//     (1-6 s, 30 / 10 mm): 23.8 / 23.2 substeps a frame, HR 0.42 s a frame (wall, 2 threads).
//     bench/bench_cloth.cpp (40 frames of 01_01 from the settled drape, one thread): 20.4
//     substeps a frame at 30 mm and 20 at 10 mm, the same figures as 20 fixed, CPU 0.063 against
//     0.059 and 0.58 against 0.57 s a frame.
// 33: the implicit bending step by Jacobi iteration (to 1e-12 m) where the mass dominates its
//     matrix, instead of the factorisation's substitutions (sim/cloth_bending_solve.hpp): every
//     LR solve, and HR ones from about 27 substeps a frame at 10 mm. Same equation, solved to
//     rounding either way, so the change is in the last bits, which the chaos of contact then
//     spreads. The t-shirt on walk 131_01 (2-2.5 s, 10 mm, 2 threads): the HR bending step 8.0 ->
//     1.8 ms a solve (13.5 sweeps), 14.2 -> 3.2 s over the clip; HR 0.916 -> 0.741 s a frame.
inline constexpr int kSolverRevision = 33;

struct SimParams {
  int substeps = 20;                // per body frame (the least; see substep_travel)
  double substep_travel = 0.003;    // m; > 0: a frame takes more substeps (in steps of substeps / 4, up to
                                    // max_substeps) when its fastest vertex, at the velocity it enters the frame
                                    // with relative to the cloth's mean, would move farther than this in one
                                    // substep: fast folds outrun self_thickness within a substep and tunnel (the
                                    // kneel of CMU 131_01: revisions 31 and 32 above have the figures, 1.2-1.3x
                                    // the CPU time of 20 fixed substeps); 0: always `substeps`
  int max_substeps = 80;            // per body frame, with substep_travel
  int iterations = 2;               // constraint passes per substep (1 pass at 40 substeps is unstable at 10 mm:
                                    // its residual divided by the small step becomes velocity, m/s on a static pose)
  double thickness = 0.004;         // m, cloth kept this far outside the body
  double friction = 0.3;            // Coulomb coefficient against the body
  double density = 0.08;            // kg/m^2 (silk charmeuse ~0.06-0.09)
  double stretch_stiffness = 2000;  // N/m (2-D Young's modulus per edge-area share)
  double compression_ratio = 0.1;   // stiffness of a shortened edge / stretch_stiffness at compression_pd_ref:
                                    // woven fabric buckles at scales below the particle distance rather than
                                    // resisting in-plane compression (Marvelous Designer's "buckling ratio"); at 1
                                    // a 30 mm mesh flares out stiffly where a 10 mm one hangs in folds (membrane
                                    // locking). 5 s of CMU 01_01 at both resolutions: 0.01 drapes LR closer to HR
                                    // (58 against 78 mm) but the 10 mm skirt crumples through itself in the jumps
                                    // (47% clean frames against 100%)
  double compression_pd_ref = 0.01;  // m. At particle distance pd the ratio is compression_ratio * (ref / pd)^k
                                     // (at most 1), k = compression_pd_exponent: an element cannot buckle inside
                                     // itself, so a coarser mesh takes up its finer folds as in-plane compression
  // compression_pd_exponent, k above: 2 is the Euler load, bending / pd^2 (0.011 at 30 mm; with HR
  // simulated on its own, before revision 13, it brought 1 s of skirt_short's HR-LR agreement from
  // 31.8 to 22.8 mm on CMU 01_01). The 30 mm LR then compresses 3-5x more than the 10 mm HR (mean
  // E_u HR / LR 0.20 on skirt_short, 01_01; 0.28 on pants, salsa 60_02): not one fabric. 1 (0.033 at
  // 30 mm): 0.47 and 0.54, HR frames with an edge torn past 2x 34 -> 20 on the pants, HR curvature
  // over upsampled LR 1.17 -> 1.11x and 1.51 -> 1.38x, agreement 4.1 -> 4.9 and 7.2 -> 9.3 mm; 0 (one
  // ratio everywhere): 0.51 / 0.73, 1.11x / 1.31x, 6.0 / 11.0 mm (bench/sim_sweep.sh).
  // Not the default, as measured on 11 clips of the status matrix (skirt_short, skirt_pleated,
  // pants, dress_layered on CMU 01_01, salsa 60_02 / 61_03 and walk 131_02, 4 s, revision 16): at
  // 1 mean E_u HR / LR rises from 0.16-0.34 to 0.30-0.58, E_u and E_v within 2x on 4 of the 11; HR frames
  // free of self-intersections rise on 5 clips (pants on 131_02 72 -> 100%, skirt_pleated on 61_03
  // 46 -> 68%) and fall on 2 (skirt_pleated on 131_02 100 -> 92%, dress_layered on 01_01 100 ->
  // 90%, its cloth > 5 mm inside the body in 25 frames, 33 mm deep, against 6 and 10 mm); the
  // agreement worsens by 0.4-2.5 mm and HR curvature over the upsampled LR falls by 0.04-0.13.
  // The strain ratio, agreement and curvature move the same way on all 11 clips; the clean-frame
  // counts move both ways, as a nudge of the friction moves them (bench/sim_sweep.sh).
  // Four tests of sim/ fail at 1: a 15 mm sheet draped on a sphere crosses itself in frames 6-16
  // of 45 (one Gauss-Seidel pass of self-contact leaves two pairs crossed after a substep's last
  // pass, and the crossing spreads; detecting every substep or a 3x slack does not help, 2
  // self_passes do), a flap held folded through by a guide stays through, a tracked 10 mm
  // sheet's curvature is 1.09x its LR's (1.1 asked), and the hand test's walk no longer shows a
  // hand carrying the skirt (a fifth, the layered skirt without self-contact, passes since
  // revision 16). 3 iterations clear all four, but HR, better converged, strains less again
  // (HR / LR 0.44 on the pants, 0.32 on the skirt) and runs 5-17% slower.
  double compression_pd_exponent = 2;
  double bend_stiffness = 2e-6;     // N m (isometric bending modulus; silk is very soft)
  double damping = 0.5;             // 1/s, velocity decay (air drag)
  gdsr::Vec3 gravity = gdsr::Vec3(0, -9.81, 0);  // m/s^2
  double layer_gap = 0.004;                      // m, outer layer kept this far outside the inner layer
  double contact_radius = 0.03;                  // m, body search radius beyond thickness
  int contact_every = 5;                         // substeps between contact refreshes (3 for the t-shirt's sleeves in a
                                                 // bending elbow, sim::body_contact_every in garments.hpp)
  double contact_travel = 1;  // the contact search reaches beyond thickness + contact_radius by this many times the
                              // distance the vertex travels (its speed) until the next refresh, for a surface it
                              // approaches fast enough to come within that radius by then: cloth that covered the
                              // radius and max_push together between two refreshes entered the body unseen and,
                              // deeper than max_push, stayed inside (a tier of skirt_tiered, spinning on salsa 61_03,
                              // 55.6 mm inside a thigh for 40 frames; revision 23 has the figures). The body's own
                              // motion is not added: it is left to the radius. 0: the fixed radius (revision 22)
  double max_push = 0.02;                        // m, vertices deeper than this inside the body are not pushed out
  double pin_yield_rate = 5;  // 1/s; 0: rigid pins (the default until revision 23). Above 0: a body part other than
                              // the one a pin was dressed on (pinch_separation apart in the first pose: a hand on the
                              // hip) presses the pin towards its home (its closest body point in the first pose, in
                              // the band's frame) by at most the pin's first-pose distance from the body minus
                              // thickness (so not into the hip), and the pin returns to the band at this rate;
                              // self-contact then moves the pin's free partners no more than C over a quarter
                              // (SelfCollision::project's min_mass_share: pushed by C over its weight, a vertex
                              // under the 10 mm band was thrown 1.7 m in one pass). Towards the home only: pressed
                              // along the part's normal (revision 23), the band slid over the pleats hanging from it
                              // and crossed them. Layered garments keep rigid pins: an outer layer's pin pressed in
                              // went through the pinned inner ones (skirt_tiered on salsa 61_03: a vertex thrown
                              // 0.4 m, 78% of LR frames free of self-intersections), the innermost layer's alone
                              // changed nothing beyond the chaotic spread. Measured in kSolverRevision 24.
  double contact_release_stretch = 1.5;  // a body contact whose push would leave an edge of the vertex longer than this
                                         // times its rest length (and longer than before) lets the cloth slip instead:
                                         // a hand sweeping past a pinned waistband (CMU salsa 61_02) otherwise dragged
                                         // one vertex 23 cm out of the skirt, its edges 20x their length. Only cloth that
                                         // hangs from a pin slips (it cannot follow a limb past its band); a garment
                                         // without pins is carried by the body: releasing let a rising arm pass through
                                         // the 10 mm t-shirt's sleeve on 61_02, and the shirt fell to the feet
  bool limbs_pass_through = true;  // cloth that hangs from a pin and lies deeper than max_push inside a body part it
                                   // was not dressed on (pinch_separation from its first-pose closest point: a hand
                                   // went through it, see contact_release_stretch) makes no contact with that part,
                                   // nor do its edge neighbours, until it is out. Otherwise the ring around it, pushed
                                   // onto the hand and held there by friction, wrapped the hand and was carried with
                                   // it: on CMU 131_01 (2-6 s) a walking hand dragged the 30 mm skirt_short from
                                   // frame 44 to the end, 28 mm deep. A part the cloth was dressed on keeps its
                                   // contacts: the garment hangs on it (a leg in a trouser leg), so letting that part
                                   // through would drop the cloth off the body (on the walks and salsa clips measured,
                                   // every vertex lost this deep was in a hand, but for the thigh in a kneel's crook:
                                   // dressed_radius keeps parts the garment covers from passing)
  bool limbs_pass_until_clear = true;  // ... and its contacts with that part, and those of the edge neighbours it
                                       // reaches, stay passing (pushed out only where the part's surface stands
                                       // still or moves away, no friction) until none of them is within reach of
                                       // the part. Fully in contact again once less than max_push inside, the
                                       // cloth on the hand's far side was pushed on ahead of it: a hand that had
                                       // gone through the first tier of skirt_tiered on CMU 131_02 lifted it to the
                                       // chest (revision 17 has the figures). On the 16 clips of the 30 mm status
                                       // matrix this changes (five garments on CMU 01_01, 131_02, salsa 60_02 and
                                       // 61_03), LR: frames with cloth threaded on the body 109 -> 35 in all (fewer
                                       // on 9 clips, more on 1), cloth more than 5 mm inside the body outside pinches
                                       // 523 -> 401 frames (fewer on 8, more on 4: skirt_pleated on 131_02 6 -> 15,
                                       // skirt_short on 61_03 2 -> 8), frames free of self-intersections: skirt_tiered
                                       // on 131_02 24.3 -> 100%, on 61_03 77.2 -> 98.5%, dress_layered on 60_02 100
                                       // -> 99.3%, the rest 100% as before. Dropping those contacts until clear
                                       // instead, on 15 of the clips: 73 -> 36 threaded, 439 -> 368 inside (passing:
                                       // 29 and 319). With the friction nudged to 0.30001 and 0.30002 (LR, frames
                                       // inside): skirt_tiered on 131_02 was lifted in 2 of 3 runs (115, 23, 118), now
                                       // in none (18, 17, 15); skirt_pleated on 131_02 is systematically worse (6, 4, 6
                                       // -> 15, 13, 13: a hanging hand stays in the skirt's side where it used to be
                                       // pushed out), skirt_short on 61_03 within the spread (2, 3, 2 -> 8, 3, 1)
  double dressed_radius = 0.05;  // m: body points this close to where some cloth was dressed (a vertex's closest body
                                 // point in the first pose) are under the garment, and limbs_pass_through lets only
                                 // parts outside it through the cloth: a hand, not the thigh that a kneel closes onto
                                 // the calf with the trouser in the crook (foreign to the crook's cloth, dressed on the
                                 // calf 19 cm lower). Let through, the leg left the 30 mm trouser leg on CMU 131_01
                                 // (2-6 s) and stayed out of it to the end of the clip (revision 29 has the figures).
                                 // 0: every part foreign to a vertex passes, as before revision 29
  double max_push_step = 0.005;    // m per contact pass (one per iteration): how much farther than the body's surface
                                   // moved along its normal (this substep) a body contact moves cloth that hangs from
                                   // no pin (6 m/s at 2 iterations, 20 substeps and 30 fps). Unlimited, a vertex a
                                   // forearm had overtaken was pushed out through the forearm's far side, and the
                                   // cloth stayed threaded on it (revision 15)
  double pinch_separation = 0.15;  // m: body points this far apart in the first pose are different parts (a hand
                                   // and a hip); cloth pinched between two parts stays on the part it was dressed on.
                                   // Not in the solver (skirt_tiered on salsa 61_03, 2-5 s, where a forearm sweeps
                                   // along the back of its three-layer waistband at frame 96 and the 10 mm tiers
                                   // cross there; frames free of self-intersections LR / HR, revision 18: 98.1 /
                                   // 90.6%, and 60.4 / 85.8% with the friction nudged by 1e-5): letting the other
                                   // part through outer layers where the parts leave less room than the layers
                                   // under them need (90.6 / 90.6%, 12,245 HR pairs at worst against 3,321), or
                                   // refreshing body and self contacts every substep (85.8 / 95.3%)
  bool hold_unpinned_pinches = true;  // cloth that hangs from no pin (the t-shirt) and lies inside two body parts at
                                      // once (an upper arm pressed into the chest: the capsule body crosses itself)
                                      // is not pushed by either: pushed onto the surface of the part it was dressed
                                      // on, which lies inside the other, the sleeve's underside and the shirt's side
                                      // swapped sides in the armpit. Held, self-contact keeps the layers in order
                                      // (revision 19 has the figures). Cloth with pins is unchanged.
                                      // The cost, on salsa 61_03 (2-6 s): a bent elbow (upper arm and forearm are
                                      // parts 16 cm apart) holds the sleeve in its crease and the arm moves on
                                      // through it; the sleeve ends off the arm, 25-37 mm inside it, from frame ~55.
                                      // Tried at revision 20, none kept (30 mm, frames with cloth > 5 mm inside the
                                      // body outside pinches / frames threaded / mean E_u; the default 98 / 32 /
                                      // 0.0042, and 91 / 35 / 0.0039 with the friction nudged by 1e-5): held only
                                      // where truly inside the other part 80 / 13 / 0.0038 and 79 / 22 / 0.0044, but
                                      // at 10 mm (2-3.5 s) LR / HR frames free of self-intersections 100 / 100% ->
                                      // 73.8 / 57.4%; held only 2 mm inside it 96 / 22 / 0.0044; contacts at any depth
                                      // within reach for cloth without pins (not only within max_push) 85 / 24 /
                                      // 0.0049; held cloth carried by the two parts' mean motion 95 / 48 / 0.0044;
                                      // pushed out of the overlap along the sum of the two normals, max_push_step a
                                      // pass, 98 / 34 / 0.0056 and 98 / 7 / 0.0035 (LR 94.9% free of
                                      // self-intersections); not held where both parts lie within pinch_separation
                                      // of the vertex's first-pose home (a joint's crease) 91 / 26 / 0.0034 (the
                                      // 30 mm run that follows it 26.5% free of self-intersections);
                                      // limbs_pass_through for cloth without pins 49 / 18 / 0.0014, but the shirt
                                      // then passes through the trunk and falls off the body.
                                      // Tried at revision 26 on the walker's sleeve, none kept (30 mm at both
                                      // resolutions, CMU 131_02 from 2 s for 4 s, friction 0.3 / 0.30001 /
                                      // 0.30002: LR frames with cloth > 5 mm inside the body outside pinches,
                                      // 118 / 119 / 119 by default): held cloth carried by the part it was
                                      // dressed on 110 / 119 / 114 (salsa 60_02: 20.6-100% of frames free of
                                      // self-intersections, edges > 2x their pattern in 6-10 frames), carried
                                      // along its surface only 118 / 17 / 119 (60_02 mean E_u 0.0018 ->
                                      // 0.0022); contacts deeper than max_push kept with the part it was
                                      // dressed on 119 / 119 / 119 (and held cloth carried along its surface
                                      // 118 / 119 / 119), with any part 119 / 119 / 119; only the
                                      // foreign part pushing held cloth 118 / 119 / 118; cloth deeper than
                                      // max_push pushed out towards the surface of that part it last touched
                                      // 117 / 119 / 118 (at once: 118 / 119 / 118, 23.5% of frames free of
                                      // self-intersections in one twin); the same with the side taken only
                                      // while the cloth was outside 118 / 119 / 119 (at once 117 / 119 / 119,
                                      // 19.1 / 99.3 / 22.8% free of self-intersections). The body is the
                                      // cause: its forearm goes 39-46 mm into the hip at the clip's first
                                      // frames (14-16) and 20 mm at frame 28 (none after frame 36), deeper
                                      // than held cloth has room for, and swallows three vertices of the
                                      // sleeve's underside there; pushed towards the side they came from, one
                                      // pass at a time, they stay 12-31 mm inside it to the end of the clip:
                                      // each pass pushes one 5 mm out and the constraints solved before the
                                      // next pass put it back (21 mm under the forearm's surface). Without
                                      // self-contact (data make --no-self-collision) that vertex stays out of
                                      // the forearm, but the shirt's side is swallowed instead: 118 frames.
                                      // So the body is fixed instead (data make --arm-clearance, default 10 mm,
                                      // gdsr::BodyOptions::arm_clearance): the arm is turned out at the shoulder
                                      // by up to 7.5 degrees there, and the LR frames > 5 mm inside fall to 23
  double max_speed = 15;                         // m/s, velocity clamp (safety against fast body parts)
  int settle_frames = 30;      // frames simulated on the first body pose before frame 0 (velocities zeroed at the end)
  double settle_rest_blend = 0.5;  // fraction of settle_frames over which rest lengths go from the placement to the pattern
  double settle_damping = 6;   // 1/s, velocity decay while settling: the placed garment falls and swings out within
                               // ~1 s instead of starting the clip in its placement shape
  bool self_collision = true;  // cloth-cloth contact (vertex-triangle and edge-edge)
  double self_thickness = 0.03 * (1.0 / 6);  // m, non-adjacent cloth kept at least this far apart: the 30 mm
                                             // mesh's thickness (below), 5 mm, at every resolution, as one
                                             // fabric (3 mm until revision 18, see there); written as that
                                             // product so that 30 mm meshes keep it to the last bit
  double self_thickness_per_pd = 1.0 / 6;  // ... and at least this fraction of the particle distance: a 30 mm mesh
                                           // folded through itself at 3 mm where the 10 mm one did not (CMU 01_01,
                                           // 1 s: t-shirt 4% of frames clean at 3 mm, 33% at 4 mm, 100% at 5 mm;
                                           // pants 63% at 3 mm, 100% at 5 mm)
  int self_detect_every = 4;      // substeps between self-contact detections (sooner when a vertex leaves its slack)
  bool self_redetect = true;      // a vertex that left its slack: only its pairs are found again (SelfCollision::
                                  // redetect); false: all pairs, as before revision 22. On 1 s of salsa 61_03 the
                                  // datasets of revision 21 byte for byte, LR 0.13 -> 0.08 s a frame (pants), HR
                                  // 0.90 -> 0.80 (pleated skirt); over 4 s the pants and t-shirt drift apart (the
                                  // t-shirt's clip is chaotic: a 1e-5 friction nudge moves it as much)
  double self_slack = 0.003;      // m, how far a vertex may leave its predicted path before re-detection
  double self_slack_per_pd = 0.15;  // ... and at most this fraction of the particle distance, self_detect_every then
                                    // growing as the slack shrinks (8 substeps at 10 mm). Every pair within slack
                                    // of a vertex's path is a contact to solve, and a 3 mm slack on a 10 mm mesh
                                    // made contact detection and projection over half of an HR step; halved, the
                                    // 10 mm skirt ran 1.4-1.7x faster with equal validity figures (CMU 01_01 1-3 s,
                                    // salsa 60_02 2-4 s, skirt_tiered on 01_01 3-4 s). A 30 mm mesh keeps 3 mm: at
                                    // 1.5 mm the 30 mm skirt_tiered folded through itself (35% clean frames)
  double untangle_step = 0.1;       // per substep, the most an edge crossing a face (an intersection that slipped
                                    // through) is moved to shrink the intersection contour, in self_thickness
                                    // (SelfCollision::untangle; 0: off). 0.3 tried on 2026-12-06, not kept: on
                                    // the 30 mm matrix (LR / 2nd run) skirt_pleated 131_01 80.1 / 100 -> 90.4 /
                                    // 96.3%, skirt_tiered 61_03 100 / 86.0 -> 100 / 90.4%, dress_layered 60_02
                                    // 100 / 97.8 -> 100 / 98.5%, skirt_tiered 131_01 76.5 / 75.7 ->
                                    // 75.7 / 76.5%, 20 clips unchanged;
                                    // at 10 mm skirt_pleated 131_01, friction 0.3 / 0.30001 / 0.30002, HR
                                    // 86.0 / 91.2 / 89.7 -> 88.2 / 88.2 / 87.5%: its knots do not wait on the step
  double self_crossed_push = 1;     // per self-contact pass, the most a pair found crossed (on the other side from the
                                 // one it was detected on, within its reach) is pushed back, in self_thickness (>= 1;
                                 // infinity: all the way). Pushed all the way back, by up to 36 mm at 10 mm, while
                                 // body contacts pushed the layers the other way (a salsa dancer's upper arm swept
                                 // across the chest, CMU 61_03 frame 36), the crossings grew from 136 to 8,961 pairs
                                 // within one frame and tore the 10 mm t-shirt (770 edges longer than 2x their
                                 // pattern, up to 7.4x). What stays crossed is left to untangling (untangle_step)
  bool self_tangle_retest = false;  // after a substep whose last self-contact pass pushed a pair back from the other
                                    // side of its remembered one, the next detection runs the tangle test again, in
                                    // full (no redetect); otherwise once a frame. In the armpit of the 30 mm t-shirt on
                                    // salsa 61_03 (friction 0.30002), pressed between arm and torso, body contacts
                                    // pushed the layers through each other, detections took the sides from the crossed
                                    // positions, and self-contact held them crossed until the next frame's test: the
                                    // tangle spread (LR frames free of self-intersections 70.6% -> 100% with it). Off:
                                    // on the 24-clip 30 mm matrix (6 garments, CMU 01_01, salsa 60_02 and 61_03, walk
                                    // 131_01, 4 s) it helped skirt_pleated on 131_01 (LR 80.1 -> 100%) and skirt_tiered
                                    // on 61_03 (2nd run 86.0 -> 94.1%) but not skirt_tiered on 131_01 (76.5 -> 62.5%),
                                    // and at 10 mm it cost the t-shirt on 61_03 (HR 100 -> 86.8%) and two nudged runs
                                    // of skirt_pleated on 131_01 (86.8 / 84.6 -> 80.2 / 52.7%; the default run 86.0 ->
                                    // 91.2%). Same CPU time within 5% (bench_cloth's retest rows). At revision 31,
                                    // same matrix (0.3), LR / HR: skirt_tiered on 131_01 83.1 / 84.6 -> 90.4 / 94.1%
                                    // (0.30001: 94.1 / 84.6 -> 85.3 / 89.0; 0.30002: 77.9 / 86.8 -> 100 / 100),
                                    // skirt_pleated on 131_01 89.7 -> 100%, pants on 131_01 89.7 -> 91.9%, but the
                                    // t-shirt on 131_01 100 -> 77.9% (a knot at frames 41-70); the other 20 clips 100 /
                                    // 100% either way, and the 10 mm t-shirt on 61_03 too. Still off.
                                    // Tried on 2026-12-06, not kept: a pair found again at a detection kept the side
                                    // it remembered instead of taking it from the positions (which may hold a
                                    // crossing the last pass had not undone yet). 30 mm matrix, LR / 2nd run: it
                                    // freed skirt_pleated on 131_01 (80.1 / 100 -> 100 / 100%) and pants on 131_01
                                    // (89.7 -> 100%) but knotted the t-shirt's elbow crook (60_02: 100 -> 19.9%,
                                    // 61_03: 100 / 100 -> 60.3 / 92.6%) and left 1-2 crossed frames on 4 clean
                                    // clips; at 10 mm skirt_pleated on 131_01, friction 0.3 / 0.30001 / 0.30002:
                                    // 86.0 / 91.2 / 89.7 -> 89.7 / 87.5 / 35.3% of HR frames clean
  bool self_refuse_crossing_push =
      false;            // a self-contact push back to a pair's remembered side that would make the
                        // pair's faces intersect where they do not is refused, and the pair takes
                        // the side it is on, where a body contact moved one of the pair's vertices
                        // in this iteration (SelfCollision::set_refuse_crossing_pushes and
                        // set_body_moved): in the armpit above, self-contact pushed the layers back
                        // through each other after the body had pushed them apart ("body: 8 -> 0
                        // crossings, self: 0 -> 8"). It frees that case (70.6 / 94.1 -> 100 / 100%,
                        // with no tangle retest). Refusing such pushes of every pair, the first
                        // version, cost the 10 mm t-shirt on 61_03 (HR 100 -> 69.9% of frames
                        // clean: the forearm held across the trunk pushes the sleeve through the
                        // shirt farther than a 10 mm face, the faces around the pair no longer
                        // intersect, and the push back was refused); with the body's cue 100%.
                        // The first version on the 30 mm matrix (LR / 2nd run, as above):
                        // dress_layered 60_02 100 / 97.8 -> 100 / 100%, skirt_tiered 61_03 100 / 86.0
                        // -> 100 / 100%, skirt_tiered 131_01 76.5 / 75.7 -> 61.8 / 75.0%, the other
                        // 21 clips as clean as before, LR seconds per frame +2.7% on average (+6% at
                        // most); 10 mm skirt_pleated 131_01 at friction 0.3 / 0.30001 / 0.30002: HR
                        // 86.0 / 91.2 / 89.7 -> 89.7 / 100 / 89.0% (with the body's cue, 0.30002:
                        // 89.7%). With the cue, on the same matrix (2026-12-06): dress_layered
                        // 60_02 HR 97.8 -> 100%, skirt_tiered 61_03 100 / 86.0 -> 95.6 / 100%,
                        // skirt_tiered 131_01 76.5 / 75.7 -> 45.6 / 76.5%, the other 21 clips as
                        // before, LR time ~+2%: a loss as large as the gains, so it stays off
  int self_passes = 1;  // self-contact Gauss-Seidel passes per iteration (stops early when none is violated). More
                        // passes clear a sphere drape at compression_pd_exponent 1, but not garments: on the 11
                        // matrix clips above at 1, 2 passes against 1 left fewer frames free of self-intersections
                        // on 7 clips (skirt_pleated on 131_02: LR 100 -> 49%, HR 92 -> 32%; dress_layered on 01_01:
                        // HR 90 -> 55%, its HR strain 3.6x its LR's; pants on salsa 60_02: HR 100 -> 90%) and more
                        // on 3 (pants on 61_03: HR 94 -> 100%), mostly within the chaotic spread (with the
                        // friction nudged by 1e-5, skirt_pleated on 131_02's LR is 96% clean at 2 passes, and
                        // freezing the pairs' sides in the extra pass gives 77% and 93%); 3 passes: pants on 61_03
                        // HR 49%, LR 69%. At k = 2 the 30 mm pants on 61_03 are 100% clean at 1, 2 and 3 passes
  bool implicit_bending = true;   // bending by one linear solve per substep (sim/cloth_bending_solve.hpp)
  // Its solve by Jacobi iteration where the mass dominates the matrix this much
  // (ImplicitBending::dominance_ratio), else by the factorisation; 0: always the factorisation
  // (revision 32's arithmetic: the scenario tests' control runs, hand-picked draws of a chaotic
  // scene, are kept on it).
  double bending_jacobi_max_ratio = ImplicitBending::kJacobiMaxRatio;
  int stretch_passes = 4;         // stretch (+ tether) passes per iteration: cheap (~1% of a substep each)
  bool tethers = true;            // long-range attachments to the pins (sim/cloth_tethers.hpp)
  double tether_stretch = 0.002;  // stretch a tether allows beyond the rest distance along the cloth (0.2%)
  double track_rate = 30;         // 1/s: with a guide (`data make` gives HR its LR simulation), how fast a
                                  // difference in drape at the LR scale decays (sim/cloth_tracking.hpp); 0:
                                  // independent. skirt_short on salsa 61_02 (2-4 s), rates 0 / 2 / 5 / 10 / 20:
                                  // HR-LR agreement 30.8 / 23.1 / 16.9 / 11.2 / 7.0 mm, HR curvature 1.52 / 1.48 /
                                  // 1.41 / 1.36 / 1.31x the upsampled LR's, the same seconds per frame. Rates 10 /
                                  // 30 / 100 split it into drape 10.8 / 4.8 / 1.8 mm and wrinkles 1.8 / 1.7 / 1.6 mm:
                                  // 30 keeps the folds and most of the drape of LR (10, revision 13's default,
                                  // until 2026-11-28, left a drape a model cannot predict; 100 crumples HR)
};

// An LR simulation for an HR one to follow (SimParams::track_rate): the tracker holds the
// LR-HR correspondence, frames[t] the LR positions (LR welded vertices x 3, metres) at body
// frame t. The settle follows frames[0].
struct Guide {
  const GuideTracker& tracker;
  const std::vector<gdsr::Points3>& frames;
};

// Stateful solver for one garment on one body topology.
class ClothSolver {
 public:
  // body_F / body_V0: body triangles and the pose the garment's rest placement was made on.
  ClothSolver(const Garment& g, const gdsr::Faces& body_F, const gdsr::Points3& body_V0, const SimParams& p);
  // Advances one frame of length dt seconds while the body moves from body_from to body_to.
  void step(const gdsr::Points3& body_from, const gdsr::Points3& body_to, double dt);
  // Sets every velocity to zero (the end of the settle).
  void zero_velocities() { v_.setZero(); }
  // Moves every vertex to X (welded vertices x 3, metres) at rest; pinned vertices are placed
  // again by the next step. Self-contacts are detected afresh.
  void set_positions(const gdsr::Points3& X);
  // Velocity decay in 1/s from the next step on (the settle damps harder than the clip).
  void set_damping(double per_second) { p_.damping = per_second; }
  // Rest lengths of edges and tethers from the placement (a = 0) to the pattern (a = 1, the
  // default). A placement that is not isometric to its pattern (a pants crotch blended into the
  // hip, a t-shirt's shoulder fold: edges 0.1x to 3x their pattern length) would otherwise snap
  // back at the speed limit in the first substeps; the settle eases it in instead.
  void set_rest_blend(double a);
  // The guide's positions at the start and the end of the next step (LR welded vertices x 3,
  // metres; both must outlive the step); nullptr: no tracking. See SimParams::track_rate.
  void set_guide(const GuideTracker* tracker, const gdsr::Points3* from, const gdsr::Points3* to);
  const gdsr::Points3& positions() const { return x_; }
  const gdsr::Points3& velocities() const { return v_; }       // m/s
  const std::vector<double>& masses() const { return mass_; }  // kg per vertex (pinned too)
  int num_edges() const { return static_cast<int>(edges_.size()); }
  int num_bends() const { return static_cast<int>(bends_.size()); }
  int num_tethers() const { return static_cast<int>(tethers_.size()); }
  int num_layer_pairs() const { return static_cast<int>(layer_pairs_.size()); }  // at the last contact refresh
  int num_body_contacts() const { return static_cast<int>(contacts_.size()); }   // at the last contact refresh
  // Self-contact pairs and tangled vertices at the last detection (0 without self-collision).
  int num_self_pairs() const { return self_ ? self_->num_vertex_triangle() + self_->num_edge_edge() : 0; }
  int num_tangled_vertices() const { return self_ ? self_->num_tangled_vertices() : 0; }
  long long num_self_detections() const { return self_ ? self_->num_detections() : 0; }
  // Substeps the next step of dt seconds takes (SimParams::substep_travel), and taken so far.
  int substeps_for(double dt) const;
  long long num_substeps() const { return num_substeps_; }
  long long num_self_redetections() const { return self_ ? self_->num_redetections() : 0; }  // SimParams::self_redetect
  // The parameters in effect: self_thickness, self_slack and self_detect_every after the
  // particle-distance rules (SimParams::self_thickness_per_pd, self_slack_per_pd).
  const SimParams& params() const { return p_; }

 private:
  struct Edge {
    int i, j;
    double rest, compliance;
  };
  struct Bend {
    int v[4];
    double K[4];
    double compliance;
  };
  struct Contact {
    int v, face;
    gdsr::Vec3 bary;
    bool passing = false;  // with a part that went through this cloth: no push where the part advances, no friction
  };
  struct LayerPair {
    int outer, inner;
    gdsr::Vec3 normal;
  };

  // h: the substep, seconds (the search reaches as far as the cloth travels until the next refresh).
  void refresh_contacts(const gdsr::Points3& body_now, double h);
  // Whether a corner of body face `body_face` is under the garment (SimParams::dressed_radius).
  bool under_garment(int body_face) const;
  // Whether contact c is with the body part around `part` (within pinch_separation of it in the first pose).
  bool in_part(const Contact& c, const gdsr::Vec3& part) const;
  // The contacts of vertex u with the body part around `part` (body points within
  // pinch_separation of it in the first pose): removed with `drop`, else marked passing; true
  // when there were some.
  bool part_contacts(int u, const gdsr::Vec3& part, bool drop, std::vector<std::array<Contact, 2>>& found,
                     std::vector<signed char>& count) const;
  // limbs_pass_through: the cloth lost inside a part (`pierced`, per vertex) and its edge
  // neighbours drop their contacts with that part; with limbs_pass_until_clear, the cloth lost in
  // a part before (lost_in_) and still within reach of it, and its edge neighbours, hold theirs as
  // passing. Updates lost_in_.
  void pass_limbs_through(const std::vector<Contact>& pierced, std::vector<std::array<Contact, 2>>& found,
                          std::vector<signed char>& count);
  // Pins on their bands on pose `body`, plus the offset a foreign part pressed them by (decayed
  // over h seconds at pin_yield_rate).
  void place_pins(const gdsr::Points3& body, double h);
  // The steps of one substep of length h (seconds), in the order step() runs them.
  void detect_self_contacts(double h);
  bool redetect_self_contacts(double h);
  Eigen::RowVector3d predicted_motion(int v, int substeps, double h) const;  // m, of vertex v over the next substeps
  void predict(double h, double decay);
  void prepare_stretch_pass(double h2);           // fills pass_edges_ for a substep of h = sqrt(h2) s
  void solve_edges(std::vector<double>& lambda);  // one stretch pass; lambda by slot of edge_schedule_
  void solve_bends(std::vector<double>& lambda, double h2);
  void solve_layers();
  void solve_body_contacts(const gdsr::Points3& body_prev, const gdsr::Points3& body_now);
  bool overstretched_at(int v, const gdsr::Vec3& x) const;  // see SimParams::contact_release_stretch
  void solve_self_contacts();
  void update_velocities(double h);
  void track_self_slack();
  void track_guide(double a0, double dt, double h);  // a0: the substep's start as a fraction of the frame

  SimParams p_;
  gdsr::Faces F_, bodyF_;
  std::vector<int> layer_;
  gdsr::Points3 x_, v_, xprev_;
  std::vector<double> mass_, winv_;
  std::vector<Edge> edges_;
  gdsr::Csr vertex_edges_;  // indices into edges_ of the edges at each vertex
  GaussSeidelSchedule edge_schedule_;                         // solve_edges' pass over edges_ on two threads
  std::vector<double> edge_rest_placed_, edge_rest_pattern_;  // m, per edge
  std::vector<double> tether_rest_placed_, tether_rest_pattern_;  // m, per tether (placed: not below the pattern)
  // What a stretch pass reads of each edge, by its slot in edge_schedule_, this substep: its
  // vertices, rest length (m) and compliance over h^2 (times 1 stretched, 1/compression_ratio
  // compressed).
  struct PassEdge {
    int i, j;
    double rest, at;
  };
  std::vector<PassEdge> pass_edges_;
  std::vector<Bend> bends_;
  PinBinding pins_;
  std::vector<int> pin_of_;   // per cloth vertex: its pin in pins_ (-1: none); only with pin_yield_rate > 0
  gdsr::Points3 pin_offset_;  // per pin: m it is pressed off its band (SimParams::pin_yield_rate), in the
                              // band's first-pose frame (a band turns a quarter turn in 0.2 s of a salsa spin);
                              // always along pin_inward_ (kept as a vector: revision 24 was measured so)
  std::vector<Eigen::Matrix3d> band_rotation_;  // per band of pins_, this substep
  std::vector<double> pin_room_;  // per pin: m it may be pressed (stand-off from its home minus thickness)
  gdsr::Points3 pin_inward_;      // per pin: unit direction to its home, in the band's first-pose frame
  std::vector<Tether> tethers_;
  std::unique_ptr<ImplicitBending> implicit_bending_;
  std::vector<Contact> contacts_;
  gdsr::Points3 body_rest_;                // body vertices in the first pose (pinch_separation is measured there)
  std::vector<char> under_garment_;        // per body vertex: within dressed_radius of a home_ (first pose)
  std::vector<char> anchored_;             // per cloth vertex: connected to a pinned vertex through the mesh
  gdsr::Points3 home_;                     // per cloth vertex: closest body point in the first pose (NaN: none)
  gdsr::Points3 lost_in_;                  // per cloth vertex: a first-pose point of the part a limb passing through
                                           // it belongs to (NaN: none; see limbs_pass_until_clear)
  int remembered_ = 0;                     // rows of lost_in_ that are set
  std::vector<LayerPair> layer_pairs_;
  SurfaceGrid grid_;
  double body_cell_ = 0.05;
  std::unique_ptr<SelfCollision> self_;
  // Each vertex's predicted path over the detection interval, x_detect_ + a motion_ (a in [0, 1]):
  // from the last detection, or for a vertex that left its slack, from its redetection.
  gdsr::Points3 x_detect_;
  gdsr::Points3 pull_step_;     // the guide's last pull of x_ (track_guide), metres per substep
  gdsr::Points3 motion_;        // m
  std::vector<int> left_slack_;   // vertices that left their slack in the last substep (redetected next)
  std::vector<char> redetected_;  // per vertex: its path was redetected since the last detection
  long long num_substeps_ = 0;    // taken by step() so far
  int since_detect_ = 1 << 30;  // substeps since the last detection
  int detect_interval_ = 1;     // substeps the last detection covers (self_detect_every or fewer for fast cloth)
  std::vector<char> body_moved_;  // per vertex, 1: moved by a body contact this iteration (self-contact reads it)
  bool tangle_test_due_ = true;  // the next detection also runs the tangle test (once per frame and on cue)
  const GuideTracker* tracker_ = nullptr;
  const gdsr::Points3 *guide_from_ = nullptr, *guide_to_ = nullptr;
};

// Simulates the garment on body frames (each frames[t] is a pose of body_F, metres) at
// fps frames per second; returns the garment positions per frame (welded vertices x 3).
// Frame 0 is the rest placement after settle_frames on frames[0]. progress(done, total).
// With `start` (welded vertices x 3, metres), the settle starts from that shape with the
// pattern's rest lengths instead of from the placement: `data make` starts the HR garment from
// the settled LR one upsampled, so that both resolutions begin in the same drape (a hanging
// skirt's folds are a buckling pattern whose places a tiny difference decides). Skirt_short on
// CMU 01_01, 30 against 10 mm: settled separately they differed by 21 mm at frame 0, almost
// all of it folds at different angles around the body (0.3 mm at rest); from the shared start
// by 12 mm, and by 31.6 instead of 34.5 mm over 4 s of the clip.
// With `guide` and p.track_rate > 0, the garment follows the guide's frames (one per body frame).
// substeps_per_frame, if given, receives the mean substeps a step took, settle included
// (SimParams::substep_travel).
std::vector<gdsr::Points3> simulate_frames(const Garment& g, const gdsr::Faces& body_F,
                                           const std::vector<gdsr::Points3>& frames, double fps, const SimParams& p,
                                           const gdsr::ProgressFn& progress = {}, const gdsr::Points3* start = nullptr,
                                           const Guide* guide = nullptr, double* substeps_per_frame = nullptr);

}  // namespace sim

namespace sim {
// Simulates the garment on a body sequence (see simulate_frames).
inline std::vector<gdsr::Points3> simulate(const Garment& g, const gdsr::BodySequence& body, const SimParams& p,
                                           const gdsr::ProgressFn& progress = {}, const gdsr::Points3* start = nullptr,
                                           const Guide* guide = nullptr, double* substeps_per_frame = nullptr) {
  return simulate_frames(g, body.F, body.frames, body.fps, p, progress, start, guide, substeps_per_frame);
}
}  // namespace sim
