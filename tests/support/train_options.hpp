// Trainer options for the tiny model on the waving sheet of data_fixtures.hpp (test code).
// A template on the options type (gdsr::TrainOptions) because tests/support may not include
// train/ (the layering rules); the train tests instantiate it.
#pragma once

#include "gdsr/model/model_config.hpp"

#include <string>

namespace gdsr_test {

// configs/tiny.json, two 32-pixel patches, no VGG term (no weights file needed; the VGG term
// has its own tests), lr 3e-3, the lambda schedule off.
template <class TrainOptions> TrainOptions tiny_train_options() {
  TrainOptions o;
  o.model = gdsr::load_model_config(std::string(GDSR_SOURCE_DIR) + "/configs/tiny.json");
  o.patches.size = 32;
  o.patches.count = 2;
  o.vgg = false;
  o.lr = 3e-3;
  o.loss.schedule = false;
  return o;
}

}  // namespace gdsr_test
