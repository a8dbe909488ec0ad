// Assembles the per-frame model input (FrameInput) from a dataset: LR frames t, t-1, t-2
// (clamped at the start of the sequence), the corrected history, and the body contacts at
// t for C_t and C_{t-1} (Embree). Shared by training (teacher forcing) and roll-out.
#pragma once

#include "gdsr/body/body_query.hpp"
#include "gdsr/data/dataset.hpp"
#include "gdsr/model/features.hpp"
#include "gdsr/model/gdsr_model.hpp"

#include <vector>

namespace gdsr {

// body: a query on the dataset's body (any frame; it is moved to frame t here), or null when
// the dataset has no body (then has_body = false and no query runs).
FrameInput make_frame_input(const Dataset& d, int t, const Points3& chat_tm1, const Points3& chat_tm2, BodyQuery* body);

// The history C^_{t-back} (back = 1 or 2) of frame t in a roll-out that started at frame
// `first`, where pred[i] is the corrected LR frame first + i. Before any prediction exists the
// history is `before` (per frame of d) if given, else the LR simulation itself (d = 0), as at
// the start of `gdsr infer`.
const Points3& rollout_history(const Dataset& d, const std::vector<Points3>& pred, int first, int t, int back,
                               const std::vector<Points3>* before = nullptr);

// The corrected LR frames C^ of frames first .. first + count - 1 rolled out by the model's
// E alone (no HR request, no noise, no gradient): the push-forward history of training.
// body: as for make_frame_input; before: the history before `first`, as for rollout_history.
std::vector<Points3> corrected_rollout(const GDSR<float>& model, const GarmentGraph& graph, const Dataset& d,
                                       BodyQuery* body, int first, int count,
                                       const std::vector<Points3>* before = nullptr);

// A BodyQuery on frame 0 of the dataset's body, or null without a body.
std::unique_ptr<BodyQuery> make_body_query(const Dataset& d);

}  // namespace gdsr
