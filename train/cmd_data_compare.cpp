// gdsr data compare: two datasets of one garment and clip, frame by frame (gdsr/data/dataset_compare.hpp).
#include "gdsr/cli/commands.hpp"

#include "gdsr/data/dataset_compare.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <string>

namespace {

struct CompareArgs {
  std::string a, b;
  int every = 10;
};

void print_summary(const char* label, const gdsr::FrameDifference& d) {
  if (d.identical) {
    std::printf("  %s: bit-identical over %zu frames\n", label, d.mean.size());
    return;
  }
  const int w = d.worst_frame();
  std::printf("  %s: mean %.2f mm over the clip, worst frame %.2f mm (f%d), largest vertex %.1f mm\n", label,
              1e3 * d.clip_mean(), 1e3 * d.mean[w], w, 1e3 * d.max);
}

void run_compare(const CompareArgs& a) {
  const gdsr::Dataset da = gdsr::load_dataset(a.a), db = gdsr::load_dataset(a.b);
  const gdsr::DatasetDifference d = gdsr::compare_datasets(da, db);
  std::printf("%s against %s: mean |a - b| over vertices, mm\n", a.a.c_str(), a.b.c_str());
  std::printf("  frame        LR        HR\n");
  for (size_t t = 0; t < d.lr.mean.size(); t += a.every)
    std::printf("  %5zu  %8.2f  %8.2f\n", t, 1e3 * d.lr.mean[t], 1e3 * d.hr.mean[t]);
  print_summary("LR", d.lr);
  print_summary("HR", d.hr);
}

}  // namespace

void add_data_compare_command(CLI::App& data) {
  auto args = std::make_shared<CompareArgs>();
  CLI::App* c = data.add_subcommand(
      "compare", "compare two datasets of one garment and clip frame by frame (a repeat, a solver change, a nudged twin)");
  c->add_option("--a", args->a, "first dataset folder")->required();
  c->add_option("--b", args->b, "second dataset folder")->required();
  c->add_option("--every", args->every, "print every k-th frame")->capture_default_str()->check(CLI::PositiveNumber);
  c->callback([args]() { run_compare(*args); });
}
