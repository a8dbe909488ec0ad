// Which training loss terms are on, their weights (the reference code's defaults) and the
// lambda schedule of the paper: lambda_c from 1.9 down and lambda_w from 0.1 up by 0.2
// every 10 epochs, clamped at 1 (schedule off: both 1). Read from and written to JSON for
// `gdsr train --loss-config F.json`.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace gdsr {

struct LossTerm {
  bool on = true;
  double weight = 1.0;
};

struct LossConfig {
  // coarse
  LossTerm c_position{true, 1.0};
  LossTerm c_normal{true, 0.01};
  LossTerm c_strain{true, 0.01};
  LossTerm c_smooth{true, 100.0};
  LossTerm c_dihedral{true, 0.003};
  // fine
  LossTerm f_position{true, 1.0};
  LossTerm f_normal_map{true, 0.01};  // weight of [VGG + L1] on the normal maps
  LossTerm f_vgg{true, 1.0};          // inside the normal-map term
  LossTerm f_image_l1{true, 1.0};     // inside the normal-map term
  LossTerm f_strain{true, 0.01};
  LossTerm f_smooth{true, 0.05};
  double image_background = 0.0;       // colour of background pixels (both images)
  bool image_l1_garment_only = false;  // false: L1 over whole images (reference); true: garment pixels
  // lambda schedule
  bool schedule = true;
  double lambda_c_start = 1.9, lambda_w_start = 0.1, lambda_step = 0.2;
  int lambda_every_epochs = 10;
  double lambda_c_end = 1.0, lambda_w_end = 1.0;
};

// JSON: {"coarse": {"position": {"on": true, "weight": 1}, "normal": .., "strain": ..,
// "smooth": .., "dihedral": ..}, "fine": {"position", "normal_map", "vgg", "image_l1",
// "strain", "smooth", "image_background", "image_l1_garment_only"}, "schedule": {"on",
// "lambda_c_start", "lambda_w_start", "step", "every_epochs", "lambda_c_end",
// "lambda_w_end"}}. Missing keys keep their defaults; unknown keys throw.
LossConfig loss_config_from_json(const nlohmann::json& j);
nlohmann::json loss_config_to_json(const LossConfig& c);
LossConfig load_loss_config(const std::string& path);  // throws naming the file
// The same on the file's text; `path` names the file in errors.
LossConfig loss_config_from_json_text(const std::string& text, const std::string& path);

struct Lambdas {
  double coarse = 1, fine = 1;
};
Lambdas lambda_schedule(const LossConfig& c, int epoch);  // epoch counts from 0

}  // namespace gdsr
