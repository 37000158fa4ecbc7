// Private to render/: the one vertex arena every mesh of a renderer lives in.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "pixelgym/render/gl.h"
#include "pixelgym/render/gl_object.h"
#include "pixelgym/render/mesh_data.h"

namespace pixelgym::render {

/// Where one mesh lies in an arena (or in another buffer drawn the same way).
struct GpuMesh {
  /// The mesh, kept alive so that its address stays a valid key.
  std::shared_ptr<const MeshData> keep_alive;
  /// Position of its first vertex in the vertex buffer (added to every index when drawn).
  GLint base_vertex = 0;
  /// Position of its first index in the index buffer.
  std::uint32_t first_index = 0;
  /// Its indices: three per triangle.
  std::uint32_t index_count = 0;
  /// Radius of a sphere about the mesh origin that holds every vertex, in mesh units.
  float radius = 0.0F;
  /// The box around its vertices, in mesh coordinates.
  Eigen::AlignedBox3f bounds;
};

/// Every mesh in one vertex buffer, one index buffer and one vertex array, so that drawing another
/// mesh changes no GL state but offsets (llvmpipe revalidates much of its state when the vertex
/// array changes, which dominated small frames). Meshes are added on first use, keyed by their
/// MeshData's address, kept alive by the arena, and never removed.
///
/// A vertex is kStride floats: position 3, normal 3, texture coordinate 2, part colour 4 (RGBA;
/// alpha -1 means "the instance's colour", for a part without its own).
class MeshArena {
 public:
  /// Floats per vertex (see above).
  static constexpr int kStride = 12;

  /// Creates the GL buffers and vertex array (a context must be current).
  MeshArena();

  /// The mesh's place in the arena, adding it (in CPU memory, sent by `sync`) on first use.
  const GpuMesh& add(const std::shared_ptr<const MeshData>& mesh);
  /// The mesh's place; throws std::out_of_range when it was never added.
  const GpuMesh& at(const MeshData* mesh) const { return meshes_.at(mesh); }
  /// Binds the arena's vertex array and sends meshes added since the last call to the GPU.
  void sync();
  /// The arena's vertex array object.
  GLuint vertex_array() const { return vertex_array_.get(); }

  /// Draws `mesh`'s triangles from the bound vertex array (the arena's, or one laid out alike).
  static void draw(const GpuMesh& mesh);

 private:
  std::vector<float> vertices_;
  std::vector<std::uint32_t> indices_;
  bool dirty_ = false;
  std::unordered_map<const MeshData*, GpuMesh> meshes_;
  GlVertexArray vertex_array_;
  GlBuffer vertex_buffer_;
  GlBuffer index_buffer_;
};

}  // namespace pixelgym::render
