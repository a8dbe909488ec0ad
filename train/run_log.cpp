#include "train/run_log.hpp"

#include "gdsr/error.hpp"
#include "train/loss_plot.hpp"

#include <cmath>
#include <fstream>
#include <sstream>

namespace gdsr {

nlohmann::json train_options_to_json(const TrainOptions& o) {
  nlohmann::json j;
  j["model"] = nlohmann::json::parse(model_config_to_json_text(o.model));
  j["loss"] = loss_config_to_json(o.loss);
  j["patches"] = {{"size", o.patches.size},
                  {"count", o.patches.count},
                  {"min_coverage", o.patches.min_coverage},
                  {"random_position", o.patches.random_position},
                  {"halo", o.patches.halo},
                  {"max_tries", o.patches.max_tries}};
  j["epochs"] = o.epochs;
  j["max_steps"] = o.max_steps;
  j["frames_per_step"] = o.frames_per_step;
  j["rollout_history"] = o.rollout_history;
  j["rollout_from_truth"] = o.rollout_from_truth;
  j["unroll"] = o.unroll;
  j["detail_target"] = o.detail_target;
  j["lr"] = o.lr;
  j["weight_decay"] = o.weight_decay;
  j["amsgrad"] = o.amsgrad;
  j["lr_halve_every"] = o.lr_halve_every;
  j["lr_floor"] = o.lr_floor;
  j["fine"] = o.fine;
  j["vgg"] = o.vgg;
  j["vgg_dir"] = o.vgg_dir;
  j["seed"] = o.seed;
  j["checkpoint"] = o.checkpoint;
  j["checkpoint_every"] = o.checkpoint_every;
  j["best_checkpoint"] = o.best_checkpoint;
  j["validation_datasets"] = o.validation.size();
  j["resume"] = o.resume;
  j["init"] = o.init;
  return j;
}

void write_text_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
    f << text;
    f.flush();
    if (!f) {
      std::remove(tmp.c_str());
      gdsr::fail(path, "cannot write (disk full or no permission?)");
    }
  }
  if (std::rename(tmp.c_str(), path.c_str()) != 0) {
    std::remove(tmp.c_str());
    gdsr::fail(path, "cannot rename the temporary file into place");
  }
}

const std::vector<std::string>& RunLog::columns() {
  static const std::vector<std::string> c = {
      "step",       "epoch",    "loss",          "coarse",          "fine",      "c_position",       "c_normal",
      "c_strain",   "c_smooth", "c_dihedral",    "f_position",      "f_vgg",     "f_image_l1",       "f_strain",
      "f_smooth",   "lr",       "lambda_c",      "lambda_w",        "grad_norm", "seconds",          "val_loss",
      "val_coarse", "val_fine", "val_vertex_mm", "val_upsample_mm", "val_ssim",  "val_upsample_ssim"};
  return c;
}

namespace {

std::string header() {
  std::string h;
  for (const std::string& c : RunLog::columns()) h += (h.empty() ? "" : ",") + c;
  return h;
}

std::string num(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.9g", v);
  return b;
}

std::string row(const TrainLog& L) {
  std::string r = std::to_string(L.step) + "," + std::to_string(L.epoch) + "," + num(L.loss) + "," + num(L.coarse) +
                  "," + num(L.fine);
  for (size_t i = 5; i < 15; ++i) {
    const auto it = L.terms.find(RunLog::columns()[i]);
    r += "," + (it == L.terms.end() ? std::string() : num(it->second));
  }
  r += "," + num(L.lr) + "," + num(L.lambda_c) + "," + num(L.lambda_w) + "," + num(L.grad_norm) + "," +
       num(L.seconds);
  if (L.validated)
    r += "," + num(L.val_loss) + "," + num(L.val_coarse) + "," + num(L.val_fine) + "," + num(L.val_vertex_mm) + "," +
         num(L.val_upsample_mm) + "," + num(L.val_ssim) + "," + num(L.val_upsample_ssim);
  else
    r += ",,,,,,,";
  return r;
}

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream ss(line);
  std::string x;
  while (std::getline(ss, x, ',')) f.push_back(x);
  if (!line.empty() && line.back() == ',') f.push_back("");
  return f;
}

}  // namespace

RunLog::RunLog(const std::string& dir, int64_t resume_step) : dir_(dir) {
  std::string kept = header() + "\n";
  if (resume_step > 0) {
    std::ifstream in(csv_path());
    std::string line;
    // A log written before columns were added at the end (val_ssim, ...) keeps its rows,
    // padded with empty fields.
    size_t old_columns = 0;
    if (std::getline(in, line) && header().compare(0, line.size(), line) == 0 &&
        (line.size() == header().size() || header()[line.size()] == ','))
      old_columns = split(line).size();
    if (old_columns > 0)
      while (std::getline(in, line)) {
        std::vector<std::string> f = split(line);
        if (f.size() != old_columns) continue;  // a row cut by a kill
        for (size_t c = old_columns; c < columns().size(); ++c) line += ",";
        f.resize(columns().size());
        int64_t step = 0;
        double loss = 0, val = 0;
        try {  // a row that does not parse (cut by a kill, edited by hand) is dropped too
          step = std::stoll(f[0]);
          loss = std::stod(f[2]);
          if (!f[20].empty()) val = std::stod(f[20]);
        } catch (const std::exception&) {
          continue;
        }
        if (step > resume_step) continue;
        kept += line + "\n";
        train_.push_back({step, loss});
        if (!f[20].empty()) val_.push_back({step, val});
      }
  }
  write_text_atomic(csv_path(), kept);
  csv_ = std::fopen(csv_path().c_str(), "a");
  if (!csv_) gdsr::fail(csv_path(), "cannot open for appending");
}

RunLog::~RunLog() {
  if (csv_) std::fclose(csv_);
}

void RunLog::add(const TrainLog& L) {
  std::fprintf(csv_, "%s\n", row(L).c_str());
  std::fflush(csv_);
  train_.push_back({L.step, L.loss});
  if (L.validated) val_.push_back({L.step, L.val_loss});
  if (L.checkpointed) draw();
}

void RunLog::draw() const {
  PlotSeries raw{"train (per step)", train_, 235, 200, 160, false};
  PlotSeries mean{"train (mean of 20 steps)", {}, 160, 60, 0, false};
  double sum = 0;
  for (size_t i = 0; i < train_.size(); ++i) {
    sum += train_[i].second;
    if (i >= 20) sum -= train_[i - 20].second;
    mean.points.push_back({train_[i].first, sum / static_cast<double>(std::min<size_t>(i + 1, 20))});
  }
  std::vector<PlotSeries> series = {raw, mean};
  if (!val_.empty()) series.push_back({"validation", val_, 30, 30, 220, true});
  draw_loss_plot(png_path(), "training loss (weighted total, log scale)", series);
}

}  // namespace gdsr
