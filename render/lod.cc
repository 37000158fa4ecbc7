#include "pixelgym/render/lod.h"

#include <algorithm>
#include <cmath>

namespace pixelgym::render {

const std::shared_ptr<const MeshData>& select_detail(const Instance& instance,
                                                     const Camera& camera) {
  const MeshData& mesh = *instance.mesh;
  if (mesh.low_detail == nullptr) return instance.mesh;
  const float distance =
      (instance.X_world_instance.translation() - camera.X_world_camera.translation()).norm();
  const float size =
      std::min(std::abs(instance.scale.x()), std::abs(instance.scale.y())) * mesh.low_detail_radius;
  const float pixels_per_metre =
      0.5F * static_cast<float>(camera.height) /
      (std::tan(camera.fov_y_deg * 3.14159265F / 360.0F) * std::max(distance, 1e-3F));
  return size * pixels_per_metre < mesh.low_detail_below_px ? mesh.low_detail : instance.mesh;
}

}  // namespace pixelgym::render
