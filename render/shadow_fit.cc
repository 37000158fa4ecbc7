#include "pixelgym/render/shadow_fit.h"

#include <algorithm>

#include "pixelgym/render/transforms.h"

namespace pixelgym::render {

int shadow_map_size(const Camera& camera) {
  int size = 128;
  while (size < std::max(camera.width, camera.height) && size < 2048) size *= 2;
  return size;
}

std::optional<Eigen::Matrix4f> fit_light_projection(
    const Scene& scene, const std::vector<Eigen::AlignedBox3f>& mesh_bounds) {
  const Eigen::Vector3f direction = scene.light.direction.normalized();
  const Eigen::Matrix4f light_view = look_from(Eigen::Vector3f::Zero(), direction);
  Eigen::Vector3f low = Eigen::Vector3f::Constant(1e30F);
  Eigen::Vector3f high = Eigen::Vector3f::Constant(-1e30F);
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    if (!instance.casts_shadow) continue;
    const Eigen::Matrix4f to_light_space = light_view * model_matrix(instance);
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3f p =
          mesh_bounds[i].corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner));
      const Eigen::Vector3f q = (to_light_space * p.homogeneous()).head<3>();
      low = low.cwiseMin(q);
      high = high.cwiseMax(q);
    }
  }
  if (low.x() > high.x()) return std::nullopt;  // nothing casts
  // A flat caster (a sheet facing the light, or seen edge-on) has no extent along some axis;
  // give it half a millimetre each way so that the projection stays finite.
  for (int axis = 0; axis < 3; ++axis) {
    if (high[axis] - low[axis] < 1e-4F) {
      low[axis] -= 5e-4F;
      high[axis] += 5e-4F;
    }
  }
  // Light space looks down -z: the casters lie between depths -high.z() and -low.z().
  return orthographic(low.x(), high.x(), low.y(), high.y(), -high.z(), -low.z()) * light_view;
}

void shadow_footprints(const Scene& scene, const std::vector<Eigen::AlignedBox3f>& mesh_bounds,
                       std::vector<Eigen::AlignedBox2f>& rectangles) {
  rectangles.clear();
  const Eigen::Vector3f direction = scene.light.direction.normalized();
  if (direction.z() > -1e-3F) return;  // light from below the horizon casts none on it
  const float h = scene.floor.height_m;
  for (std::size_t i = 0; i < scene.instances.size(); ++i) {
    const Instance& instance = scene.instances[i];
    if (!instance.casts_shadow) continue;
    const Eigen::Matrix4f model = model_matrix(instance);
    Eigen::AlignedBox2f rect;
    bool above = false;
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector3f p =
          (model * mesh_bounds[i]
                       .corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner))
                       .homogeneous())
              .head<3>();
      above = above || p.z() > h;
      const Eigen::Vector3f on_floor = p - direction * ((p.z() - h) / direction.z());
      rect.extend(on_floor.head<2>());
    }
    if (above) rectangles.push_back(rect);  // else entirely below the floor
  }
}

}  // namespace pixelgym::render
