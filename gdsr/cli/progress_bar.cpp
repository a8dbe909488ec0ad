#include "gdsr/cli/progress_bar.hpp"

#include <algorithm>
#include <string>
#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace gdsr {

ProgressBar::ProgressBar(std::string label, std::ostream* out, int width)
    : label_(std::move(label)),
      out_(out ? out : &std::cerr),
      width_(width),
      tty_(out == nullptr && ::isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() {
  try {
    finish();
  } catch (...) {
  }
}

double ProgressBar::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

void ProgressBar::draw(int done, int total) {
  const double frac = total > 0 ? std::clamp(static_cast<double>(done) / total, 0.0, 1.0) : 1.0;
  const int filled = static_cast<int>(frac * width_ + 0.5);
  const double t = elapsed_seconds();
  const double eta = frac > 0 ? t * (1 - frac) / frac : 0;
  char buf[96];
  std::snprintf(buf, sizeof buf, "] %3d%% %d/%d  %.1fs  eta %.0fs", static_cast<int>(frac * 100), done, total, t, eta);
  std::string line = label_ + " [" + std::string(filled, '#') + std::string(width_ - filled, '.') + buf;
  if (tty_)
    *out_ << '\r' << line << "\x1b[K" << std::flush;
  else
    *out_ << line << '\n' << std::flush;
  drawn_ = true;
}

void ProgressBar::update(int done, int total) {
  if (finished_) return;
  done_ = done;
  total_ = total;
  const auto now = std::chrono::steady_clock::now();
  if (tty_) {
    if (done >= total || now - last_draw_ > std::chrono::milliseconds(100) || !drawn_) {
      draw(done, total);
      last_draw_ = now;
    }
    return;
  }
  const int decile = total > 0 ? std::min(10, done * 10 / total) : 10;
  if (decile != last_decile_) {
    last_decile_ = decile;
    draw(done, total);
  }
}

void ProgressBar::finish() {
  if (finished_) return;
  if (drawn_ && tty_) {
    draw(done_, total_);
    *out_ << '\n' << std::flush;
  }
  finished_ = true;
}

ProgressFn ProgressBar::callback() {
  return [this](int done, int total) { update(done, total); };
}

}  // namespace gdsr
