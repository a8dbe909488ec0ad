#include "gdsr/data/recipe.hpp"

#include "gdsr/error.hpp"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

namespace gdsr {

namespace fs = std::filesystem;

namespace {

// Sane bounds (the same as `gdsr data make`'s flags).
constexpr double kMinPd = 0.002, kMaxPd = 0.5, kMaxFps = 240, kMaxSeconds = 3600;

double number(const nlohmann::json& j, const std::string& key, const std::string& where, double lo, double hi,
              double fallback, bool required) {
  if (!j.contains(key)) {
    if (required) fail(where, "missing \"" + key + "\"");
    return fallback;
  }
  const auto& v = j.at(key);
  if (!v.is_number()) fail(where, "\"" + key + "\" must be a number, got " + v.dump());
  const double x = v.get<double>();
  if (!(x >= lo && x <= hi))
    fail(where, "\"" + key + "\" = " + v.dump() + " is outside [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return x;
}

std::string text(const nlohmann::json& j, const std::string& key, const std::string& where, const std::string& fallback,
                 bool required) {
  if (!j.contains(key)) {
    if (required) fail(where, "missing \"" + key + "\"");
    return fallback;
  }
  if (!j.at(key).is_string() || j.at(key).get<std::string>().empty())
    fail(where, "\"" + key + "\" must be a non-empty string");
  return j.at(key).get<std::string>();
}

std::string default_name(const RecipeClip& c) {
  char start[32];
  std::snprintf(start, sizeof start, "%g", c.start);
  return c.garment + "_" + fs::path(c.motion).stem().string() + "_" + start + "s";
}

// "60_03" with subject "60" in a partner group -> "<group>/03"; "" when the clip has no partner.
std::string partner_key(const std::string& motion, const std::vector<std::vector<std::string>>& groups) {
  const std::string stem = fs::path(motion).stem().string();
  const auto us = stem.find('_');
  if (us == std::string::npos) return "";
  const std::string subject = stem.substr(0, us), take = stem.substr(us + 1);
  for (size_t g = 0; g < groups.size(); ++g)
    if (std::find(groups[g].begin(), groups[g].end(), subject) != groups[g].end())
      return std::to_string(g) + "/" + take;
  return "";
}

}  // namespace

Recipe load_recipe(const std::string& path, const std::vector<std::string>& garments) {
  std::ifstream in(path);
  if (!in || fs::is_directory(path)) fail(path, "cannot open the recipe");
  std::ostringstream ss;
  ss << in.rdbuf();
  nlohmann::json j;
  try {
    j = nlohmann::json::parse(ss.str());
  } catch (const std::exception&) {
    fail(path, "invalid JSON");
  }
  if (!j.is_object()) fail(path, "a recipe is a JSON object");
  static const std::set<std::string> known = {
      "comment", "lr_pd", "hr_pd", "fps", "rest_blend", "hr_track_rate", "partner_subjects", "clips"};
  for (const auto& [key, v] : j.items())
    if (!known.count(key)) fail(path, "unknown key \"" + key + "\"");

  Recipe r;
  r.path = path;
  r.lr_pd = number(j, "lr_pd", path, kMinPd, kMaxPd, r.lr_pd, false);
  r.hr_pd = number(j, "hr_pd", path, kMinPd, kMaxPd, r.hr_pd, false);
  if (r.hr_pd > r.lr_pd) fail(path, "\"hr_pd\" is coarser than \"lr_pd\"");
  r.fps = number(j, "fps", path, 1, kMaxFps, r.fps, false);
  const double blend = number(j, "rest_blend", path, 0, 1000, r.rest_blend, false);
  if (std::floor(blend) != blend) fail(path, "\"rest_blend\" must be a whole number of frames");
  r.rest_blend = static_cast<int>(blend);
  r.hr_track_rate = number(j, "hr_track_rate", path, 0, 1000, r.hr_track_rate, false);

  std::vector<std::vector<std::string>> groups;
  if (j.contains("partner_subjects")) {
    const auto& p = j.at("partner_subjects");
    bool ok = p.is_array();
    for (const auto& g : p) {
      ok = ok && g.is_array();
      std::vector<std::string> group;
      for (const auto& s : g) {
        ok = ok && s.is_string();
        if (s.is_string()) group.push_back(s.get<std::string>());
      }
      groups.push_back(group);
    }
    if (!ok) fail(path, "\"partner_subjects\" must be a list of lists of subject numbers as strings");
  }

  if (!j.contains("clips") || !j.at("clips").is_array() || j.at("clips").empty())
    fail(path, "\"clips\" must be a non-empty list");
  const fs::path base = fs::path(path).parent_path();
  std::set<std::string> names;
  for (size_t i = 0; i < j.at("clips").size(); ++i) {
    const auto& c = j.at("clips")[i];
    const std::string where = path + ": clips[" + std::to_string(i) + "]";
    if (!c.is_object()) fail(where, "a clip is a JSON object");
    static const std::set<std::string> clip_keys = {"garment", "motion", "start", "seconds", "split", "name"};
    for (const auto& [key, v] : c.items())
      if (!clip_keys.count(key)) fail(where, "unknown key \"" + key + "\"");
    RecipeClip clip;
    clip.garment = text(c, "garment", where, "", true);
    if (std::find(garments.begin(), garments.end(), clip.garment) == garments.end())
      fail(where, "unknown garment \"" + clip.garment + "\"");
    const fs::path motion = text(c, "motion", where, "", true);
    clip.motion = (motion.is_absolute() ? motion : base / motion).lexically_normal().string();
    if (!fs::is_regular_file(clip.motion)) fail(where, "motion file " + clip.motion + " does not exist");
    clip.start = number(c, "start", where, 0, 1e6, 0, false);
    clip.seconds = number(c, "seconds", where, 1e-3, kMaxSeconds, 0, true);
    const std::string split = text(c, "split", where, "train", false);
    if (split != "train" && split != "heldout") fail(where, "\"split\" must be \"train\" or \"heldout\"");
    clip.heldout = split == "heldout";
    clip.name = text(c, "name", where, default_name(clip), false);
    if (clip.name.find('/') != std::string::npos || clip.name == "." || clip.name == "..")
      fail(where, "\"name\" must be a plain folder name");
    if (!names.insert(clip.name).second) fail(where, "a second clip named \"" + clip.name + "\"");
    r.clips.push_back(clip);
  }

  // Partners on one side: the first clip of each partner key sets the side.
  std::map<std::string, const RecipeClip*> side;
  for (const RecipeClip& c : r.clips) {
    const std::string key = partner_key(c.motion, groups);
    if (key.empty()) continue;
    const auto [it, first] = side.emplace(key, &c);
    if (!first && it->second->heldout != c.heldout)
      fail(path, "partner clips " + fs::path(it->second->motion).stem().string() + " and " +
                     fs::path(c.motion).stem().string() + " are on different sides of the split (" + it->second->name +
                     ", " + c.name + ")");
  }
  return r;
}

}  // namespace gdsr
