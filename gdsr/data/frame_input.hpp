// Assembles the per-frame model input (FrameInput) from a dataset: LR frames t, t-1, t-2
// (clamped at the start of the sequence), the corrected history, and the body contacts at
// t for C_t and C_{t-1} (Embree). Shared by training (teacher forcing) and roll-out.
#pragma once

#include "gdsr/body/body_query.hpp"
#include "gdsr/data/dataset.hpp"
#include "gdsr/model/features.hpp"

namespace gdsr {

// body: a query on the dataset's body (any frame; it is moved to frame t here), or null when
// the dataset has no body (then has_body = false and no query runs).
FrameInput make_frame_input(const Dataset& d, int t, const Points3& chat_tm1, const Points3& chat_tm2, BodyQuery* body);

// A BodyQuery on frame 0 of the dataset's body, or null without a body.
std::unique_ptr<BodyQuery> make_body_query(const Dataset& d);

}  // namespace gdsr
