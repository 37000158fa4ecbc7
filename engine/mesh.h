// Triangle meshes imported with assimp (OBJ, STL, DAE, PLY), shared read-only by every world.
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
    /// Position of the run's first index in `indices`.
    std::uint32_t first_index = 0;
    /// Indices in the run: three per triangle.
    std::uint32_t index_count = 0;
    /// The file's diffuse colour, RGBA in [0, 1], when `has_color`; grey otherwise.
    Eigen::Vector4f rgba{0.7F, 0.7F, 0.7F, 1.0F};
    /// True when the file gave this part a colour (diffuse) of its own.
    bool has_color = false;
  };

  /// The path it was read from, as given to load_mesh (absolute and normalized when read through
  /// MeshCache).
  std::string path;
  /// Vertex positions, with the file's node transforms applied.
  std::vector<Eigen::Vector3f> positions;
  /// One unit normal per position (computed by assimp when the file has none).
  std::vector<Eigen::Vector3f> normals;
  /// Three per triangle, indexing `positions`.
  std::vector<std::uint32_t> indices;
  /// The runs of triangles, one per mesh of the file that has triangles, in `indices` order.
  std::vector<Part> parts;
  /// The axis-aligned box around `positions`.
  Eigen::AlignedBox3f bounds;

  /// indices.size() / 3.
  std::size_t triangle_count() const { return indices.size() / 3; }
};

/// Reads a mesh file. Throws std::runtime_error naming the path and the reason for a missing or
/// unreadable file, an unsupported format (only .obj, .stl, .dae and .ply are accepted), or a file
/// with no triangles.
std::shared_ptr<const Mesh> load_mesh(const std::string& path);

/// Loads each mesh file once and hands out the same shared Mesh afterwards. Thread-safe.
class MeshCache {
 public:
  /// The mesh at `path` (made absolute and normalized first), read with load_mesh on first use.
  /// Throws as load_mesh; a file that failed is not remembered, so a later call reads it again.
  /// Reads happen under the cache's lock: concurrent first uses take turns.
  std::shared_ptr<const Mesh> get(const std::string& path);
  /// How many files this cache has read.
  int files_read() const;

 private:
  mutable std::mutex mutex_;
  std::map<std::string, std::shared_ptr<const Mesh>> meshes_;
  int files_read_ = 0;
};

}  // namespace pixelgym::engine
