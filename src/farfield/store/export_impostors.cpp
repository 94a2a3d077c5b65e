// Baked impostors as glTF nodes (see the header). The files are read with the store's checked readers one at a
// time and handed to the builder, which copies their data into the .glb buffer, so memory holds one decoded view or
// layered impostor besides the output.
#include "farfield/store/export_impostors.h"

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "farfield/core/error.h"
#include "farfield/core/progress.h"
#include "farfield/impostor/layered.h"
#include "farfield/store/impostor_store.h"
#include "farfield/store/json_fields.h"
#include "farfield/store/placement_store.h"

namespace farfield::store {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

json cameraJson(const Camera& c) {
  return {{"eye", vec3Json(c.eye)}, {"at", vec3Json(c.at)},       {"up", vec3Json(c.up)},
          {"fov_y_deg", radToDeg(double(c.fov_y))}, {"width", c.width}, {"height", c.height}};
}

json validityJson(const impostor::ValidityRegion& v) {
  return {{"origin", vec3Json(v.origin)}, {"end", vec3Json(v.end)}, {"half_width", v.half_width},
          {"below", v.below},             {"above", v.above},       {"back", v.back}};
}

json tagged(json body) { return json{{"farfield_impostor", std::move(body)}}; }

// The unlit, double-sided, alpha-tested material of an impostor texture.
scene::Material impostorMaterial(const std::string& name, std::shared_ptr<const image::ColorImage> texture) {
  scene::Material m;
  m.name = name;
  m.texture = std::move(texture);
  m.texture_path = name;
  m.unlit = true;
  m.double_sided = true;
  return m;
}

constexpr scene::GltfMaterialOptions kImpostorMaterial{true, 0.5f, true};

class PipelineExport {
 public:
  PipelineExport(scene::GltfBuilder& b, const std::string& dir, int root, ImpostorExportStats& stats)
      : builder_(b), dir_(dir), root_(root), stats_(stats) {}

  void run(const StoreIndex& index) {
    Progress progress("export impostors", index.cells.size());
    for (const CellEntry& cell : index.cells) {
      json region = {{"kind", "street cell"},
                     {"half_edge", cell.half_edge},
                     {"creation_camera", cameraJson(cell.camera)},
                     {"local_objects", cell.local_objects}};
      if (cell.pipeline) {
        const CellPipeline& p = *cell.pipeline;
        if (p.has_pvs) region["pvs"] = p.pvs;
        if (p.has_split) {
          region["near"] = p.near;
          region["far"] = p.far;
        }
      }
      const std::string name = "cell " + std::to_string(cell.half_edge);
      const int group = builder_.addNode(name, -1, root_, Mat4(1.0f), tagged(region));
      ++stats_.regions;
      if (cell.pipeline) {
        const CellPipeline& p = *cell.pipeline;
        if (p.has_single) writeLayer(group, name + " single", "single", p.single, -1);
        if (p.has_mmi)
          for (size_t l = 0; l < p.layers.size(); ++l)
            writeLayer(group, name + " mmi layer " + std::to_string(l), "mmi", p.layers[l], int(l));
      }
      for (const auto& [technique, stored] : cell.impostors) {
        const impostor::DepthMeshImpostor imp = loadImpostor(dir_, cell, technique);
        json extras = {{"kind", technique == "grid-mesh" ? "textured grid mesh" : "textured depth mesh"},
                       {"technique", technique},
                       {"half_edge", cell.half_edge},
                       {"creation_camera", cameraJson(imp.camera)}};
        writeMesh(group, name + " " + technique, imp, std::move(extras));
      }
      progress.advance();
    }
  }

 private:
  void writeLayer(int group, const std::string& name, const char* stage, const StoredLayer& layer, int layer_index) {
    json validity = json::array();
    for (const impostor::ValidityRegion& v : layer.validity) validity.push_back(validityJson(v));
    for (size_t v = 0; v < layer.views.size(); ++v) {
      const StoredView& view = layer.views[v];
      const impostor::DepthMeshImpostor imp = loadLayerView(dir_, view);
      json extras = {{"kind", "textured depth mesh"},
                     {"stage", stage},
                     {"objects", layer.objects},
                     {"view", v},
                     {"station", view.station},
                     {"creation_camera", cameraJson(view.camera)}};
      if (layer_index >= 0) extras["layer"] = layer_index;
      if (view.station < layer.validity.size()) extras["validity_region"] = validity[view.station];
      writeMesh(group, name + " view " + std::to_string(v), imp, std::move(extras));
    }
  }

  void writeMesh(int group, const std::string& name, const impostor::DepthMeshImpostor& imp, json extras) {
    if (imp.empty() || !imp.texture) {
      ++stats_.empty;
      return;
    }
    const int mesh = builder_.addMesh(imp.mesh, impostorMaterial(name, imp.texture), kImpostorMaterial, name);
    extras["triangles"] = imp.mesh.indices.size() / 3;
    builder_.addNode(name, mesh, group, Mat4(1.0f), tagged(std::move(extras)));
    ++stats_.impostors;
    ++stats_.meshes;
    stats_.triangles += imp.mesh.indices.size() / 3;
  }

  scene::GltfBuilder& builder_;
  const std::string& dir_;
  int root_;
  ImpostorExportStats& stats_;
};

// One quad per layer, as GpuLayeredImpostor draws it with LayerDraw::WholeQuads (layered_gpu.cpp; the same image as its
// tiles) but with each layer's own image: uv (0, 0) at the image's top-left texel, the capture's -right, +up corner;
// counter-clockwise seen from the viewers. One glTF mesh with a primitive per layer (far to near), so a CPV drawing
// the impostor needs one node.
int layeredMesh(scene::GltfBuilder& builder, const impostor::LayeredImpostor& imp, const std::string& name) {
  const impostor::LayeredPlan& plan = imp.plan;
  std::vector<scene::Mesh> quads(plan.layers.size());
  std::vector<scene::GltfBuilder::MeshPart> parts;
  for (size_t i = 0; i < plan.layers.size(); ++i) {
    const impostor::LayerPlan& lp = plan.layers[i];
    const Vec3 centre =
        plan.shaft.apex + lp.depth * plan.shaft.axis + lp.offset_u * plan.right + lp.offset_v * plan.up;
    const Vec3 du = lp.half_u * plan.right, dv = lp.half_v * plan.up;
    scene::Mesh& quad = quads[i];
    quad.positions = {centre - du + dv, centre + du + dv, centre + du - dv, centre - du - dv};
    quad.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    quad.indices = {3, 2, 1, 3, 1, 0};
    quad.computeBounds();
    auto texture = std::make_shared<const image::ColorImage>(imp.layers[i].color);
    parts.push_back({&quad, impostorMaterial(name + " layer " + std::to_string(i), texture), kImpostorMaterial});
  }
  return builder.addMesh(parts, name);
}

void exportPlacement(scene::GltfBuilder& builder, const std::string& dir, int root, const PlacementIndex& index,
                     ImpostorExportStats& stats) {
  // Each impostor's mesh is written once; the nodes of every CPV drawing it share it.
  std::map<uint32_t, int> meshes;
  {
    Progress progress("export impostors", index.impostors.size());
    for (const StoredPlacedImpostor& rec : index.impostors) {
      const impostor::LayeredImpostor imp = loadPlacedImpostor(dir, rec);
      meshes[rec.id] = layeredMesh(builder, imp, "impostor " + std::to_string(rec.id));
      ++stats.impostors;
      ++stats.meshes;
      stats.layers += imp.plan.layers.size();
      stats.triangles += 2 * imp.plan.layers.size();
      progress.advance();
    }
  }
  std::map<uint32_t, size_t> drawn;
  // The first node of an impostor describes it; the others (the same impostor drawn in other CPVs) name it.
  auto addImpostorNode = [&](int group, const StoredPlacedImpostor& rec) {
    const std::string name = "impostor " + std::to_string(rec.id);
    if (drawn.count(rec.id)) {
      builder.addNode(name, meshes.at(rec.id), group, Mat4(1.0f),
                      tagged({{"kind", "layered impostor"}, {"impostor", rec.id}}));
      return;
    }
    const impostor::LayeredPlan plan = impostor::planLayered(rec.box, rec.shaft, rec.bound, rec.options);
    json extras = {{"kind", "layered impostor"},
                   {"impostor", rec.id},
                   {"objects", rec.objects},
                   {"cluster_box", box3Json(rec.box)},
                   {"layers", rec.layers.size()},
                   {"error_angle_rad", plan.error_angle},
                   {"bound_px", rec.bound.pixels},
                   {"shaft", {{"apex", vec3Json(rec.shaft.apex)},
                              {"axis", vec3Json(rec.shaft.axis)},
                              {"apex_angle_rad", rec.shaft.apex_angle},
                              {"min_distance", rec.shaft.min_distance}}}};
    json layers = json::array();
    for (const StoredImpostorLayer& l : rec.layers) layers.push_back(l.data_texels);
    extras["layer_data_texels"] = std::move(layers);
    builder.addNode(name, meshes.at(rec.id), group, Mat4(1.0f), tagged(extras));
  };
  for (size_t k = 0; k < index.cpvs.size(); ++k) {
    const StoredCpv& cpv = index.cpvs[k];
    if (cpv.impostors.empty()) continue;  // geometry only there: nothing to show
    json region = {{"kind", "conservative problem view"},
                   {"cpv", k},
                   {"region", box3Json(cpv.region)},
                   {"view_directions", {{"face", cpv.vdi.face}, {"u", {cpv.vdi.u0, cpv.vdi.u1}},
                                        {"v", {cpv.vdi.v0, cpv.vdi.v1}}}},
                   {"t_enc", cpv.t_enc},
                   {"t_after", cpv.t_after},
                   {"impostors", cpv.impostors}};
    const int group = builder.addNode("cpv " + std::to_string(k), -1, root, Mat4(1.0f), tagged(region));
    ++stats.regions;
    for (uint32_t id : cpv.impostors) {
      const StoredPlacedImpostor* rec = index.find(id);
      if (!rec) throw Error(dir, "cpv " + std::to_string(k) + " names impostor " + std::to_string(id) + ", which the index lacks");
      addImpostorNode(group, *rec);
      ++drawn[id];
    }
  }
  int unused = -1;
  for (const StoredPlacedImpostor& rec : index.impostors)
    if (!drawn.count(rec.id)) {
      if (unused < 0)
        unused = builder.addNode("impostors in no view region", -1, root, Mat4(1.0f),
                                 tagged({{"kind", "impostors no CPV draws"}}));
      addImpostorNode(unused, rec);
    }
}

}  // namespace

ImpostorExportStats addImpostors(scene::GltfBuilder& builder, const std::string& database_dir, size_t scene_objects) {
  const bool pipeline = fs::exists(fs::path(database_dir) / kIndexFile);
  const bool placement = fs::exists(fs::path(database_dir) / kPlacementIndexFile);
  if (!fs::is_directory(database_dir))
    throw Error(database_dir, "is not an impostor database (not a directory)");
  if (!pipeline && !placement)
    throw Error(database_dir, std::string("is not an impostor database: neither ") + kIndexFile + " (farfield bake) nor " +
                                  kPlacementIndexFile + " (farfield place) found");
  ImpostorExportStats stats;
  auto checkScene = [&](size_t baked) {
    if (baked != scene_objects)
      throw Error(database_dir, "was made for a scene of " + std::to_string(baked) + " objects, the scene exported has " +
                                    std::to_string(scene_objects) + ": not this scene's database");
  };
  if (pipeline) {
    const StoreIndex index = readIndex(database_dir);
    checkScene(index.scene_objects);
    stats.database = "pipeline store";
    const int root = builder.addNode(
        "impostors", -1, -1, scene::worldToGltf(),
        tagged({{"kind", "impostor database"}, {"format", kIndexFormat}, {"version", index.version},
                {"pipeline", index.pipeline}, {"scene", index.scene}, {"frame", "Farfield world, Z up, metres"}}));
    PipelineExport(builder, database_dir, root, stats).run(index);
  } else {
    const PlacementIndex index = readPlacementIndex(database_dir);
    checkScene(index.scene_objects);
    stats.database = "placement";
    const int root = builder.addNode(
        "impostors", -1, -1, scene::worldToGltf(),
        tagged({{"kind", "impostor database"}, {"format", kPlacementFormat}, {"version", index.version},
                {"scene", index.scene}, {"view_space", box3Json(index.view_space)},
                {"frame", "Farfield world, Z up, metres"}}));
    exportPlacement(builder, database_dir, root, index, stats);
  }
  return stats;
}

ImpostorExportStats exportSceneAndImpostors(const scene::Scene& scene, const std::string& database_dir,
                                            const std::string& glb_path, size_t* bytes) {
  scene::GltfBuilder builder(glb_path);
  builder.addObjects(scene);
  ImpostorExportStats stats;
  if (!database_dir.empty()) stats = addImpostors(builder, database_dir, scene.objects.size());
  const size_t written = builder.write();
  if (bytes) *bytes = written;
  return stats;
}

}  // namespace farfield::store
