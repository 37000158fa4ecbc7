#include "pixelgym/engine/mesh.h"

#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "pixelgym/engine/regular_file.h"

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

// Checks a PLY file's header before assimp reads it: assimp 5.2 loops forever on some malformed
// headers (a "property" line with bytes that are no type, found by fuzz/mesh_fuzz.cc). A header is
// "ply", a "format" line, then "comment", "obj_info", "element NAME COUNT", "property TYPE NAME"
// and "property list TYPE TYPE NAME" lines up to "end_header"; anything else is refused, naming
// the line.
void check_ply_header(const std::string& path) {
  const auto fail = [&](int line, const std::string& problem) {
    throw std::runtime_error("mesh " + path + ": malformed PLY header at line " +
                             std::to_string(line) + ": " + problem);
  };
  std::ifstream in(path, std::ios::binary);
  static const std::set<std::string> kTypes = {
      "char", "uchar", "short", "ushort", "int",   "uint",   "float",   "double",
      "int8", "uint8", "int16", "uint16", "int32", "uint32", "float32", "float64"};
  std::string line;
  for (int number = 1; number <= 10000; ++number) {
    if (!std::getline(in, line)) fail(number, "the file ends before end_header");
    if (!line.empty() && line.back() == '\r') line.pop_back();
    for (const char c : line) {
      if (c != ' ' && c != '\t' && std::isprint(static_cast<unsigned char>(c)) == 0) {
        fail(number, "a byte that is not printable text");
      }
    }
    std::istringstream words(line);
    std::vector<std::string> word{std::istream_iterator<std::string>(words),
                                  std::istream_iterator<std::string>()};
    if (number == 1) {
      if (line != "ply") fail(number, "expected \"ply\", got \"" + line + "\"");
      continue;
    }
    if (word.empty()) continue;
    const std::string& key = word[0];
    if (key == "end_header") return;
    if (key == "comment" || key == "obj_info") continue;
    if (key == "format") {
      if (word.size() != 3 || (word[1] != "ascii" && word[1] != "binary_little_endian" &&
                               word[1] != "binary_big_endian")) {
        fail(number, "expected \"format ascii|binary_little_endian|binary_big_endian 1.0\"");
      }
    } else if (key == "element") {
      if (word.size() != 3 || word[2].find_first_not_of("0123456789") != std::string::npos) {
        fail(number, "expected \"element NAME COUNT\"");
      }
    } else if (key == "property") {
      const bool scalar = word.size() == 3 && kTypes.count(word[1]) != 0;
      const bool list = word.size() == 5 && word[1] == "list" && kTypes.count(word[2]) != 0 &&
                        kTypes.count(word[3]) != 0;
      if (!scalar && !list) {
        fail(number, "expected \"property TYPE NAME\" or \"property list TYPE TYPE NAME\"");
      }
    } else {
      fail(number, "unknown keyword \"" + key + "\"");
    }
  }
  fail(10000, "no end_header in the first 10,000 lines");
}
}  // namespace

std::shared_ptr<const Mesh> load_mesh(const std::string& path) {
  const std::string extension = lowercase_extension(path);
  if (extension != ".obj" && extension != ".stl" && extension != ".dae" && extension != ".ply") {
    throw std::runtime_error("mesh " + path + ": unsupported format \"" + extension +
                             "\" (supported: .obj, .stl, .dae, .ply)");
  }
  // assimp reads the file itself: refuse a FIFO or a device before it opens one (no size cap: a
  // scanned mesh of hundreds of MB is a real input).
  try {
    check_regular_file(path, "a mesh");
  } catch (const FileProblem& problem) {
    throw std::runtime_error("mesh " + path + ": " + problem.what());
  }
  if (extension == ".ply") check_ply_header(path);
  Assimp::Importer importer;
  // URDF meshes are in their file's coordinates: keep a Collada file's Z_UP as authored instead of
  // letting assimp turn the scene to its own Y-up convention.
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, true);
  // Read, then post-process. The post-processing steps trust each mesh's primitive types, which a
  // reader can get wrong on a malformed file: on a PLY with a garbled body (a face without
  // vertices) Triangulate called abort(), ending the process. They are recomputed from the faces in
  // between, and a face without vertices is refused.
  const aiScene* scene = importer.ReadFile(path, 0);
  if (scene != nullptr) {
    for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
      aiMesh& read = *scene->mMeshes[m];
      unsigned types = 0;
      for (unsigned f = 0; f < read.mNumFaces; ++f) {
        const unsigned corners = read.mFaces[f].mNumIndices;
        if (corners == 0) {
          throw std::runtime_error("mesh " + path + ": face " + std::to_string(f) + " of mesh " +
                                   std::to_string(m) + " has no vertices");
        }
        types |= corners == 1   ? aiPrimitiveType_POINT
                 : corners == 2 ? aiPrimitiveType_LINE
                 : corners == 3 ? aiPrimitiveType_TRIANGLE
                                : aiPrimitiveType_POLYGON;
      }
      if (types != 0) read.mPrimitiveTypes = types;  // a mesh without faces keeps its own
    }
    scene = importer.ApplyPostProcessing(aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                                         aiProcess_GenSmoothNormals | aiProcess_SortByPType);
  }
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
