#include "gdsr/data/frame_input.hpp"

#include "gdsr/error.hpp"

#include "autograd/tensor.hpp"
#include "gdsr/model/frames.hpp"

#include <algorithm>
#include <stdexcept>

namespace gdsr {

FrameInput make_frame_input(const Dataset& d, int t, const Points3& chat_tm1, const Points3& chat_tm2,
                            BodyQuery* body) {
  const int T = static_cast<int>(d.lr_frames.size());
  if (t < 0 || t >= T)
    gdsr::fail("frame_input",
               "frame " + std::to_string(t) + " is outside the sequence of " + std::to_string(T) + " frames");
  FrameInput in;
  in.C_t = d.lr_frames[t];
  in.C_tm1 = d.lr_frames[std::max(t - 1, 0)];
  in.C_tm2 = d.lr_frames[std::max(t - 2, 0)];
  in.Chat_tm1 = chat_tm1;
  in.Chat_tm2 = chat_tm2;
  in.has_body = body != nullptr && d.has_body();
  if (in.has_body) {
    body->update(d.body_frames[t]);
    const ClosestPoints now = body->closest(in.C_t);
    const ClosestPoints before = body->closest(in.C_tm1);
    in.contact_t = {now.point, now.normal};
    in.contact_tm1 = {before.point, before.normal};
  }
  return in;
}

const Points3& rollout_history(const Dataset& d, const std::vector<Points3>& pred, int first, int t, int back,
                               const std::vector<Points3>* before) {
  const int k = t - back - first;  // index of frame t - back among the predictions
  if (k >= 0) {
    if (k >= static_cast<int>(pred.size()))
      gdsr::fail("rollout_history", "frame " + std::to_string(t - back) + " has not been predicted yet");
    return pred[static_cast<size_t>(k)];
  }
  const std::vector<Points3>& history = before ? *before : d.lr_frames;
  if (history.size() != d.lr_frames.size())
    gdsr::fail("rollout_history", "the history before the roll-out has " + std::to_string(history.size()) +
                                      " frames, the dataset " + std::to_string(d.lr_frames.size()));
  return history[static_cast<size_t>(std::max(t - back, 0))];
}

std::vector<Points3> corrected_rollout(const GDSR<float>& model, const GarmentGraph& graph, const Dataset& d,
                                       BodyQuery* body, int first, int count, const std::vector<Points3>* before) {
  ag::NoGradGuard no_grad;
  std::vector<Points3> pred;
  pred.reserve(static_cast<size_t>(std::max(count, 0)));
  for (int t = first; t < first + count; ++t) {
    const FrameInput in = make_frame_input(d, t, rollout_history(d, pred, first, t, 1, before),
                                           rollout_history(d, pred, first, t, 2, before), body);
    pred.push_back(to_points(model.forward(graph, in, nullptr).C_hat));
  }
  return pred;
}

std::unique_ptr<BodyQuery> make_body_query(const Dataset& d) {
  if (!d.has_body()) return nullptr;
  TriMesh m;
  m.V = d.body_frames.front();
  m.F = d.body_faces;
  // Rebuild, not refit: a refitted BVH depends on the frames visited before and so (measured)
  // did the contact features; a frame's input must depend on that frame alone (exact resume,
  // data-parallel ranks). A body of a few thousand triangles rebuilds in about a millisecond.
  return std::make_unique<BodyQuery>(m, BodyQuery::Update::Rebuild);
}

}  // namespace gdsr
