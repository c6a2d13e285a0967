// SPDX-License-Identifier: MIT
// DroneModel::from_mesh: airframes from mesh files (glTF, OBJ, COLLADA, STL, ...) through assimp.
#include "wingman/sim/drone_model.hpp"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>
#include <assimp/Importer.hpp>

#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <regex>
#include <stdexcept>

namespace wingman::sim {
namespace {

// A mesh's colour: glTF base colour (linear), else the diffuse colour; opacity from the base colour's alpha or the
// material's opacity.
Eigen::Vector4f material_colour(const aiMaterial* material) {
  aiColor4D c(1.0f, 1.0f, 1.0f, 1.0f);
  if (material->Get(AI_MATKEY_BASE_COLOR, c) != AI_SUCCESS) {
    aiColor3D d(1.0f, 1.0f, 1.0f);
    if (material->Get(AI_MATKEY_COLOR_DIFFUSE, d) == AI_SUCCESS) c = aiColor4D(d.r, d.g, d.b, 1.0f);
    float opacity = 1.0f;
    if (material->Get(AI_MATKEY_OPACITY, opacity) == AI_SUCCESS) c.a = opacity;
  }
  return Eigen::Vector4f(c.r, c.g, c.b, c.a).cwiseMax(0.0f).cwiseMin(1.0f);
}

struct Loaded {
  std::vector<DroneVertex> vertices;
  std::vector<uint32_t> opaque, translucent;
  std::map<std::string, int> prop_parts;  // propeller name (the matched text) -> part
};

struct Walker {
  const aiScene* scene;
  const std::regex* prop_pattern;
  Eigen::Matrix4d T_mesh_to_body;  // mesh_scale and mesh_rpy_deg
  Loaded out;

  int part_of(const std::string& node_name, const std::string& mesh_name) {
    if (prop_pattern == nullptr) return 0;
    std::smatch m;
    for (const std::string* name : {&node_name, &mesh_name}) {
      if (std::regex_search(*name, m, *prop_pattern)) {
        const std::string key = m.str(0);
        auto it = out.prop_parts.find(key);
        if (it == out.prop_parts.end())
          it = out.prop_parts.emplace(key, static_cast<int>(out.prop_parts.size()) + 1).first;
        return it->second;
      }
    }
    return 0;
  }

  void walk(const aiNode* node, const aiMatrix4x4& parent) {
    const aiMatrix4x4 world = parent * node->mTransformation;
    Eigen::Matrix4d T_node;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) T_node(r, c) = world[r][c];
    }
    const Eigen::Matrix4d T = T_mesh_to_body * T_node;
    const Eigen::Matrix3d N = T.topLeftCorner<3, 3>().inverse().transpose();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
      const Eigen::Vector4f colour = material_colour(scene->mMaterials[mesh->mMaterialIndex]);
      const int part = part_of(node->mName.C_Str(), mesh->mName.C_Str());
      const uint32_t base = static_cast<uint32_t>(out.vertices.size());
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D& p = mesh->mVertices[v];
        DroneVertex dv;
        dv.p_in_body = (T * Eigen::Vector4d(p.x, p.y, p.z, 1.0)).head<3>().cast<float>();
        Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
        if (mesh->HasNormals())
          n = (N * Eigen::Vector3d(mesh->mNormals[v].x, mesh->mNormals[v].y, mesh->mNormals[v].z));
        dv.n_in_body = n.norm() > 0.0 ? Eigen::Vector3f(n.normalized().cast<float>()) : Eigen::Vector3f::UnitZ();
        dv.colour = colour;
        if (mesh->HasVertexColors(0)) {
          const aiColor4D& vc = mesh->mColors[0][v];
          dv.colour = dv.colour.cwiseProduct(Eigen::Vector4f(vc.r, vc.g, vc.b, vc.a));
        }
        dv.part = part;
        out.vertices.push_back(dv);
      }
      for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
        const aiFace& face = mesh->mFaces[f];
        if (face.mNumIndices != 3) continue;  // points and lines
        const bool translucent = colour.w() < 1.0f;
        auto& list = translucent ? out.translucent : out.opaque;
        for (int k = 0; k < 3; ++k) list.push_back(base + face.mIndices[k]);
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c) walk(node->mChildren[c], world);
  }
};

}  // namespace

DroneModel DroneModel::from_mesh(const DroneSpec& spec) {
  const std::string& path = spec.mesh_path;
  DroneSpec checked = spec;
  checked.frame = "mesh";
  const std::vector<std::string> problems = checked.validate();
  if (!problems.empty()) {
    std::string msg = "invalid drone spec: ";
    for (size_t i = 0; i < problems.size(); ++i) msg += (i ? "; " : "") + problems[i];
    throw std::invalid_argument(msg);
  }
  if (!std::filesystem::is_regular_file(path)) throw std::runtime_error(fmt::format("{}: no such mesh file", path));

  Assimp::Importer importer;
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices | aiProcess_SortByPType | aiProcess_GenNormals);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error(fmt::format("{}: assimp cannot read it: {}", path, importer.GetErrorString()));
  }

  const double deg = M_PI / 180.0;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(spec.mesh_rpy_deg[2] * deg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(spec.mesh_rpy_deg[1] * deg, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(spec.mesh_rpy_deg[0] * deg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  std::optional<std::regex> prop_pattern;
  if (!spec.mesh_prop_pattern.empty()) {
    prop_pattern.emplace(spec.mesh_prop_pattern, std::regex::ECMAScript | std::regex::icase);
  }
  Walker walker{scene, prop_pattern ? &*prop_pattern : nullptr, Eigen::Matrix4d::Identity(), {}};
  walker.T_mesh_to_body.topLeftCorner<3, 3>() = spec.mesh_scale * R;
  walker.walk(scene->mRootNode, aiMatrix4x4());
  Loaded& loaded = walker.out;
  if (loaded.opaque.empty() && loaded.translucent.empty()) {
    throw std::runtime_error(fmt::format("{}: the file holds no triangles", path));
  }

  // Each propeller spins about the vertical axis through the mean (x, y) of its vertices, or about the axes the spec
  // gives. The mean lands on the hub, where the vertices crowd: a bounding box or an area centroid is off by
  // millimetres for propellers whose blades differ, as the Iris's do.
  std::vector<Propeller> propellers(loaded.prop_parts.size());
  std::vector<Eigen::Vector2d> sum(propellers.size(), Eigen::Vector2d::Zero());
  std::vector<size_t> count(propellers.size(), 0);
  for (const DroneVertex& v : loaded.vertices) {
    if (v.part == 0) continue;
    sum[v.part - 1] += v.p_in_body.head<2>().cast<double>();
    ++count[v.part - 1];
  }
  if (!spec.mesh_prop_axes_m.empty() && spec.mesh_prop_axes_m.size() != 2 * propellers.size()) {
    throw std::runtime_error(
        fmt::format("{}: mesh_prop_axes_m has {} numbers but the mesh has {} propellers (need x, y "
                    "for each, in the order of their names)",
                    path, spec.mesh_prop_axes_m.size(), propellers.size()));
  }
  for (const auto& [name, part] : loaded.prop_parts) {
    const size_t k = static_cast<size_t>(part - 1);
    propellers[k].axis_in_body =
        count[k] > 0 ? Eigen::Vector2d(sum[k] / static_cast<double>(count[k])) : Eigen::Vector2d::Zero();
  }
  if (!spec.mesh_prop_axes_m.empty()) {
    size_t i = 0;  // prop_parts is ordered by name
    for (const auto& [name, part] : loaded.prop_parts) {
      propellers[part - 1].axis_in_body = {spec.mesh_prop_axes_m[2 * i], spec.mesh_prop_axes_m[2 * i + 1]};
      ++i;
    }
  }
  // Directions alternate around the ring by azimuth, like a multirotor's motors.
  std::vector<size_t> order(propellers.size());
  for (size_t k = 0; k < order.size(); ++k) order[k] = k;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return std::atan2(propellers[a].axis_in_body.y(), propellers[a].axis_in_body.x()) <
           std::atan2(propellers[b].axis_in_body.y(), propellers[b].axis_in_body.x());
  });
  for (size_t i = 0; i < order.size(); ++i) propellers[order[i]].direction = i % 2 == 0 ? 1 : -1;

  std::vector<uint32_t> indices = loaded.opaque;
  indices.insert(indices.end(), loaded.translucent.begin(), loaded.translucent.end());
  return DroneModel(std::move(loaded.vertices), std::move(indices), loaded.opaque.size(), std::move(propellers),
                    std::filesystem::path(path).filename().string());
}

}  // namespace wingman::sim
