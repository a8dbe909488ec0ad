// The command line's progress bar: ProgressBar::callback() is a ProgressFn that draws a
// one-line bar on a stream (stderr by default), redrawn in place with '\r' on a terminal and
// in 10% steps otherwise so logs stay short. Libraries only call the ProgressFn.
#pragma once

#include "gdsr/io/progress.hpp"

#include <chrono>
#include <iosfwd>
#include <string>

namespace gdsr {

class ProgressBar {
 public:
  explicit ProgressBar(std::string label, std::ostream* out = nullptr, int width = 30);
  ~ProgressBar();
  void update(int done, int total);
  void finish();  // redraws the last state and ends the line on a terminal; idempotent
  ProgressFn callback();
  double elapsed_seconds() const;

 private:
  std::string label_;
  std::ostream* out_;
  int width_;
  bool tty_;
  bool drawn_ = false, finished_ = false;
  int last_decile_ = -1, total_ = 0, done_ = 0;
  std::chrono::steady_clock::time_point start_, last_draw_;
  void draw(int done, int total);
};

}  // namespace gdsr
