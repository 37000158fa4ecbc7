#include "engine/mesh.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <filesystem>
#include <stdexcept>

namespace pixelgym::engine {
namespace {

std::string lowercase_extension(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
}

// Appends `node`'s meshes, transformed by its accumulated transform, to `mesh`.
void append_node(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent_transform,
                 Mesh& mesh) {
  const aiMatrix4x4 transform = parent_transform * node.mTransformation;
  aiMatrix3x3 normal_transform(transform);
  normal_transform.Inverse().Transpose();
  for (unsigned m = 0; m < node.mNumMeshes; ++m) {
    const aiMesh& source = *scene.mMeshes[node.mMeshes[m]];
    const auto base = static_cast<std::uint32_t>(mesh.positions.size());
    for (unsigned v = 0; v < source.mNumVertices; ++v) {
      const aiVector3D p = transform * source.mVertices[v];
      mesh.positions.emplace_back(p.x, p.y, p.z);
      aiVector3D n =
          source.HasNormals() ? normal_transform * source.mNormals[v] : aiVector3D(0, 0, 1);
      n.Normalize();
      mesh.normals.emplace_back(n.x, n.y, n.z);
    }
    Mesh::Part part;
    part.first_index = static_cast<std::uint32_t>(mesh.indices.size());
    for (unsigned f = 0; f < source.mNumFaces; ++f) {
      const aiFace& face = source.mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines left by triangulation
      for (int k = 0; k < 3; ++k) mesh.indices.push_back(base + face.mIndices[k]);
    }
    part.index_count = static_cast<std::uint32_t>(mesh.indices.size()) - part.first_index;
    if (source.mMaterialIndex < scene.mNumMaterials) {
      aiColor4D diffuse;
      if (scene.mMaterials[source.mMaterialIndex]->Get(AI_MATKEY_COLOR_DIFFUSE, diffuse) ==
          AI_SUCCESS) {
        part.rgba = {diffuse.r, diffuse.g, diffuse.b, diffuse.a};
        part.has_color = true;
      }
    }
    if (part.index_count > 0) mesh.parts.push_back(part);
  }
  for (unsigned c = 0; c < node.mNumChildren; ++c) {
    append_node(scene, *node.mChildren[c], transform, mesh);
  }
}

}  // namespace

std::shared_ptr<const Mesh> load_mesh(const std::string& path) {
  const std::string extension = lowercase_extension(path);
  if (extension != ".obj" && extension != ".stl" && extension != ".dae" && extension != ".ply") {
    throw std::runtime_error("mesh " + path + ": unsupported format \"" + extension +
                             "\" (supported: .obj, .stl, .dae, .ply)");
  }
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) {
    throw std::runtime_error("mesh " + path + ": file not found");
  }
  Assimp::Importer importer;
  // URDF meshes are in their file's coordinates: keep a Collada file's Z_UP as authored instead of
  // letting assimp turn the scene to its own Y-up convention.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  const aiScene* scene =
      importer.ReadFile(path, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                  aiProcess_GenSmoothNormals | aiProcess_SortByPType);
  if (scene == nullptr || scene->mRootNode == nullptr) {
    throw std::runtime_error("mesh " + path + ": cannot be read: " + importer.GetErrorString());
  }
  auto mesh = std::make_shared<Mesh>();
  mesh->path = path;
  append_node(*scene, *scene->mRootNode, aiMatrix4x4(), *mesh);
  if (mesh->indices.empty()) throw std::runtime_error("mesh " + path + ": has no triangles");
  for (const Eigen::Vector3f& p : mesh->positions) mesh->bounds.extend(p);
  return mesh;
}

std::shared_ptr<const Mesh> MeshCache::get(const std::string& path) {
  const std::string key = std::filesystem::absolute(path).lexically_normal().string();
  std::lock_guard<std::mutex> lock(mutex_);
  auto found = meshes_.find(key);
  if (found != meshes_.end()) return found->second;
  std::shared_ptr<const Mesh> mesh = load_mesh(key);
  ++files_read_;
  meshes_.emplace(key, mesh);
  return mesh;
}

int MeshCache::files_read() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return files_read_;
}

}  // namespace pixelgym::engine
