#include "pixelgym/render/shadow_pass.h"

#include "pixelgym/render/lod.h"
#include "pixelgym/render/render_target.h"
#include "pixelgym/render/transforms.h"

namespace pixelgym::render {

ShadowPass::ShadowPass()
    : caster_vertex_array_(make_vertex_array()),
      caster_vertex_buffer_(make_buffer()),
      caster_index_buffer_(make_buffer()) {
  glBindVertexArray(caster_vertex_array_.get());
  glBindBuffer(GL_ARRAY_BUFFER, caster_vertex_buffer_.get());
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, caster_index_buffer_.get());
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), reinterpret_cast<void*>(0));
  glEnableVertexAttribArray(0);
}

void ShadowPass::ensure_map(int size) {
  if (map_size_ == size) return;
  if (!map_framebuffer_) {
    map_framebuffer_ = make_framebuffer();
    map_texture_ = make_texture();
  }
  glBindTexture(GL_TEXTURE_2D, map_texture_.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, size, size, 0, GL_DEPTH_COMPONENT, GL_FLOAT,
               nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glBindFramebuffer(GL_FRAMEBUFFER, map_framebuffer_.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, map_texture_.get(), 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  check_framebuffer("shadow");
  map_size_ = size;
}

void ShadowPass::draw(const Scene& scene, const std::vector<const GpuMesh*>& drawn,
                      const Eigen::Matrix4f& light, int size, const DepthProgram& program) {
  ensure_map(size);
  glBindFramebuffer(GL_FRAMEBUFFER, map_framebuffer_.get());
  glViewport(0, 0, size, size);
  glClear(GL_DEPTH_BUFFER_BIT);
  glUseProgram(program.program.get());
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(2.0F, 4.0F);  // slope-scaled bias against shadow acne
  // Every caster in at most two draws: llvmpipe's cost per draw call outweighs transforming the
  // casters' vertices here (the depth pass needs positions only). Closed casters come first and
  // are drawn with their faces turned away from the light culled: the map keeps the nearest
  // depth, which is always a face turned toward the light, and llvmpipe's cost here is in
  // filling triangles (culling halves the arm's shadow pass).
  caster_positions_.clear();
  caster_indices_.clear();
  open_caster_indices_.clear();
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    if (!scene.instances[i].casts_shadow) continue;
    const MeshData& camera_mesh = *drawn[i]->keep_alive;
    const MeshData& mesh =
        camera_mesh.low_detail != nullptr ? *camera_mesh.low_detail : camera_mesh;
    const Eigen::Matrix4f model = model_matrix(scene.instances[i]);
    const auto first = static_cast<std::uint32_t>(caster_positions_.size() / 3);
    for (const Eigen::Vector3f& position : mesh.positions) {
      const Eigen::Vector4f p = model * position.homogeneous();
      caster_positions_.insert(caster_positions_.end(), {p.x(), p.y(), p.z()});
    }
    std::vector<std::uint32_t>& indices =
        cullable(scene.instances[i], mesh) ? caster_indices_ : open_caster_indices_;
    for (std::uint32_t index : mesh.indices) indices.push_back(first + index);
  }
  const std::size_t culled_index_count = caster_indices_.size();
  caster_indices_.insert(caster_indices_.end(), open_caster_indices_.begin(),
                         open_caster_indices_.end());
  glBindVertexArray(caster_vertex_array_.get());
  glBindBuffer(GL_ARRAY_BUFFER, caster_vertex_buffer_.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(caster_positions_.size() * sizeof(float)),
               caster_positions_.data(), GL_STREAM_DRAW);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, caster_index_buffer_.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER,
               static_cast<GLsizeiptr>(caster_indices_.size() * sizeof(std::uint32_t)),
               caster_indices_.data(), GL_STREAM_DRAW);
  glUniformMatrix4fv(program.model_view_projection, 1, GL_FALSE, light.data());
  glFrontFace(GL_CCW);  // the light's projection is not flipped
  if (culled_index_count > 0) {
    glEnable(GL_CULL_FACE);
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(culled_index_count), GL_UNSIGNED_INT,
                   nullptr);
    glDisable(GL_CULL_FACE);
  }
  if (caster_indices_.size() > culled_index_count) {
    glDrawElements(GL_TRIANGLES, static_cast<GLsizei>(caster_indices_.size() - culled_index_count),
                   GL_UNSIGNED_INT,
                   reinterpret_cast<void*>(culled_index_count * sizeof(std::uint32_t)));
  }
  glFrontFace(GL_CW);  // back to the camera's flipped projection
  glDisable(GL_POLYGON_OFFSET_FILL);
}

ShadowFootprints::ShadowFootprints()
    : vertex_array_(make_vertex_array()),
      vertex_buffer_(make_buffer()),
      index_buffer_(make_buffer()) {
  glBindVertexArray(vertex_array_.get());
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_.get());
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_.get());
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), reinterpret_cast<void*>(0));
  glEnableVertexAttribArray(0);
}

const GpuMesh& ShadowFootprints::upload(const std::vector<Eigen::AlignedBox2f>& rectangles) {
  vertices_.clear();
  for (const Eigen::AlignedBox2f& rect : rectangles) {
    const Eigen::Vector2f lo = rect.min();
    const Eigen::Vector2f hi = rect.max();
    const float quad[6][2] = {{lo.x(), lo.y()}, {hi.x(), lo.y()}, {hi.x(), hi.y()},
                              {lo.x(), lo.y()}, {hi.x(), hi.y()}, {lo.x(), hi.y()}};
    for (const auto& v : quad) vertices_.insert(vertices_.end(), {v[0], v[1], 0.0F});
  }
  glBindVertexArray(vertex_array_.get());
  glBindBuffer(GL_ARRAY_BUFFER, vertex_buffer_.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(vertices_.size() * sizeof(float)),
               vertices_.data(), GL_STREAM_DRAW);
  const auto count = static_cast<std::uint32_t>(vertices_.size() / 3);
  if (indices_.size() < count) {
    indices_.resize(count);
    for (std::uint32_t k = 0; k < count; ++k) indices_[k] = k;
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, index_buffer_.get());
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(count * sizeof(std::uint32_t)),
                 indices_.data(), GL_STATIC_DRAW);
  }
  mesh_.index_count = count;
  return mesh_;
}

}  // namespace pixelgym::render
