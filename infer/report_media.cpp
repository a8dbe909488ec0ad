#include "infer/report_media.hpp"

#include "gdsr/error.hpp"
#include "gdsr/geometry/correspondence.hpp"
#include "gdsr/io/plot.hpp"
#include "gdsr/io/render.hpp"

#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

namespace gdsr {

namespace {

const cv::Scalar kGdsr(200, 90, 30), kLr(40, 140, 240), kHr(60, 150, 60);  // BGR: blue, orange, green
const cv::Scalar kScale(150, 150, 150);  // grey: the HR simulation at the LR scale (a perfect correction E)

std::vector<double> column(const Evaluation& e, double (*get)(const FrameEvaluation&)) {
  std::vector<double> v;
  for (const auto& f : e.frames) v.push_back(get(f));
  return v;
}

std::vector<double> frames_of(const Evaluation& e) {
  return column(e, [](const FrameEvaluation& f) { return static_cast<double>(f.frame); });
}

// LR | GDSR | HR meshes of dataset frame t.
std::vector<TriMesh> three_meshes(const Dataset& d, const Points3& G, int t) {
  return {TriMesh{d.lr_frames[t], d.lr.F}, TriMesh{G, d.hr.F}, TriMesh{d.hr_frames[t], d.hr.F}};
}

const std::vector<std::string> kLabels{"LR input", "GDSR", "HR simulation"};

// One camera framing all points of `meshes` seen along view_dir.
RenderOptions shared_camera(const std::vector<const Points3*>& pts, const Vec3& view_dir, int size) {
  RenderOptions o;
  o.width = o.height = size;
  o.view_dir = view_dir;
  Vec3 lo = Vec3::Constant(1e300), hi = Vec3::Constant(-1e300);
  for (const Points3* p : pts) {
    lo = lo.cwiseMin(p->colwise().minCoeff().transpose());
    hi = hi.cwiseMax(p->colwise().maxCoeff().transpose());
  }
  o.center = 0.5 * (lo + hi);
  const Vec3 f = view_dir.normalized(), right = f.cross(o.up).normalized(), up = right.cross(f);
  double ext = 0;
  for (int c = 0; c < 8; ++c) {
    const Vec3 q((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    ext = std::max({ext, std::abs((q - o.center).dot(right)), std::abs((q - o.center).dot(up))});
  }
  o.ortho_half_height = std::max(ext, 1e-3) * (1 + o.margin);
  return o;
}

cv::Mat render_row(const std::vector<TriMesh>& meshes, const RenderOptions& o) {
  const std::vector<cv::Vec3b> colours{cv::Vec3b(40, 140, 240), cv::Vec3b(200, 120, 60), cv::Vec3b(80, 170, 80)};
  std::vector<cv::Mat> imgs;
  for (size_t k = 0; k < meshes.size(); ++k) imgs.push_back(render_meshes({meshes[k]}, {colours[k]}, o));
  return side_by_side(imgs, kLabels);
}

}  // namespace

cv::Mat plot_error(const Evaluation& e) {
  PlotOptions o;
  o.title = "Vertex error to the HR simulation";
  o.x_label = "dataset frame";
  o.y_label = "mm";
  o.y_from_zero = true;
  const auto x = frames_of(e);
  return line_plot(
      {{"Upsampled LR", x, column(e, [](const FrameEvaluation& f) { return 1e3 * f.error_lr; }), kLr},
       {"GDSR", x, column(e, [](const FrameEvaluation& f) { return 1e3 * f.error; }), kGdsr},
       {"HR at the LR scale", x, column(e, [](const FrameEvaluation& f) { return 1e3 * f.error_scale; }), kScale}},
      o);
}

cv::Mat plot_ssim(const Evaluation& e) {
  std::vector<double> x;
  for (const auto& f : e.frames)
    if (f.has_ssim) x.push_back(f.frame);
  if (x.empty()) gdsr::fail("plot_ssim", "no frame has an SSIM");
  const auto series = [&](double FrameEvaluation::*field) {
    std::vector<double> s;
    for (const auto& f : e.frames)
      if (f.has_ssim) s.push_back(f.*field);
    return s;
  };
  PlotOptions o;
  o.title = "Normal-map SSIM, whole map";
  o.height = 280;
  o.y_label = "SSIM";
  const cv::Mat whole = line_plot({{"Upsampled LR", x, series(&FrameEvaluation::ssim_lr), kLr},
                                   {"GDSR", x, series(&FrameEvaluation::ssim), kGdsr},
                                   {"HR at the LR scale", x, series(&FrameEvaluation::ssim_scale), kScale}},
                                  o);
  o.title = "SSIM, garment pixels only";
  o.x_label = "dataset frame";
  const cv::Mat garment = line_plot({{"Upsampled LR", x, series(&FrameEvaluation::ssim_garment_lr), kLr},
                                     {"GDSR", x, series(&FrameEvaluation::ssim_garment), kGdsr},
                                     {"HR at the LR scale", x, series(&FrameEvaluation::ssim_garment_scale), kScale}},
                                    o);
  cv::Mat out;
  cv::vconcat(std::vector<cv::Mat>{whole, garment}, out);
  return out;
}

cv::Mat plot_energies(const Evaluation& e) {
  const auto x = frames_of(e);
  std::vector<cv::Mat> rows;
  const char* names[3] = {"E_u (stretch along u)", "E_v (stretch along v)", "E_uv (shear)"};
  for (int w = 0; w < 3; ++w) {
    const auto get = [w](const StrainEnergies& s) { return w == 0 ? s.E_u : w == 1 ? s.E_v : s.E_uv; };
    std::vector<double> g, lr, hr;
    for (const auto& f : e.frames)
      g.push_back(get(f.energies)), lr.push_back(get(f.energies_lr)), hr.push_back(get(f.energies_hr));
    PlotOptions o;
    o.title = names[w];
    o.x_label = w == 2 ? "dataset frame" : "";
    o.height = 280;
    o.y_from_zero = true;
    rows.push_back(line_plot({{"Upsampled LR", x, lr, kLr}, {"GDSR", x, g, kGdsr}, {"HR simulation", x, hr, kHr}}, o));
  }
  cv::Mat out;
  cv::vconcat(rows, out);
  return out;
}

cv::Mat normal_map_panel(const Dataset& d, const Points3& G, int t, int size) {
  const Points3 up = upsample(d.corr, d.lr_frames[t]);
  std::vector<cv::Mat> imgs;
  for (const Points3* V : {&up, &G, &d.hr_frames[t]}) {
    cv::Mat rgb = uv_normal_map(d.raster, d.hr.F, *V), bgr8, sized;
    cv::cvtColor(rgb, rgb, cv::COLOR_RGB2BGR);
    rgb.convertTo(bgr8, CV_8UC3, 255.0);
    cv::resize(bgr8, sized, cv::Size(size, size), 0, 0, cv::INTER_AREA);
    imgs.push_back(sized);
  }
  return side_by_side(imgs, {"LR upsampled", "GDSR", "HR simulation"});
}

cv::Mat shaded_panel(const Dataset& d, const Points3& G, int t, int size) {
  const auto meshes = three_meshes(d, G, t);
  std::vector<cv::Mat> rows;
  for (const Vec3& dir : {Vec3(0, 0, -1), Vec3(-1, 0, 0)})
    rows.push_back(render_row(meshes, shared_camera({&d.lr_frames[t], &G, &d.hr_frames[t]}, dir, size)));
  cv::Mat out;
  cv::vconcat(rows, out);
  return out;
}

int write_rollout_video(const std::string& path, const Dataset& d, const std::vector<Points3>& G, int first_frame,
                        int every, int size) {
  if (G.empty()) gdsr::fail(path, "no frames for the video");
  if (every < 1) every = 1;
  std::vector<const Points3*> all;
  for (size_t k = 0; k < G.size(); ++k) {
    const int t = first_frame + static_cast<int>(k);
    all.insert(all.end(), {&d.lr_frames[t], &G[k], &d.hr_frames[t]});
  }
  const RenderOptions cam = shared_camera(all, Vec3(0, 0, -1), size);
  const std::string tmp = path + ".tmp.avi";
  cv::VideoWriter video;
  int written = 0;
  // A failure half-way (a render error, a full disk) takes the temp video with it.
  struct RemoveOnFailure {
    const std::string& file;
    bool done = false;
    ~RemoveOnFailure() {
      if (!done) std::remove(file.c_str());
    }
  } cleanup{tmp};
  for (size_t k = 0; k < G.size(); k += static_cast<size_t>(every)) {
    const int t = first_frame + static_cast<int>(k);
    cv::Mat img = render_row(three_meshes(d, G[k], t), cam);
    char label[48];
    std::snprintf(label, sizeof label, "frame %d", t);
    cv::putText(img, label, {8, img.rows - 10}, cv::FONT_HERSHEY_SIMPLEX, 0.5, cv::Scalar(40, 40, 40), 1, cv::LINE_AA);
    if (!video.isOpened()) {
      const double fps = std::max(1.0, d.manifest.fps / every);
      if (!video.open(tmp, cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps, img.size()))
        gdsr::fail(path, "OpenCV cannot open an MJPG video writer");
    }
    video.write(img);
    ++written;
  }
  video.release();
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) gdsr::fail(path, "cannot rename " + tmp + ": " + ec.message());
  cleanup.done = true;
  return written;
}

}  // namespace gdsr
