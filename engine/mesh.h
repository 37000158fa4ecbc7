// Triangle meshes imported with assimp (OBJ, STL, DAE), shared read-only by every world.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace pixelgym::engine {

/// An immutable triangle mesh in its file's units (scale is applied by whoever uses it).
struct Mesh {
  /// A run of triangles sharing one material.
  struct Part {
    std::uint32_t first_index = 0;  // into `indices`
    std::uint32_t index_count = 0;  // a multiple of 3
    Eigen::Vector4f rgba{0.7F, 0.7F, 0.7F, 1.0F};
    /// True when the file gave this part a colour (diffuse) of its own.
    bool has_color = false;
  };

  /// The absolute path it was read from.
  std::string path;
  std::vector<Eigen::Vector3f> positions;
  /// One unit normal per position (computed by assimp when the file has none).
  std::vector<Eigen::Vector3f> normals;
  /// Three per triangle, indexing `positions`.
  std::vector<std::uint32_t> indices;
  std::vector<Part> parts;
  Eigen::AlignedBox3f bounds;

  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Reads a mesh file. Throws std::runtime_error naming the path and the reason for a missing or
/// unreadable file, an unsupported format (only .obj, .stl, .dae and .ply are accepted), or a file
/// with no triangles.
std::shared_ptr<const Mesh> load_mesh(const std::string& path);

/// Loads each mesh file once and hands out the same shared Mesh afterwards. Thread-safe.
class MeshCache {
 public:
  /// The mesh at `path` (made absolute and normalized first).
  std::shared_ptr<const Mesh> get(const std::string& path);
  /// How many files this cache has read.
  int files_read() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const Mesh>> meshes_;
  int files_read_ = 0;
};

}  // namespace pixelgym::engine
