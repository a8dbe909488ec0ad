#include "gdsr/sim/garments.hpp"

#include "gdsr/error.hpp"

#include "gdsr/sim/garment_design.hpp"

#include <algorithm>
#include <stdexcept>

namespace sim {

namespace {

struct CatalogueEntry {
  const char* name;
  GarmentDesign (*design)(const BodyLandmarks&);
  double rest_arm_drop_degrees = -1;  // see rest_arm_drop_degrees()
  int body_contact_every = 0;         // see body_contact_every(); 0: the solver's default
};

// The garment catalogue: the one place a garment's name is looked up.
const CatalogueEntry kCatalogue[] = {
    {"skirt_short", design_skirt_short},
    {"skirt_long", design_skirt_long},
    {"top", design_top},
    {"shorts", design_shorts},
    {"skirt_layered", design_skirt_layered},
    // The paper's five training garment types.
    {"tshirt", design_tshirt, 45, 3},
    {"pants", design_pants},
    {"skirt_pleated", design_skirt_pleated},
    {"dress_layered", design_dress_layered},
    {"skirt_tiered", design_skirt_tiered},
};

const CatalogueEntry& entry(const std::string& name) {
  for (const CatalogueEntry& e : kCatalogue)
    if (name == e.name) return e;
  std::string known;
  for (const CatalogueEntry& e : kCatalogue) known += std::string(known.empty() ? "" : ", ") + e.name;
  gdsr::fail("sim/garments", "unknown garment '" + name + "' (known: " + known + ")");
}

GarmentDesign design(const std::string& name, const BodyLandmarks& lm) { return entry(name).design(lm); }

}  // namespace

std::vector<std::string> garment_names() {
  std::vector<std::string> names;
  for (const CatalogueEntry& e : kCatalogue) names.push_back(e.name);
  return names;
}

double rest_arm_drop_degrees(const std::string& name) { return entry(name).rest_arm_drop_degrees; }

int body_contact_every(const std::string& name, int solver_default) {
  const int every = entry(name).body_contact_every;
  return every > 0 ? every : solver_default;
}

Pattern garment_pattern(const std::string& name, const BodyLandmarks& lm) { return design(name, lm).pattern; }

Garment make_garment(const std::string& name, double particle_distance_m, const gdsr::TriMesh& body_rest) {
  const BodyLandmarks lm = measure_body(body_rest);
  const GarmentDesign d = design(name, lm);
  PatternMesh pm = mesh_pattern(d.pattern, particle_distance_m);
  place_pattern(pm, d.place);
  if (d.layer) {
    pm.mesh.layer.assign(pm.mesh.V.rows(), 0);
    for (int u = 0; u < pm.mesh.UV.rows(); ++u) pm.mesh.layer[pm.mesh.uv_to_vertex[u]] = d.layer(pm.uv_panel[u]);
  }
  Garment g;
  g.name = name;
  g.particle_distance = particle_distance_m;
  if (d.pinned)
    for (int u = 0; u < pm.mesh.UV.rows(); ++u)
      if (d.pinned(pm.uv_panel[u], gdsr::Vec2(pm.mesh.UV.row(u)))) g.pinned.push_back(pm.mesh.uv_to_vertex[u]);
  std::sort(g.pinned.begin(), g.pinned.end());
  g.pinned.erase(std::unique(g.pinned.begin(), g.pinned.end()), g.pinned.end());
  g.mesh = std::move(pm.mesh);
  return g;
}

}  // namespace sim
