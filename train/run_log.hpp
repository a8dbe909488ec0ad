// The record of a training run in its folder: train_log.csv (one row per step: every loss
// term, learning rate, lambda weights, gradient norm, step time, validation figures at
// checkpoint steps), loss_curves.png (train and validation totals on a log scale, redrawn at
// every checkpoint) and config.json (every option and preset value of the run). Files are
// written to a temp file and renamed; the CSV is appended row by row.
#pragma once

#include "train/trainer.hpp"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <string>
#include <vector>

namespace gdsr {

// Every value of the options (model preset, loss config, patches, schedule, paths).
nlohmann::json train_options_to_json(const TrainOptions& opt);

// Writes `text` to `path` through "<path>.tmp" and a rename; throws naming the file.
void write_text_atomic(const std::string& path, const std::string& text);

class RunLog {
 public:
  // dir: the run folder. resume_step > 0: rows after that step (a killed run's steps past its
  // checkpoint) are dropped and the log continues; 0: a fresh log.
  RunLog(const std::string& dir, int64_t resume_step);
  ~RunLog();
  RunLog(const RunLog&) = delete;
  RunLog& operator=(const RunLog&) = delete;

  void add(const TrainLog& L);  // appends a row; redraws the PNG when L.checkpointed
  void draw() const;            // redraws loss_curves.png now
  std::string csv_path() const { return dir_ + "/train_log.csv"; }
  std::string png_path() const { return dir_ + "/loss_curves.png"; }

  static const std::vector<std::string>& columns();

 private:
  std::string dir_;
  std::FILE* csv_ = nullptr;
  std::vector<std::pair<int64_t, double>> train_, val_;  // (step, total) for the plot
};

}  // namespace gdsr
