#include "pixelgym/envs/tasks/world_scene.h"

#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>

namespace pixelgym {
namespace {

constexpr float kPi = 3.14159265358979323846F;

constexpr std::size_t kMeshLowDetailMinTriangles = 200;
constexpr float kMeshLowDetailBelowPx = 10.0F;

// Engine meshes converted for drawing, shared process-wide; the engine mesh is kept alive so its
// address stays a valid key.
struct ConvertedMesh {
  std::shared_ptr<const engine::Mesh> source;
  std::shared_ptr<const render::MeshData> with_colors;
  std::shared_ptr<const render::MeshData> without_colors;
};

std::shared_ptr<const render::MeshData> convert(const std::shared_ptr<const engine::Mesh>& mesh,
                                                bool keep_part_colors) {
  static std::mutex mutex;
  static std::map<const engine::Mesh*, ConvertedMesh> converted;
  std::lock_guard<std::mutex> lock(mutex);
  ConvertedMesh& entry = converted[mesh.get()];
  std::shared_ptr<const render::MeshData>& slot =
      keep_part_colors ? entry.with_colors : entry.without_colors;
  if (slot == nullptr) {
    entry.source = mesh;
    auto data = std::make_shared<render::MeshData>();
    data->positions = mesh->positions;
    data->normals = mesh->normals;
    data->indices = mesh->indices;
    for (const engine::Mesh::Part& part : mesh->parts) {
      render::MeshData::Part out;
      out.first_index = part.first_index;
      out.index_count = part.index_count;
      out.rgba = part.rgba;
      out.has_color = keep_part_colors && part.has_color;
      data->parts.push_back(out);
    }
    data->closed = render::is_closed_surface(*data);
    // Drawn small (as in 84 x 84 observations), a mesh needs only a fraction of its triangles,
    // and llvmpipe pays for every one: a clustered copy with cells of a tenth of its size is
    // drawn while its half-diagonal covers fewer than kMeshLowDetailBelowPx pixels.
    Eigen::AlignedBox3f bounds;
    for (const Eigen::Vector3f& p : data->positions) bounds.extend(p);
    const float half_diagonal = 0.5F * bounds.diagonal().norm();
    if (data->triangle_count() > kMeshLowDetailMinTriangles && half_diagonal > 0.0F) {
      // Two levels: the coarse copy has its own coarser copy, which shadows use (see Renderer).
      auto coarse = std::make_shared<render::MeshData>(
          *render::simplify_by_clustering(*data, half_diagonal / 3.0F));
      coarse->low_detail = render::simplify_by_clustering(*data, half_diagonal / 1.5F);
      coarse->low_detail_radius = half_diagonal;
      coarse->low_detail_below_px = 0.0F;  // never chosen for the camera, only for shadows
      data->low_detail = std::move(coarse);
      data->low_detail_radius = half_diagonal;
      data->low_detail_below_px = kMeshLowDetailBelowPx;
    }
    slot = std::move(data);
  }
  return slot;
}

// Round primitives switch to 10 segments below this radius on screen, where 24 would only add
// triangles (and llvmpipe pays per triangle, however small).
constexpr float kLowDetailBelowPx = 6.0F;

// Unit primitives shared by every scene.
std::shared_ptr<const render::MeshData> shared_primitive(engine::GeometryType type) {
  static const auto box = render::make_box_mesh();
  static const auto sphere = render::with_low_detail(
      *render::make_sphere_mesh(24), render::make_sphere_mesh(10), kLowDetailBelowPx);
  static const auto cylinder = render::with_low_detail(
      *render::make_cylinder_mesh(24), render::make_cylinder_mesh(10), kLowDetailBelowPx);
  switch (type) {
    case engine::GeometryType::kBox:
      return box;
    case engine::GeometryType::kSphere:
      return sphere;
    default:
      return cylinder;
  }
}

std::shared_ptr<const render::MeshData> shared_capsule(double length_over_radius) {
  static std::mutex mutex;
  static std::map<long, std::shared_ptr<const render::MeshData>>
      capsules;  // by ratio in thousandths
  const long key = std::lround(length_over_radius * 1000.0);
  std::lock_guard<std::mutex> lock(mutex);
  auto& slot = capsules[key];
  if (slot == nullptr) {
    const double ratio = static_cast<double>(key) / 1000.0;
    slot = render::with_low_detail(*render::make_capsule_mesh(ratio, 24),
                                   render::make_capsule_mesh(ratio, 10), kLowDetailBelowPx);
  }
  return slot;
}

}  // namespace

WorldScene::WorldScene(const engine::World& world) {
  for (const engine::VisualShape& shape : world.visual_shapes()) {
    render::Instance instance;
    const engine::Geometry& geometry = shape.geometry;
    switch (geometry.type) {
      case engine::GeometryType::kBox:
        instance.mesh = shared_primitive(geometry.type);
        instance.scale = geometry.box_size_m.cast<float>();
        break;
      case engine::GeometryType::kSphere:
        instance.mesh = shared_primitive(geometry.type);
        instance.scale = Eigen::Vector3f::Constant(static_cast<float>(geometry.radius_m));
        break;
      case engine::GeometryType::kCylinder:
        instance.mesh = shared_primitive(geometry.type);
        instance.scale = Eigen::Vector3f(static_cast<float>(geometry.radius_m),
                                         static_cast<float>(geometry.radius_m),
                                         static_cast<float>(geometry.length_m));
        break;
      case engine::GeometryType::kCapsule:
        instance.mesh = shared_capsule(geometry.length_m / geometry.radius_m);
        instance.scale = Eigen::Vector3f::Constant(static_cast<float>(geometry.radius_m));
        break;
      case engine::GeometryType::kMesh:
        // A URDF colour overrides the mesh file's own colours (as in ROS and PyBullet).
        instance.mesh = convert(geometry.mesh, !shape.material.has_rgba);
        instance.scale = geometry.mesh_scale.cast<float>();
        break;
    }
    instance.material.base_color = shape.material.rgba.cast<float>();
    instance.material.texture_path = shape.material.texture_path;
    instance.segmentation_id = shape.segmentation_id;
    scene_.instances.push_back(std::move(instance));
  }
  update(world);
}

void WorldScene::update(const engine::World& world) {
  world.visual_poses(poses_);
  if (poses_.size() != scene_.instances.size()) {
    throw std::invalid_argument(
        "WorldScene::update: the world has " + std::to_string(poses_.size()) +
        " visual shapes, the scene was built for " + std::to_string(scene_.instances.size()));
  }
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    scene_.instances[i].X_world_instance = poses_[i].cast<float>();
  }
}

Eigen::AlignedBox3f WorldScene::bounds() const {
  Eigen::AlignedBox3f box;
  for (const render::Instance& instance : scene_.instances) {
    for (const Eigen::Vector3f& p : instance.mesh->positions) {
      box.extend(instance.X_world_instance * p.cwiseProduct(instance.scale));
    }
  }
  return box;
}

render::Camera frame_box(const Eigen::AlignedBox3f& box, float azimuth_deg, float elevation_deg,
                         int width, int height, float fov_y_deg) {
  if (box.isEmpty()) throw std::invalid_argument("frame_box: nothing to frame (the box is empty)");
  const Eigen::Vector3f centre = box.center();
  const float radius = std::max(0.5F * box.diagonal().norm(), 1e-3F);
  const float azimuth = azimuth_deg * kPi / 180.0F;
  const float elevation = elevation_deg * kPi / 180.0F;
  const Eigen::Vector3f direction(std::cos(elevation) * std::cos(azimuth),
                                  std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
  // The closest distance at which all eight corners of the box project inside the image (with a
  // 5% margin), found by bisection between touching the box and fitting its bounding sphere.
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  const float half_fov_y = fov_y_deg * kPi / 360.0F;
  const float half_fov = std::min(half_fov_y, std::atan(std::tan(half_fov_y) * aspect));
  const Eigen::Vector3f up =
      std::abs(direction.z()) > 0.99F ? Eigen::Vector3f::UnitY() : Eigen::Vector3f::UnitZ();
  const auto camera_at = [&](float distance) {
    render::Camera camera = render::Camera::look_at(centre + distance * direction, centre, up);
    camera.width = width;
    camera.height = height;
    camera.fov_y_deg = fov_y_deg;
    camera.near_m = std::max(0.01F, distance - 2.0F * radius) * 0.5F;
    camera.far_m = distance + 20.0F * radius + 10.0F;
    return camera;
  };
  const auto fits = [&](const render::Camera& camera) {
    const Eigen::Matrix4f view_projection = camera.projection_matrix() * camera.view_matrix();
    for (int corner = 0; corner < 8; ++corner) {
      const Eigen::Vector4f clip =
          view_projection *
          box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(corner)).homogeneous();
      if (clip.w() <= 0.0F || std::abs(clip.x()) > 0.95F * clip.w() ||
          std::abs(clip.y()) > 0.95F * clip.w()) {
        return false;
      }
    }
    return true;
  };
  float near_distance = radius;
  float far_distance = radius / std::sin(half_fov) * 1.05F;
  for (int i = 0; i < 30; ++i) {
    const float middle = 0.5F * (near_distance + far_distance);
    (fits(camera_at(middle)) ? far_distance : near_distance) = middle;
  }
  render::Camera camera = camera_at(far_distance);
  return camera;
}

}  // namespace pixelgym
