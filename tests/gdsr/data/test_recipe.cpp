#include <doctest/doctest.h>

#include "gdsr/data/recipe.hpp"
#include "gdsr/error.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kGarments = {"skirt_short", "pants"};

// A recipe file in a fresh folder beside two empty motion files 60_03.bvh and 61_03.bvh.
struct RecipeDir {
  fs::path dir = fs::temp_directory_path() / ("gdsr_recipe_" + std::to_string(::getpid()));
  RecipeDir() {
    fs::remove_all(dir);
    fs::create_directories(dir / "motions");
    for (const char* m : {"60_03.bvh", "61_03.bvh", "01_01.bvh"}) std::ofstream(dir / "motions" / m) << "x";
  }
  ~RecipeDir() { fs::remove_all(dir); }
  std::string write(const std::string& json) const {
    std::ofstream(dir / "r.json") << json;
    return (dir / "r.json").string();
  }
};

std::string clip(const std::string& motion, const std::string& split, const std::string& extra = "") {
  return R"({"garment": "skirt_short", "motion": "motions/)" + motion + R"(", "start": 2, "seconds": 1.5, "split": ")" +
         split + "\"" + extra + "}";
}

std::string error_of(const RecipeDir& d, const std::string& json) {
  try {
    gdsr::load_recipe(d.write(json), kGarments);
  } catch (const gdsr::Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST_CASE("recipe: clips, defaults, names and motion paths relative to the recipe") {
  RecipeDir d;
  const auto r = gdsr::load_recipe(
      d.write(R"({"hr_pd": 0.015, "partner_subjects": [["60", "61"]], "clips": [)" + clip("60_03.bvh", "train") + ", " +
              clip("61_03.bvh", "train", R"(, "name": "mine")") + ", " + clip("01_01.bvh", "heldout") + "]}"),
      kGarments);
  CHECK(r.lr_pd == 0.03);
  CHECK(r.hr_pd == 0.015);
  CHECK(r.fps == 30);
  CHECK(r.rest_blend == 15);
  CHECK(std::isnan(r.hr_track_rate));  // absent: data make uses the solver's default
  REQUIRE(r.clips.size() == 3);
  CHECK(r.clips[0].name == "skirt_short_60_03_2s");
  CHECK(r.clips[0].motion == (d.dir / "motions" / "60_03.bvh").string());
  CHECK(r.clips[0].start == 2);
  CHECK(r.clips[0].seconds == 1.5);
  CHECK_FALSE(r.clips[0].heldout);
  CHECK(r.clips[1].name == "mine");
  CHECK(r.clips[2].heldout);
}

TEST_CASE("recipe: bad recipes are refused with the file and the key named") {
  RecipeDir d;
  const std::string path = (d.dir / "r.json").string();
  const std::string partners = R"("partner_subjects": [["60", "61"]], )";
  struct Case {
    std::string json, expect;
  } cases[] = {
      {"{", "invalid JSON"},
      {"[]", "JSON object"},
      {R"({"clips": []})", "\"clips\""},
      {R"({"clip": [1]})", "unknown key \"clip\""},
      {R"({"lr_pd": 0.01, "hr_pd": 0.02, "clips": [)" + clip("60_03.bvh", "train") + "]}", "coarser"},
      {R"({"fps": 0, "clips": [)" + clip("60_03.bvh", "train") + "]}", "\"fps\""},
      {R"({"hr_track_rate": -1, "clips": [)" + clip("60_03.bvh", "train") + "]}", "\"hr_track_rate\""},
      {R"({"clips": [{"garment": "cape", "motion": "motions/60_03.bvh", "seconds": 1}]})", "unknown garment"},
      {R"({"clips": [{"garment": "pants", "motion": "motions/none.bvh", "seconds": 1}]})", "none.bvh"},
      {R"({"clips": [{"garment": "pants", "motion": "motions/60_03.bvh"}]})", "clips[0]: missing \"seconds\""},
      {R"({"clips": [{"garment": "pants", "motion": "motions/60_03.bvh", "seconds": -1}]})", "\"seconds\""},
      {R"({"clips": [{"garment": "pants", "motion": "motions/60_03.bvh", "seconds": 1, "split": "test"}]})",
       "\"split\""},
      {R"({"clips": [)" + clip("60_03.bvh", "train", R"(, "name": "../up")") + "]}", "plain folder name"},
      {R"({"clips": [)" + clip("60_03.bvh", "train") + ", " + clip("60_03.bvh", "heldout") + "]}", "second clip"},
      // A held-out take whose partner was trained on is not unseen.
      {"{" + partners + R"("clips": [)" + clip("60_03.bvh", "train") + ", " + clip("61_03.bvh", "heldout") + "]}",
       "partner clips 60_03 and 61_03"},
  };
  for (const auto& c : cases) {
    const std::string msg = error_of(d, c.json);
    INFO(c.json);
    CHECK(msg.find(path) == 0);
    CHECK(msg.find(c.expect) != std::string::npos);
    CHECK(msg.find('\n') == std::string::npos);
  }
  CHECK(error_of(d, "{" + partners + R"("clips": [)" + clip("60_03.bvh", "heldout") + ", " +
                        clip("61_03.bvh", "heldout") + "]}") == "");
  CHECK(gdsr::load_recipe(d.write(R"({"hr_track_rate": 5, "clips": [)" + clip("60_03.bvh", "train") + "]}"), kGarments)
            .hr_track_rate == 5);
  try {
    gdsr::load_recipe((d.dir / "missing.json").string(), kGarments);
    FAIL("no error");
  } catch (const gdsr::Error& e) {
    CHECK(std::string(e.what()).find("missing.json") != std::string::npos);
  }
}
