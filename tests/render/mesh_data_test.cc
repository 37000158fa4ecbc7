#include "render/mesh_data.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

namespace pixelgym {
namespace {

// Every triangle faces outward (its winding normal points away from the centre) and the vertex
// normals are unit length: the renderer's lighting depends on both.
void expect_closed_outward(const MeshData& mesh) {
  ASSERT_EQ(mesh.positions.size(), mesh.normals.size());
  ASSERT_EQ(mesh.indices.size() % 3, 0U);
  for (const Eigen::Vector3f& n : mesh.normals) ASSERT_NEAR(n.norm(), 1.0F, 1e-4F);
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    const Eigen::Vector3f& a = mesh.positions[mesh.indices[i]];
    const Eigen::Vector3f& b = mesh.positions[mesh.indices[i + 1]];
    const Eigen::Vector3f& c = mesh.positions[mesh.indices[i + 2]];
    const Eigen::Vector3f face = (b - a).cross(c - a);
    if (face.norm() < 1e-9F) continue;  // degenerate triangles at poles
    ASSERT_GT(face.dot((a + b + c) / 3.0F), 0.0F) << "triangle " << i / 3 << " faces inward";
  }
}

TEST(MeshDataTest, PrimitivesAreClosedAndFaceOutward) {
  expect_closed_outward(*make_box_mesh());
  expect_closed_outward(*make_sphere_mesh());
  expect_closed_outward(*make_cylinder_mesh());
  expect_closed_outward(*make_capsule_mesh(3.0));
}

TEST(MeshDataTest, PrimitiveExtents) {
  const auto extent = [](const MeshData& mesh) {
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& p : mesh.positions) box.extend(p);
    return Eigen::Vector3f(box.sizes());
  };
  EXPECT_TRUE(extent(*make_box_mesh()).isApprox(Eigen::Vector3f(1, 1, 1), 1e-6F));
  EXPECT_TRUE(extent(*make_sphere_mesh()).isApprox(Eigen::Vector3f(2, 2, 2), 1e-3F));
  EXPECT_TRUE(extent(*make_cylinder_mesh()).isApprox(Eigen::Vector3f(2, 2, 1), 1e-3F));
  EXPECT_TRUE(extent(*make_capsule_mesh(3.0)).isApprox(Eigen::Vector3f(2, 2, 5), 1e-3F));
}

}  // namespace
}  // namespace pixelgym
