// gdsr export: a roll-out (a folder written by gdsr infer, or a checkpoint rolled out now)
// as files a DCC tool opens: glTF 2.0, PC2 point cache + rest OBJ, OBJ per frame, for the
// GDSR prediction, the LR input and the HR simulation (docs/exports.md).
#include "gdsr/cli/commands.hpp"

#include "gdsr/error.hpp"
#include "gdsr/io/staged_folder.hpp"
#include "infer/cmd_rollout_common.hpp"
#include "infer/export_rollout.hpp"

#include <CLI/CLI.hpp>

#include <cstdio>
#include <memory>
#include <sstream>

namespace {

struct ExportArgs {
  gdsr_cli::RolloutArgs rollout;
  std::string out = "runs/export";
  std::string formats = "gltf,pc2,obj";
  std::string sequences = "gdsr,lr,hr";
  int obj_every = 1;
};

// Comma-separated names, each one of `allowed`; throws naming the flag otherwise.
std::vector<std::string> split_names(const std::string& list, const std::string& flag,
                                     const std::vector<std::string>& allowed) {
  std::vector<std::string> out;
  std::stringstream ss(list);
  for (std::string item; std::getline(ss, item, ',');) {
    bool ok = false;
    for (const auto& a : allowed) ok |= item == a;
    if (!ok) gdsr::fail(flag, "unknown name '" + item + "'");
    out.push_back(item);
  }
  if (out.empty()) gdsr::fail(flag, "empty list");
  return out;
}

bool has(const std::vector<std::string>& v, const char* x) {
  for (const auto& s : v)
    if (s == x) return true;
  return false;
}

}  // namespace

void add_export_command(CLI::App& app) {
  auto a = std::make_shared<ExportArgs>();
  CLI::App* c = app.add_subcommand("export", "write a roll-out as glTF, PC2 + rest OBJ and OBJ per frame");
  gdsr_cli::add_source_options(c, a->rollout);
  gdsr_cli::add_rollout_options(c, a->rollout, false);
  gdsr_cli::add_sequence_options(c, a->rollout);
  c->add_option("--out", a->out, "output folder")->capture_default_str();
  c->add_option("--formats", a->formats, "comma-separated: gltf, pc2, obj")->capture_default_str();
  CLI::Option* sequences =
      c->add_option("--sequences", a->sequences,
                    "comma-separated: gdsr (prediction), lr (input), hr (simulation; not with --lr-dir)")
          ->capture_default_str();
  c->add_option("--obj-every", a->obj_every, "OBJ for every k-th frame")->capture_default_str();
  c->callback([a, sequences]() {
    const auto formats = split_names(a->formats, "--formats", {"gltf", "pc2", "obj"});
    const auto seqs = split_names(a->sequences, "--sequences", {"gdsr", "lr", "hr"});
    if (a->obj_every < 1) gdsr::fail("--obj-every", "must be at least 1");
    const gdsr::Dataset d = gdsr_cli::load_input(a->rollout);
    const gdsr::Prediction p = gdsr_cli::obtain_prediction(a->rollout, d);
    for (const gdsr::Points3& g : p.G)
      if (g.rows() != d.hr.V.rows())
        gdsr::fail(a->rollout.pred.empty() ? a->rollout.model : a->rollout.pred + "/pred_hr.bin",
                   std::to_string(g.rows()) + " HR vertices per frame, the HR garment has " +
                       std::to_string(d.hr.V.rows()) + " (same --data or --lr-dir/--hr-uv/--subdivide as gdsr infer?)");
    gdsr::RolloutExportOptions opt;
    opt.gdsr = has(seqs, "gdsr");
    opt.lr = has(seqs, "lr");
    opt.hr = has(seqs, "hr");
    if (d.hr_frames.empty() && sequences->count() == 0) opt.hr = false;  // --lr-dir: no HR simulation
    opt.formats.gltf = has(formats, "gltf");
    opt.formats.pc2 = has(formats, "pc2");
    opt.formats.obj = has(formats, "obj");
    opt.formats.obj_every = a->obj_every;
    gdsr::StagedFolder out(a->out, "export.json");  // all files, or none
    const nlohmann::json j = gdsr::export_rollout(out.path(), d, p.G, p.first_frame, opt);
    out.commit();
    std::printf("wrote %s: frames %d..%d at %g fps (export.json)\n", a->out.c_str(), p.first_frame,
                p.first_frame + static_cast<int>(p.G.size()) - 1, d.manifest.fps);
    for (const auto& s : j.at("sequences")) {
      std::string files;
      if (s.contains("gltf")) files += " " + s["gltf"].get<std::string>();
      if (s.contains("pc2")) files += " " + s["pc2"].get<std::string>() + " + " + s["rest_obj"].get<std::string>();
      if (s.contains("obj")) files += " obj/ (" + std::to_string(s["obj"].size()) + " files)";
      std::printf("  %-5s %6d vertices:%s\n", s.at("name").get<std::string>().c_str(), s.at("vertices").get<int>(),
                  files.c_str());
    }
  });
}
