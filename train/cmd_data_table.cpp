// gdsr data table: the stored validity figures of several datasets (or of every dataset in a
// recipe's folder), one row each, against the limits of issue 10 (gdsr/data/validity_summary.hpp).
#include "gdsr/cli/commands.hpp"

#include "gdsr/data/dataset.hpp"
#include "gdsr/data/validity_summary.hpp"
#include "gdsr/error.hpp"
#include "train/run_log.hpp"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

namespace {

struct TableArgs {
  std::vector<std::string> data;
  std::string out;
};

namespace fs = std::filesystem;

// A dataset folder as given, or, for a folder without a manifest, the datasets in it (a
// recipe's output), by name.
std::vector<fs::path> datasets_in(const std::string& path) {
  fs::path p = fs::path(path).lexically_normal();
  if (p.filename().empty()) p = p.parent_path();  // "DATA/"
  if (fs::exists(p / "manifest.json")) return {p};
  if (!fs::is_directory(p))
    gdsr::fail("--data " + path, "not a dataset folder (no manifest.json) nor a folder of them");
  std::vector<fs::path> found;
  for (const auto& e : fs::directory_iterator(p))
    if (e.is_directory() && fs::exists(e.path() / "manifest.json")) found.push_back(e.path());
  if (found.empty()) gdsr::fail("--data " + path, "no manifest.json in it nor in any folder in it");
  std::sort(found.begin(), found.end());
  return found;
}

double stat(const nlohmann::json& stats, const char* key) {
  return stats.contains(key) && stats[key].is_number() ? stats[key].get<double>() : std::nan("");
}

void run_table(const TableArgs& a) {
  std::vector<gdsr::ValiditySummaryRow> rows;
  for (const std::string& d : a.data)
    for (const fs::path& dir : datasets_in(d)) {
      const std::string manifest = (dir / "manifest.json").string();
      const gdsr::DatasetManifest m = gdsr::read_manifest(manifest);
      if (m.validity.empty())
        gdsr::fail(manifest, "no validity figures stored (made before they existed; `gdsr data check` prints them)");
      gdsr::ValiditySummaryRow row;
      row.name = dir.filename().string();
      row.garment = m.garment;
      row.v = gdsr::validity_from_json(m.validity);
      row.lr_seconds_per_frame = stat(m.stats, "lr_seconds_per_frame");
      row.hr_seconds_per_frame = stat(m.stats, "hr_seconds_per_frame");
      rows.push_back(row);
    }
  const std::string table = gdsr::validity_summary_markdown(rows);
  std::printf("%s", table.c_str());
  const auto passing = std::count_if(
      rows.begin(), rows.end(), [](const gdsr::ValiditySummaryRow& r) { return gdsr::failed_criteria(r.v).empty(); });
  std::printf("%ld of %zu datasets pass every limit\n", static_cast<long>(passing), rows.size());
  if (!a.out.empty()) {
    gdsr::write_text_atomic(a.out, table);
    std::printf("wrote %s\n", a.out.c_str());
  }
}

}  // namespace

void add_data_table_command(CLI::App& data) {
  auto args = std::make_shared<TableArgs>();
  CLI::App* t = data.add_subcommand(
      "table", "the stored validity figures of datasets side by side, one row each, and the limits each one fails");
  t->add_option("--data", args->data, "dataset folder, or a folder of them (a recipe's output); repeatable")
      ->required();
  t->add_option("--out", args->out, "also write the table to this Markdown file");
  t->callback([args]() { run_table(*args); });
}
