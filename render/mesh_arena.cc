#include "pixelgym/render/mesh_arena.h"

#include <algorithm>

namespace pixelgym::render {

MeshArena::MeshArena()
    : vertex_array_(make_vertex_array()),
      vertex_buffer_(make_buffer()),
      index_buffer_(make_buffer()) {
  glBindVertexArray(vertex_array_.get());
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_.get());
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_.get());
  constexpr GLsizei kBytes = kStride * sizeof(float);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, kBytes, reinterpret_cast<void*>(0));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, kBytes,
                        reinterpret_cast<void*>(3 * sizeof(float)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(2, 2, GL_FLOAT, GL_FALSE, kBytes,
                        reinterpret_cast<void*>(6 * sizeof(float)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(3, 4, GL_FLOAT, GL_FALSE, kBytes,
                        reinterpret_cast<void*>(8 * sizeof(float)));
  glEnableVertexAttribArray(3);
}

const GpuMesh& MeshArena::add(const std::shared_ptr<const MeshData>& mesh) {
  auto found = meshes_.find(mesh.get());
  if (found != meshes_.end()) return found->second;
  GpuMesh gpu;
  gpu.keep_alive = mesh;
  gpu.base_vertex = static_cast<GLint>(vertices_.size() / kStride);
  gpu.first_index = static_cast<std::uint32_t>(indices_.size());
  // Each part's colour goes into its vertices, so that a mesh is one draw whatever its number
  // of materials.
  std::vector<Eigen::Vector4f> colors(mesh->positions.size(), Eigen::Vector4f(0, 0, 0, -1));
  for (const MeshData::Part& part : mesh->parts) {
    if (!part.has_color) continue;
    for (std::uint32_t k = part.first_index; k < part.first_index + part.index_count; ++k) {
      colors[mesh->indices[k]] = part.rgba;
    }
  }
  for (std::size_t i = 0; i < mesh->positions.size(); ++i) {
    const Eigen::Vector3f& p = mesh->positions[i];
    const Eigen::Vector3f n =
        i < mesh->normals.size() ? mesh->normals[i] : Eigen::Vector3f::UnitZ();
    const Eigen::Vector2f t =
        i < mesh->texcoords.size() ? mesh->texcoords[i] : Eigen::Vector2f::Zero();
    const Eigen::Vector4f& c = colors[i];
    vertices_.insert(vertices_.end(), {p.x(), p.y(), p.z(), n.x(), n.y(), n.z(), t.x(), t.y(),
                                       c.x(), c.y(), c.z(), c.w()});
    gpu.radius = std::max(gpu.radius, p.norm());
    gpu.bounds.extend(p);
  }
  indices_.insert(indices_.end(), mesh->indices.begin(), mesh->indices.end());
  dirty_ = true;
  gpu.index_count = static_cast<std::uint32_t>(mesh->indices.size());
  return meshes_.emplace(mesh.get(), std::move(gpu)).first->second;
}

void MeshArena::sync() {
  glBindVertexArray(vertex_array_.get());
  if (!dirty_) return;
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices_.size() * sizeof(float)),
               vertices_.data(), GL_STATIC_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(indices_.size() * sizeof(std::uint32_t)), indices_.data(),
               GL_STATIC_DRAW);
  dirty_ = false;
}

void MeshArena::draw(const GpuMesh& mesh) {
  glDrawElementsBaseVertex(GL_TRIANGLES, static_cast<GLsizei>(mesh.index_count), GL_UNSIGNED_INT,
                           reinterpret_cast<void*>(static_cast<std::uintptr_t>(mesh.first_index) *
                                                   sizeof(std::uint32_t)),
                           mesh.base_vertex);
}

}  // namespace pixelgym::render
