#include "infer/rollout.hpp"

#include "gdsr/error.hpp"

#include "autograd/tensor.hpp"
#include "gdsr/data/frame_input.hpp"
#include "gdsr/model/frames.hpp"

#include <chrono>
#include <stdexcept>

namespace gdsr {

RolloutResult rollout(const GDSR<float>& model, const Dataset& d, const RolloutOptions& opt,
                      const ProgressFn& progress) {
  const int T = static_cast<int>(d.lr_frames.size());
  if (opt.first_frame < 0 || opt.first_frame >= T)
    gdsr::fail("--first",
               std::to_string(opt.first_frame) + " is outside the input's frames 0.." + std::to_string(T - 1));
  if (opt.frames == 0 || opt.frames < -1)
    gdsr::fail("--frames", std::to_string(opt.frames) + ": must be at least 1 (or -1: to the end)");
  if (opt.frames > T - opt.first_frame)
    gdsr::fail("--frames", std::to_string(opt.frames) + " from frame " + std::to_string(opt.first_frame) +
                               " runs past the input's " + std::to_string(T) + " frames");
  const int count = opt.frames < 0 ? T - opt.first_frame : opt.frames;
  std::vector<Points3> truth;  // the downsampled HR frames, for opt.true_history
  if (opt.true_history) {
    if (d.hr_frames.size() != d.lr_frames.size())
      gdsr::fail("--true-history", "needs the input's HR simulation (a dataset's hr_frames); this input has " +
                                       std::to_string(d.hr_frames.size()) + " HR frames for " + std::to_string(T) +
                                       " LR frames");
    for (const Points3& hr : d.hr_frames) truth.push_back(downsample(d.corr, hr));
  }
  const std::vector<Points3> none;
  ag::NoGradGuard no_grad;
  const GarmentGraph graph = build_graph(d.lr);
  const HrRequest all = hr_request_all(d.corr);
  std::unique_ptr<BodyQuery> body = make_body_query(d);

  RolloutResult r;
  r.first_frame = opt.first_frame;
  double model_secs = 0;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < count; ++k) {
    const int t = opt.first_frame + k;
    // True history: no prediction before t, so both frames come from the downsampled truth.
    const std::vector<Points3>& pred = opt.true_history ? none : r.C_hat;
    const int first = opt.true_history ? t : opt.first_frame;
    const std::vector<Points3>* before = opt.true_history ? &truth : nullptr;
    const FrameInput in = make_frame_input(d, t, rollout_history(d, pred, first, t, 1, before),
                                           rollout_history(d, pred, first, t, 2, before), body.get());
    const auto m0 = std::chrono::steady_clock::now();
    const GdsrOutput<float> out = model.forward(graph, in, &all);
    model_secs += std::chrono::duration<double>(std::chrono::steady_clock::now() - m0).count();
    Points3 C_hat = to_points(out.C_hat);
    Points3 G = to_points(out.G);
    r.mean_correction += to_points(out.D).rowwise().norm().mean() / count;
    r.mean_detail += to_points(out.residual).rowwise().norm().mean() / count;

    CollisionStats stats;
    if (opt.collisions) {
      BodyQueryFn query;
      if (body) {
        query = [&body](const Points3& q, Points3& closest, Points3& normal) {
          const ClosestPoints cp = body->closest(q);  // body is at frame t already
          closest = cp.point;
          normal = cp.normal;
        };
      }
      CollisionInput ci;
      ci.C_hat = &C_hat;
      ci.lr_F = &d.lr.F;
      ci.lr_layer = &d.lr.layer;
      ci.hr_nearest_lr = &d.corr.hr_nearest_lr;
      ci.body = body ? &query : nullptr;
      stats = resolve_collisions(opt.collision, ci, G);
    }
    r.C_hat.push_back(std::move(C_hat));
    r.G.push_back(std::move(G));
    r.collisions.push_back(stats);
    if (progress) progress(k + 1, count);
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  r.seconds_per_frame = count ? secs / count : 0.0;
  r.model_seconds_per_frame = count ? model_secs / count : 0.0;
  return r;
}

}  // namespace gdsr
